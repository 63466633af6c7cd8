//! A closed pipe is not a crash: `bowl sim sweep | head -1` and `bowl monitor PORT | head -2`
//! end the way Unix tools do (SIGPIPE, or quietly), never with a panic; `bowl chart` writes
//! every file all the same. A run that cannot be
//! measured (`sim step --pulses-per-rev 0`) is refused with the flag, the value and the range.

mod common;

use std::io::{BufRead, BufReader};
use std::os::unix::process::ExitStatusExt;
use std::process::{Command, Stdio};
use std::time::Duration;

use common::{BOWL, Sim, bowl, stderr_of, wait_within};

/// Runs `bowl ARGS`, reads `lines` lines of its output, closes the pipe; the run must then end
/// by SIGPIPE or with status 0, and say nothing of a panic.
fn ends_quietly_when_the_reader_goes(args: &[&str], lines: usize) {
    let mut child = Command::new(BOWL)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    for _ in 0..lines {
        let mut line = String::new();
        assert!(
            out.read_line(&mut line).unwrap() > 0,
            "{args:?}: output ended early"
        );
    }
    drop(out);
    let status = wait_within(
        &mut child,
        Duration::from_secs(30),
        "bowl after its reader left",
    );
    let err = stderr_of(&mut child);
    assert!(
        status.signal() == Some(nix::libc::SIGPIPE) || status.code() == Some(0),
        "{args:?}: {status:?}: {err}"
    );
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

#[test]
fn sim_sweep_into_a_closed_pipe() {
    ends_quietly_when_the_reader_goes(&["sim", "sweep"], 1);
}

/// The monitor's log is closed as on Ctrl-C when its reader goes (`... --log day.csv | head`):
/// before, SIGPIPE killed it and the log just stopped, without `monitor end`.
#[test]
fn monitor_into_a_closed_pipe() {
    let sim = Sim::start(&["--seconds", "30"]);
    let dir = common::temp_dir("closed-pipe-monitor");
    let log = dir.join("run.csv");
    let log_arg = log.to_str().unwrap();
    ends_quietly_when_the_reader_goes(&["monitor", &sim.path, "--plain", "--log", log_arg], 2);
    common::assert_log_closed(&log);
}

#[test]
fn a_step_with_no_pulses_is_refused_in_plain_words() {
    let out = bowl(&["sim", "step", "--pulses-per-rev", "0"]);
    assert_eq!(out.status.code(), Some(2), "a usage error");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("'0'") && err.contains("1..=65535"), "{err}");
}

#[test]
fn a_chart_into_a_closed_pipe_still_writes_every_file() {
    // The files are the product: a reader gone before the first "wrote" line must not stop
    // the svg, png and csv from being written.
    let dir = std::env::temp_dir().join(format!("bowl-closed-pipe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("radial.svg");
    let mut child = Command::new(BOWL)
        .args(["chart", "radial", "--out", svg.to_str().unwrap()])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let status = wait_within(&mut child, Duration::from_secs(60), "bowl chart radial");
    let err = stderr_of(&mut child);
    assert_eq!(status.code(), Some(0), "{status:?}: {err}");
    for ext in ["svg", "png", "csv"] {
        let f = svg.with_extension(ext);
        assert!(
            std::fs::metadata(&f).is_ok_and(|m| m.len() > 0),
            "{} not written",
            f.display()
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
