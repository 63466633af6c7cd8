//! The monitor's log dates the telemetry that waited in the port's buffer before it opened the
//! port by the device clock, not with the one instant the burst was read (docs/console.md, the
//! log).

mod common;

use common::{Sim, monitor_logged, temp_dir};

/// Seconds of the day of `2026-11-29T01:17:11.750Z` (the date does not change within a test
/// but midnight: then the test fails loudly rather than passing wrongly).
fn day_seconds(iso: &str) -> f64 {
    let time = iso.split('T').nth(1).unwrap_or_else(|| panic!("{iso:?}"));
    let parts: Vec<f64> = time
        .trim_end_matches('Z')
        .split(':')
        .map(|p| p.parse().unwrap())
        .collect();
    parts[0] * 3600.0 + parts[1] * 60.0 + parts[2]
}

#[test]
fn the_backlog_read_at_open_is_dated_by_the_device_clock() {
    let sim = Sim::start(&[]);
    // The rig talks for 2 s before anyone reads: its frames wait in the pty's buffer.
    std::thread::sleep(std::time::Duration::from_secs(2));
    let dir = temp_dir("monitor-backlog");
    let log = dir.join("log.csv");
    let out = monitor_logged(&sim.path, "1.5", &log);
    assert!(out.status.success(), "{}", common::stdout(&out));
    let text = std::fs::read_to_string(&log).unwrap();
    let mut open_at = None;
    let mut rows: Vec<(f64, f64)> = Vec::new();
    for line in text.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        let (device, host, event) = (cells[1], cells[16], cells[17]);
        if event == "port open" {
            open_at = Some(day_seconds(host));
        }
        if !device.is_empty() && event.is_empty() {
            assert!(!host.is_empty(), "a dated row: {line}");
            rows.push((device.parse::<f64>().unwrap() / 1000.0, day_seconds(host)));
        }
    }
    let open_at = open_at.expect("a port open row");
    let backlog: Vec<_> = rows.iter().filter(|r| r.1 < open_at - 0.5).collect();
    assert!(
        backlog.len() >= 25,
        "at least half a second of backlog dated before the port opened: {} rows of {}",
        backlog.len(),
        rows.len()
    );
    // Every row's PC time follows its device time: one clock offset, to within the read's
    // latency, not one instant for the whole burst.
    let offsets: Vec<f64> = rows.iter().map(|(d, h)| h - d).collect();
    let lo = offsets.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = offsets.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    assert!(
        hi - lo < 0.1,
        "offsets spread {:.3} s over {} rows",
        hi - lo,
        rows.len()
    );
}
