//! `bowl chart log`: a run logged by `bowl monitor --log` drawn per axis, with its link events.

mod common;

use common::{bowl, monitor_logged, sim_timed, stdout, temp_dir};

#[test]
fn a_monitor_log_is_drawn_with_its_link_events() {
    let sim = sim_timed("10", &["0:speed,1800,2100", "0:start"]);
    let dir = temp_dir("chart-log");
    let log = dir.join("run.csv");
    let mon = monitor_logged(&sim.path, "2", &log);
    assert_eq!(mon.status.code(), Some(0), "{}", stdout(&mon));
    let out = dir.join("run.svg");
    let drawn = bowl(&[
        "chart",
        "log",
        "--csv",
        log.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        drawn.status.success(),
        "{}",
        String::from_utf8_lossy(&drawn.stderr)
    );
    for axis in ["precession", "spin"] {
        let svg = std::fs::read_to_string(dir.join(format!("run-{axis}.svg"))).unwrap();
        for label in ["port open", "monitor end", "measured", "PC clock"] {
            assert!(svg.contains(label), "{axis}: no {label:?} in the chart");
        }
        // A run without a fault marks none.
        assert!(
            !svg.contains("fault:") && !svg.contains("fault cleared"),
            "{axis}: a fault marked in a run without one"
        );
        let png = std::fs::read(dir.join(format!("run-{axis}.png"))).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    }
    // A fault in the log (the CSV's word for it) is marked in words where it came and went.
    let text = std::fs::read_to_string(&log).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let telemetry: Vec<usize> = (1..lines.len())
        .filter(|&i| lines[i].split(',').nth(4) == Some("none"))
        .collect();
    assert!(telemetry.len() > 20, "{} telemetry rows", telemetry.len());
    for &i in &telemetry[10..15] {
        lines[i] = lines[i].replacen(",none,", ",no-pulses-spin,", 1);
    }
    let faulted = dir.join("faulted.csv");
    std::fs::write(&faulted, lines.join("\n") + "\n").unwrap();
    let drawn = bowl(&[
        "chart",
        "log",
        "--csv",
        faulted.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(drawn.status.success(), "{}", stdout(&drawn));
    let svg = std::fs::read_to_string(dir.join("run-spin.svg")).unwrap();
    assert!(
        svg.contains("fault: spin motor: no sensor pulses") && svg.contains("fault cleared"),
        "the fault is not marked in words"
    );
    // A file that is not a telemetry log is refused in plain words.
    let other = dir.join("other.csv");
    std::fs::write(&other, "a,b\n1,2\n").unwrap();
    let refused = bowl(&[
        "chart",
        "log",
        "--csv",
        other.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(refused.status.code(), Some(1));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("no `device_time_ms` column"), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}
