//! End to end: the rig-side commands asked to end (Ctrl-C, `kill`) end their own way, and a rig
//! that resets under `commission` is not taken for a finished identification.
//!
//! - `commission` on SIGINT stops the motors first (STOP), says so and exits 130;
//! - `monitor` on SIGTERM closes its log with `monitor end` and prints its counters (in the
//!   terminal UI it also gives the terminal back: `console_tui`);
//! - `serve --pty --link L` on SIGTERM removes `L` (a dangling link is a port that is gone);
//! - a Hello in the middle of commissioning ends `commission` with `restarted`, exit 1.

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{BOWL, Sim, bowl, last_json, send, stdout, temp_dir, wait_within};
use model_core::wire::crc::crc32;
use model_core::wire::{Frame, decode_frame};
use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

fn signal(child: &Child, sig: Signal) {
    kill(Pid::from_raw(child.id() as i32), sig).expect("signal sent");
}

/// Reads `from` up to a line that holds `text` (the command is under way); fails at its end.
fn read_until(from: &mut impl BufRead, text: &str) {
    let mut line = String::new();
    while from.read_line(&mut line).unwrap() > 0 {
        if line.contains(text) {
            return;
        }
        line.clear();
    }
    panic!("no line with {text:?}");
}

/// Ctrl-C on `commission` while the rig identifies its motors: STOP goes out before it ends, so
/// the rig is idle at once (not left commissioning, nor faulted by the link watchdog 3 s later),
/// and the exit code says it was interrupted (130, as a shell reports Ctrl-C).
#[test]
fn commission_interrupted_stops_the_motors_first() {
    let sim = Sim::start(&["--seconds", "60"]);
    let mut child = Command::new(BOWL)
        .args(["commission", &sim.path])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The first progress line: the motors turn.
    read_until(
        &mut BufReader::new(child.stderr.take().unwrap()),
        " s  precession",
    );
    signal(&child, Signal::SIGINT);
    let status = wait_within(
        &mut child,
        Duration::from_secs(5),
        "commission after Ctrl-C",
    );
    let mut text = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut text)
        .unwrap();
    assert_eq!(status.code(), Some(130), "{text}");
    assert!(
        text.contains("commissioning interrupted") && text.contains("the motors are off"),
        "{text}"
    );
    // Its suggestion names the port, to be pasted as it stands.
    assert!(
        text.contains(&format!("(`bowl send {} models`)", sim.path)),
        "{text}"
    );
    // Asked right away: well inside the rig's 3 s link timeout, so idle is STOP's doing.
    let (code, now) = send(&sim.path, "status");
    assert_eq!(code, 0, "{now}");
    assert!(now.contains("state=idle fault=none"), "{now}");
}

/// Ctrl-C on `commission` before the rig took COMMISSION (here a rig slow to answer the
/// question asked first): nothing is started, not motors started and stopped at once.
#[test]
fn commission_interrupted_before_it_starts_sends_nothing() {
    let (master, path) = common::open_pty();
    let child = Command::new(BOWL)
        .args(["commission", &path])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    signal(&child, Signal::SIGINT);
    let out = child.wait_with_output().unwrap();
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(130), "{text}");
    assert!(
        text.contains("interrupted before it started: COMMISSION was not sent"),
        "{text}"
    );
    nix::fcntl::fcntl(
        &master,
        nix::fcntl::FcntlArg::F_SETFL(nix::fcntl::OFlag::O_NONBLOCK),
    )
    .unwrap();
    let mut sent = Vec::new();
    let mut buf = [0u8; 4096];
    let mut master = master;
    while let Ok(n) = master.read(&mut buf) {
        if n == 0 {
            break;
        }
        sent.extend_from_slice(&buf[..n]);
    }
    let sent = String::from_utf8_lossy(&sent);
    assert!(sent.contains("MODELS"), "what the rig got: {sent}");
    assert!(!sent.contains("COMMISSION"), "what the rig got: {sent}");
}

/// `bowl monitor PORT --plain --log LOG EXTRA...` run by `command` (`bowl`, or `nohup bowl`),
/// once it has printed a status line (telemetry flows and is logged); its standard output.
fn logging_monitor(
    mut command: Command,
    port: &str,
    log: &std::path::Path,
    extra: &[&str],
) -> (Child, BufReader<std::process::ChildStdout>) {
    let mut child = command
        .args(["monitor", port, "--plain", "--log"])
        .arg(log)
        .args(extra)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    read_until(&mut out, "frames ok");
    (child, out)
}

