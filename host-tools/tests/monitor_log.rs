//! End to end: `bowl monitor --log FILE` onto a file that exists. Its own earlier log is
//! appended to (one header, every row whole, even after a row cut off by a power loss); any
//! other CSV is refused before anything is written to it.

mod common;

use common::{Sim, monitor_logged, temp_dir};

/// The columns of a log row, counted as a CSV reader counts them.
fn fields(line: &str) -> usize {
    csv::ReaderBuilder::new()
        .has_headers(false)
        .from_reader(line.as_bytes())
        .records()
        .next()
        .map_or(0, |r| r.unwrap().len())
}

/// A `bowl monitor --plain --seconds 3 --log LOG` on `port`, once its log is open (its first
/// row is there).
fn monitor_writing(port: &str, log: &std::path::Path) -> std::process::Child {
    let child = std::process::Command::new(common::BOWL)
        .args(["monitor", port, "--plain", "--seconds", "3", "--log"])
        .arg(log)
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while !std::fs::read_to_string(log).is_ok_and(|t| t.contains("port open")) {
        assert!(
            started.elapsed().as_secs() < 5,
            "no first row in {}",
            log.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    child
}

#[test]
fn a_log_is_appended_to_and_another_csv_is_left_alone() {
    let sim = Sim::start(&["--seconds", "30"]);
    let dir = temp_dir("monitor-log");

    // A results file given by mistake: refused as a usage error (2), not one byte added.
    let results = dir.join("results.csv");
    let kept = "model,w_rad_s,mu,ri_m,R_m\ncoriolis,3.0,0.02,0.02,0.15\n";
    std::fs::write(&results, kept).unwrap();
    let out = monitor_logged(&sim.path, "1", &results);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("results.csv") && err.contains("not a telemetry log"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&results).unwrap(), kept);

    // The monitor's own log, its last row cut off mid-line (the PC lost power), appended to.
    let log = dir.join("run.csv");
    assert!(monitor_logged(&sim.path, "1", &log).status.success());
    let whole = std::fs::read_to_string(&log).unwrap();
    let columns = fields(whole.lines().next().unwrap());
    let cut = whole.trim_end().len() - 40;
    std::fs::write(&log, &whole[..cut]).unwrap();
    let out = monitor_logged(&sim.path, "1", &log);
    assert!(out.status.success(), "{out:?}");
    let text = std::fs::read_to_string(&log).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines.iter().filter(|l| l.starts_with("boot,")).count(),
        1,
        "one header"
    );
    // The stub stays short; every other row, the second run's `port open` first, is whole.
    let short: Vec<&&str> = lines.iter().filter(|l| fields(l) != columns).collect();
    assert_eq!(short.len(), 1, "{short:?}");
    assert!(
        lines.iter().filter(|l| l.ends_with(",port open")).count() == 2,
        "{text}"
    );
}

/// Two monitors given the same log (two benches, one command line copied): the second is
/// refused (2) before it writes, and the log holds the first one's rows alone (before, both
/// wrote, their rows mixed and cut where their buffers met).
#[test]
fn one_log_takes_one_monitor() {
    let first = Sim::start(&["--seconds", "30"]);
    let second = Sim::start(&["--seconds", "30"]);
    let dir = temp_dir("monitor-log-shared");
    let log = dir.join("bench.csv");
    let mut writing = monitor_writing(&first.path, &log);
    let out = monitor_logged(&second.path, "1", &log);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("another `bowl monitor` is writing to this log"),
        "{err}"
    );
    assert!(writing.wait().unwrap().success());
    let text = std::fs::read_to_string(&log).unwrap();
    assert_eq!(text.matches(",port open").count(), 1, "{text}");
    assert!(
        text.lines()
            .skip(1)
            .all(|l| fields(l) == fields(text.lines().next().unwrap())),
        "{text}"
    );
}

/// `bowl replay cap.bin --csv day.csv` with the day's monitor log named by mistake: before, the
/// log was emptied and filled with the capture's rows while the monitor went on appending to
/// it (the day's rows gone, two runs mixed). Now it is refused (exit 2) and left whole, while a
/// monitor writes it and after; a replay's own CSV is still replaced. The log itself given as
/// the capture is told to be a log, with what draws it.
#[test]
fn a_replay_does_not_replace_a_monitor_log() {
    let sim = Sim::start(&["--seconds", "30"]);
    let dir = temp_dir("monitor-log-replay");
    let capture = common::capture_timed(&dir, "1", &[]);
    let log = dir.join("day.csv");
    let mut writing = monitor_writing(&sim.path, &log);
    let out = common::replay_to_csv(&capture, &log);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--csv") && err.contains("a `bowl monitor` is writing it now"),
        "{err}"
    );
    assert!(writing.wait().unwrap().success());
    let whole = std::fs::read_to_string(&log).unwrap();
    assert_eq!(whole.matches(",port open").count(), 1, "{whole}");
    assert!(whole.trim_end().ends_with(",monitor end"), "{whole}");

    // The monitor gone, the log is still one of a day's PC times: refused again, untouched.
    let out = common::replay_to_csv(&capture, &log);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("it was logged live"), "{err}");
    assert_eq!(std::fs::read_to_string(&log).unwrap(), whole);

    // The log as the capture: said to be a log, and what reads it.
    let out = common::bowl(&["replay", log.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("is a telemetry log") && err.contains("bowl chart log --csv"),
        "{err}"
    );

    // A replay's CSV is made again from its capture: replaced, as before.
    let decoded = dir.join("replay.csv");
    assert!(common::replay_to_csv(&capture, &decoded).status.success());
    let again = common::replay_to_csv(&capture, &decoded);
    assert!(again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("existed and was replaced"));
}
