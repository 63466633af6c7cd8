//! A wrong flag or value on the command line exits with 2 (docs/console.md, exit codes) and says
//! in words which value, the limit and what to do: every command-line check of the rig-side
//! commands (`sim`, `serve`, `replay`), not only clap's.

mod common;

use common::{Sim, bowl, temp_dir};

/// Runs `bowl ARGS`; asserts exit 2, nothing on stdout, and every one of `words` on stderr.
fn refused(args: &[&str], words: &[&str]) {
    let out = bowl(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        out.stdout.is_empty(),
        "{args:?} printed {:?}",
        common::stdout(&out)
    );
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    for w in words {
        assert!(err.contains(w), "{args:?}: {w:?} not in {err}");
    }
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

#[test]
fn sim_step_speed_flags_are_usage_errors_with_the_range_and_the_floor() {
    let range = "outside the controller's speed range, 0.200 to 4 rad/s";
    for value in ["-1", "100", "0"] {
        refused(&["sim", "step", "--target-rad-s", value], &[range]);
    }
    // Not a number, or none f32 holds: said so by the one number parser of every flag.
    refused(
        &["sim", "step", "--target-rad-s", "NaN"],
        &["--target-rad-s", "`NaN` is not a number"],
    );
    for value in ["inf", "1e400", "1e39"] {
        refused(
            &["sim", "step", "--target-rad-s", value],
            &[&format!("{value} is out of range")],
        );
    }
    // Below the sensor floor: the motor never moves, the figures would read as a perfect step.
    for value in ["0.1", "0.19"] {
        refused(
            &["sim", "step", "--target-rad-s", value],
            &[
                &format!("--target-rad-s {value} is below the lowest speed"),
                "0.200 rad/s",
                "ask for at least that",
            ],
        );
    }
    refused(
        &["sim", "step", "--from-rad-s", "0.1"],
        &["--from-rad-s 0.1 is below the lowest speed", "0.200 rad/s"],
    );
    refused(
        &["sim", "step", "--from-rad-s", "3", "--target-rad-s", "3"],
        &["--from-rad-s 3 equals --target-rad-s", "0 (from rest)"],
    );
    refused(
        &["sim", "step", "--accel-rad-s2", "-1"],
        &["--accel-rad-s2", "0.01 to 1000"],
    );
    refused(
        &["sim", "step", "--ripple-nm", "NaN"],
        &["--ripple-nm", "`NaN` is not a number"],
    );
    refused(
        &["sim", "family", "--plants", "3"],
        &["--plants must be at least 50"],
    );
    // A family of no plants was written, and then refused by every reader of it.
    refused(
        &["sim", "make-family", "--plants", "0"],
        &["--plants", "0 is not in 1.."],
    );
}

#[test]
fn sim_faults_flags_are_usage_errors() {
    let rig = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/rigs/nominal.toml");
    fn faults<'a>(rig: &'a str, flag: &'a str, value: &'a str) -> Vec<&'a str> {
        vec!["sim", "faults", "--rig-file", rig, flag, value]
    }
    refused(
        &faults(rig, "--speed-rad-s", "0"),
        &["--speed-rad-s 0 is outside", "0.200 to 4"],
    );
    refused(
        &faults(rig, "--speed-rad-s", "0.1"),
        &["below the lowest speed", "ask for at least that"],
    );
    refused(
        &faults(rig, "--drop-pulses-pct", "150"),
        &["--drop-pulses-pct must be from 0 to 50", "got 150"],
    );
}

#[test]
fn serve_flags_are_usage_errors_in_words() {
    let dir = temp_dir("usage-serve");
    let cap = dir.join("c.bin");
    let cap = cap.to_str().unwrap();
    let serve = |extra: [&'static str; 2]| -> Vec<String> {
        ["serve", "--capture", cap, "--seconds", "1"]
            .into_iter()
            .chain(extra)
            .map(str::to_string)
            .collect()
    };
    let refused = |args: &[String], words: &[&str]| {
        refused(&args.iter().map(String::as_str).collect::<Vec<_>>(), words)
    };
    refused(
        &["serve", "--capture", cap, "--seconds", "-1"].map(str::to_string),
        &["--seconds must be between 0 and 4e6 (got -1)"],
    );
    refused(
        &serve(["--line-noise-percent", "150"]),
        &["--line-noise-percent must be between 0 and 100 (got 150)"],
    );
    refused(
        &serve(["--command", "x:speed,1,1"]),
        &["--command x:speed,1,1: `x` is not a time"],
    );
    refused(
        &serve(["--command", "0:jump"]),
        &["`jump` is not a command", "speed, rtime"],
    );
    refused(
        &serve(["--command", "0:speed,99999,1"]),
        &[
            "RANGE",
            "the precession speed 99999 mrad/s is outside its range 0..=32767",
        ],
    );
    // Due after the run's end: it would be dropped without a word.
    refused(
        &serve(["--command", "5000:start"]),
        &["due at 5000 ms", "the run ends at 1000 ms (--seconds 1)"],
    );
    assert!(!std::path::Path::new(cap).exists(), "nothing was written");
}