/// SIGTERM on a logging monitor: the loop ends as on Ctrl-C, so the log's last row is
/// `monitor end` and the counters are printed (before, the process died where it stood).
#[test]
fn monitor_on_sigterm_closes_its_log() {
    let sim = Sim::start(&["--seconds", "30"]);
    let dir = temp_dir("monitor-sigterm");
    let log = dir.join("run.csv");
    let (mut child, mut out) = logging_monitor(Command::new(BOWL), &sim.path, &log, &[]);
    signal(&child, Signal::SIGTERM);
    let status = wait_within(&mut child, Duration::from_secs(5), "monitor after SIGTERM");
    let mut rest = String::new();
    out.read_to_string(&mut rest).unwrap();
    assert_eq!(status.code(), Some(0), "{rest}");
    let summary: serde_json::Value =
        serde_json::from_str(rest.lines().last().expect("a summary line")).expect("JSON");
    let logged = summary["logged_rows"].as_u64().expect("logged_rows");
    assert!(logged > 0, "{summary}");
    let text = std::fs::read_to_string(&log).unwrap();
    assert!(
        text.trim_end().ends_with(",monitor end"),
        "last row: {:?}",
        text.lines().last()
    );
    // Every telemetry row counted was written (the buffer was flushed, not lost).
    let rows = text.lines().filter(|l| l.ends_with(',')).count() as u64;
    assert_eq!(rows, logged, "{summary}");
}

/// A monitor started to outlive its terminal (`nohup bowl monitor ... &`, SIGHUP ignored) goes
/// on logging when the terminal closes: only a monitor whose terminal is its console ends then.
#[test]
fn a_monitor_under_nohup_outlives_its_terminal() {
    let sim = Sim::start(&["--seconds", "30"]);
    let dir = temp_dir("monitor-nohup");
    let log = dir.join("night.csv");
    let mut nohup = Command::new("nohup");
    nohup.arg(BOWL);
    let (mut child, _out) = logging_monitor(nohup, &sim.path, &log, &["--seconds", "3"]);
    signal(&child, Signal::SIGHUP);
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the monitor ended on SIGHUP under nohup"
    );
    let status = wait_within(&mut child, Duration::from_secs(10), "monitor under nohup");
    assert!(status.success(), "{status:?}");
    common::assert_log_closed(&log);
}

/// SIGTERM on `serve --pty --link L`: the link goes with the rig, as at the end of `--seconds`.
#[test]
fn serve_on_sigterm_removes_its_link() {
    let dir = temp_dir("serve-sigterm");
    let link = dir.join("rig");
    let mut child = Command::new(BOWL)
        .args(["serve", "--pty", "--link"])
        .arg(&link)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut path = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut path)
        .unwrap();
    assert!(std::fs::symlink_metadata(&link).is_ok(), "{path}");
    signal(&child, Signal::SIGTERM);
    wait_within(&mut child, Duration::from_secs(5), "serve after SIGTERM");
    assert!(
        std::fs::symlink_metadata(&link).is_err(),
        "{} still points at {}",
        link.display(),
        path.trim()
    );
}

/// `serve --pty --link L` run again with the same `L` (a second bench, a restart in another
/// terminal) takes the link over; the first one, ended, leaves it to the rig it points at now
/// (before, it removed the link from under the running rig, and a monitor on `L` lost it).
#[test]
fn a_link_taken_over_stays_with_its_new_rig() {
    let dir = temp_dir("serve-link-taken");
    let link = dir.join("rig");
    let link_text = link.to_str().unwrap();
    let first = Sim::start(&["--link", link_text]);
    let second = Sim::start(&["--link", link_text]);
    assert_eq!(
        std::fs::read_link(&link).unwrap(),
        std::path::Path::new(&second.path)
    );
    let mut first = first;
    first.terminate();
    assert_eq!(
        std::fs::read_link(&link).ok().as_deref(),
        Some(std::path::Path::new(&second.path)),
        "the link of the rig still served"
    );
}

/// `--link` onto a path that is not a link (a file of the user's) is refused, the file left
/// as it was (before, it was deleted to make the link).
#[test]
fn a_link_onto_a_file_is_refused() {
    let dir = temp_dir("serve-link-file");
    let notes = dir.join("notes.txt");
    std::fs::write(&notes, "bench notes\n").unwrap();
    let out = bowl(&[
        "serve",
        "--pty",
        "--seconds",
        "1",
        "--link",
        notes.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("exists and is not a symlink"), "{err}");
    assert_eq!(std::fs::read_to_string(&notes).unwrap(), "bench notes\n");
}

/// A rig that resets while it commissions (a watchdog, a brown-out: a Hello, then idle with its
/// clock from zero) has not identified anything; `commission` says so and fails instead of
/// reporting the idle state after the reset as "commissioning done". A scripted rig on a pty:
/// it acknowledges every command, sends commissioning telemetry, then a Hello and idle.
#[test]
fn a_rig_reset_during_commissioning_is_not_success() {
    let (master, path) = common::open_pty();
    nix::fcntl::fcntl(
        &master,
        nix::fcntl::FcntlArg::F_SETFL(nix::fcntl::OFlag::O_NONBLOCK),
    )
    .unwrap();
    let rig = std::thread::spawn(move || {
        let mut master = master;
        let frame = |payload: String| format!("${payload}*{:08X}\r\n", crc32(payload.as_bytes()));
        let started = Instant::now();
        let mut line = Vec::new();
        let mut next_frame = Instant::now();
        let (mut seq, mut clock_ms, mut reset) = (0u16, 60_000u32, false);
        while started.elapsed() < Duration::from_secs(8) {
            let mut buf = [0u8; 256];
            while let Ok(n) = master.read(&mut buf) {
                if n == 0 {
                    break;
                }
                for &b in &buf[..n] {
                    line.push(b);
                    if b == b'\n' {
                        if let Ok(Frame::Command { id, .. }) = decode_frame(&line) {
                            let _ = master.write_all(frame(format!("A1,{id}")).as_bytes());
                        }
                        line.clear();
                    }
                }
            }
            if Instant::now() >= next_frame {
                next_frame += Duration::from_millis(20);
                if !reset && started.elapsed() > Duration::from_millis(2500) {
                    // The reset: Hello, then the device clock from zero.
                    reset = true;
                    clock_ms = 0;
                    let _ = master.write_all(frame("H1,3,18".into()).as_bytes());
                }
                let state = if reset { 0 } else { 1 };
                let duty = if reset { 0 } else { 2500 };
                let payload = format!("T1,{clock_ms},{seq},{state},0,0,0,{duty},0,0,0,0,0,0,-2,-2");
                let _ = master.write_all(frame(payload).as_bytes());
                seq = seq.wrapping_add(1);
                clock_ms += 20;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    });
    let out = bowl(&["commission", &path, "--json", "--timeout-s", "6"]);
    rig.join().unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", stdout(&out));
    let got = last_json(&out);
    assert_eq!(got["result"], "restarted", "{got}");
    assert!(got["axes"].as_array().is_none_or(|a| a.is_empty()), "{got}");
}

/// Ctrl-C on `bowl demo` mid-session: before, it died where it stood (killed by the signal, no
/// exit code), its telemetry.csv cut mid-row beside an earlier run's summary and charts, a chart
/// being written left at 0 bytes. Now it sends STOP, waits for the motors to be off, says so,
/// summarises and charts the run up to there, and exits 130.
#[test]
fn demo_interrupted_stops_the_motors_and_says_so() {
    let dir = temp_dir("demo-interrupted");
    let mut child = Command::new(BOWL)
        .args(["demo", "--fast", "--rig", "host", "--plain", "--out"])
        .arg(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    // The motors turn once START is answered.
    read_until(&mut out, "start: start -> ok");
    signal(&child, Signal::SIGINT);
    let mut rest = String::new();
    out.read_to_string(&mut rest).unwrap();
    let status = wait_within(&mut child, Duration::from_secs(30), "demo after SIGINT");
    let err = common::stderr_of(&mut child);
    assert_eq!(status.code(), Some(130), "{err}\n{rest}");
    assert!(
        err.contains("interrupted (Ctrl-C): STOP sent, the motors are off"),
        "{err}"
    );
    assert!(rest.contains("stop (interrupted): stop -> ok"), "{rest}");
    // The log ends with both motors off, idle, each row whole.
    let rows = common::csv_rows(&dir.join("telemetry.csv"));
    let last = rows.last().expect("telemetry rows");
    assert_eq!(last["state"], "idle", "{last:?}");
    assert_eq!((&*last["prec_duty_bp"], &*last["spin_duty_bp"]), ("0", "0"));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let aborted = summary.to_string();
    assert!(aborted.contains("interrupted (Ctrl-C)"), "{summary}");
    for chart in ["speeds_precession.png", "speeds_spin.png"] {
        let len = std::fs::metadata(dir.join(chart)).map_or(0, |m| m.len());
        assert!(len > 0, "{chart}: {len} bytes");
    }
}