/// Every check comes before the pty path is printed: a script reading the first line must not
/// take a rig that is about to fail for a running one.
#[test]
fn serve_pty_checks_the_rig_file_before_printing_the_path() {
    let out = bowl(&["serve", "--pty", "--rig-file", "/nonexistent.toml"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(out.stdout.is_empty(), "{}", common::stdout(&out));
    assert!(err.contains("/nonexistent.toml"), "{err}");
    refused(
        &["serve", "--pty", "--seconds", "-1"],
        &["--seconds must be between 0 and 4e6"],
    );
}

/// A serial port (here the virtual rig's pty) as the capture: refused at once in words, not a
/// wait forever.
#[test]
fn replay_of_a_port_points_to_the_monitor() {
    let sim = Sim::start(&[]);
    let started = std::time::Instant::now();
    refused(
        &["replay", &sim.path],
        &[
            "is a serial port or terminal, not a capture file",
            &format!("bowl monitor {} --log", sim.path),
        ],
    );
    assert!(started.elapsed() < std::time::Duration::from_secs(5));
}

/// `replay --csv` writes the whole decode and says so when it replaced a file.
#[test]
fn replay_says_when_it_replaced_the_csv() {
    let dir = temp_dir("usage-replay-csv");
    let capture = common::capture_timed(&dir, "1", &[]);
    let csv = dir.join("run.csv");
    let first = common::replay_to_csv(&capture, &csv);
    assert!(first.status.success());
    assert!(!String::from_utf8_lossy(&first.stderr).contains("replaced"));
    let rows = std::fs::read_to_string(&csv).unwrap();
    let again = common::replay_to_csv(&capture, &csv);
    assert!(again.status.success());
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(err.contains("existed and was replaced"), "{err}");
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        rows,
        "replaced, not appended"
    );
}

/// The other rig-side commands' own checks: judged before any port is opened.
#[test]
fn monitor_commission_and_stability_flags_are_usage_errors() {
    refused(
        &["monitor", "/dev/null-never-opened", "--seconds", "inf"],
        &["--seconds inf", "0 s or more"],
    );
    refused(
        &["commission", "/dev/null-never-opened", "--timeout-s", "0"],
        &["--timeout-s must be above 0 and at most 86400 s (got 0)"],
    );
    refused(
        &["sim", "stability", "--speed-rad-s", "-1"],
        &["--speed-rad-s -1 is outside the controller's speed range, above 0 and up to 4 rad/s"],
    );
    refused(
        &["sim", "stability", "--tick-hz", "0"],
        &["--tick-hz", "100..=10000"],
    );
    // No pulses: the CSV was its header alone, exit 0.
    refused(
        &["sim", "stability", "--pulses-per-rev", "0"],
        &["--pulses-per-rev", "0 is not in 1.."],
    );
    // One pulse a revolution cannot measure 0.5 rad/s: every row read as a perfect hold
    // (amplitude 0.000) of a shaft that never turned.
    refused(
        &["sim", "stability", "--pulses-per-rev", "1"],
        &[
            "--speed-rad-s 0.5 is below the lowest speed of the nominal rig's precession axis, \
             1.571 rad/s (1 pulse per revolution)",
        ],
    );
}

/// `bowl send --id` with an id whose answers are another's: 0 (the rig's answer to a line it
/// could not read, `$R1,0,UNREADABLE`, would have been taken for this command's refusal) and
/// the monitor's two (its heartbeat's ack for this command's). Before, each was sent.
#[test]
fn send_ids_whose_answers_are_anothers_are_usage_errors() {
    let send = |id: &'static str| ["send", "/dev/null-never-opened", "--id", id, "stop"];
    refused(
        &send("0"),
        &["'0'", "lines typed at its console", "give 1 to 65533"],
    );
    for id in ["65534", "65535"] {
        refused(
            &send(id),
            &["`bowl monitor`'s own commands", "give 1 to 65533"],
        );
    }
    refused(
        &send("65536"),
        &["`65536` is not a request id", "from 1 to 65533"],
    );
}

/// `bowl chart family`'s step is judged as `bowl sim family`'s, before any plant runs: a target
/// of 10, 0, -1 or NaN rad/s, one below the sensors' floor, or a "step" to the speed it starts
/// at each drew a chart (never-settled axes, false faults, NaN ripple) and exited 0.
#[test]
fn chart_family_speed_flags_are_usage_errors() {
    let rig = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/rigs/family-small.toml"
    );
    let dir = temp_dir("chart-family-flags");
    let out = dir.join("family.svg");
    let out = out.to_str().unwrap();
    let chart = |extra: &[&'static str]| {
        let mut v = vec!["chart", "family", "--rig-file", rig, "--out", out];
        v.extend_from_slice(extra);
        v
    };
    let range = "outside the controller's speed range, 0.200 to 4 rad/s";
    for value in ["10", "0", "-1"] {
        refused(&chart(&["--target-rad-s", value]), &[range]);
    }
    refused(
        &chart(&["--target-rad-s", "NaN"]),
        &["--target-rad-s", "`NaN` is not a number"],
    );
    refused(
        &chart(&["--target-rad-s", "0.1"]),
        &[
            "--target-rad-s 0.1 is below the lowest speed of plant p00",
            "0.200 rad/s",
        ],
    );
    refused(
        &chart(&["--from-rad-s", "1", "--target-rad-s", "1"]),
        &["--from-rad-s 1 equals --target-rad-s", "0 (from rest)"],
    );
    for ext in ["svg", "png", "csv"] {
        assert!(
            !dir.join(format!("family.{ext}")).exists(),
            "family.{ext} written"
        );
    }
}
