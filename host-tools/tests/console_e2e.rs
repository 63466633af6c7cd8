//! One port, several tools: 40 `bowl send` commands through a running `bowl monitor` on the
//! virtual rig, on a clean line and with 1 % line noise. Every answer must be the right one (the
//! id asked, the kind the command gets, the outcome the rig's state implies) and the monitor must
//! see no reconnect. Ctrl-C ends the monitor with its counters printed.

mod common;

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use common::{BOWL, Sim, bowl, stdout, wait_within};

/// A `bowl monitor --plain` on `port`, its standard input `stdin`; its stdout lines arrive on
/// the receiver.
fn start_monitor(
    port: &str,
    log: &std::path::Path,
    stdin: Stdio,
) -> (Child, mpsc::Receiver<String>) {
    let mut child = Command::new(BOWL)
        .args(["monitor", port, "--plain", "--log"])
        .arg(log)
        .stdin(stdin)
        .stdout(Stdio::piped())
        .spawn()
        .expect("bowl monitor starts");
    let (tx, rx) = mpsc::channel();
    let out = child.stdout.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(out).lines() {
            let Ok(line) = line else { break };
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let opened = rx
        .recv_timeout(Duration::from_secs(10))
        .expect("monitor speaks");
    assert!(opened.contains("open"), "{opened}");
    (child, rx)
}

/// Ten commands whose answers the rig's state fixes, repeated four times: (words, exit code,
/// how the answer starts, what else it must say).
const ROUND: [(&str, i32, &str, &str); 10] = [
    ("speed 1500 1500", 0, "ok", ""),
    ("status", 0, "status", "state=idle"),
    ("clear", 1, "rejected", "STATE"),
    ("speed 1800 30000", 1, "rejected", "RANGE"),
    ("start", 0, "ok", ""),
    ("status", 0, "status", "state=changing-speed|state=running"),
    ("ping", 0, "ok", ""),
    ("stop", 0, "ok", ""),
    ("ping", 0, "ok", ""),
    ("status", 0, "status", "fault=none"),
];

/// Each `bowl send` may take this long (it resends every 200 ms meanwhile): with 1 % of the bytes
/// damaged, a 40-byte answer arrives whole only two times in three.
const TIMEOUT_MS: &str = "5000";

fn forty_commands_through_the_monitor(noise_percent: &str) {
    let sim = Sim::start(&["--line-noise-percent", noise_percent]);
    forty_commands(&sim.path, noise_percent == "0");
}

/// Asks STATUS (through the monitor as well) until the rig is Idle again after a STOP.
fn wait_until_idle(port: &str, round: u16) {
    let started = std::time::Instant::now();
    for k in 0u16.. {
        let id = (3000 + round * 100 + k).to_string();
        let out = bowl(&[
            "send",
            port,
            "--timeout-ms",
            TIMEOUT_MS,
            "--id",
            &id,
            "status",
        ]);
        let text = stdout(&out);
        assert_eq!(out.status.code(), Some(0), "{text}");
        if text.contains("state=idle") {
            return;
        }
        assert!(
            started.elapsed() < Duration::from_secs(20),
            "not Idle: {text}"
        );
        std::thread::sleep(Duration::from_millis(250));
    }
}

/// The 40 commands through a monitor of `port`; `clean`: the line loses nothing.
fn forty_commands(port: &str, clean: bool) {
    let dir = common::temp_dir(&format!("console-{}", port.replace('/', "_")));
    let log = dir.join("log.csv");
    let (mut monitor, lines) = start_monitor(port, &log, Stdio::null());
    for round in 0..4u16 {
        for (k, (words, code, starts, says)) in ROUND.iter().enumerate() {
            let id = 1000 + round * 10 + k as u16;
            let mut args = vec!["send", port, "--timeout-ms", TIMEOUT_MS, "--id"];
            let id_text = id.to_string();
            args.push(&id_text);
            args.extend(words.split(' '));
            let out = bowl(&args);
            let text = stdout(&out);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(*code), "{words}: {text} {err}");
            assert!(text.starts_with(starts), "{words}: {text}");
            assert!(text.contains(&format!("(id {id})")), "{words}: {text}");
            assert!(says.split('|').any(|s| text.contains(s)), "{words}: {text}");
            assert!(err.contains("held by a running `bowl monitor`"), "{err}");
            // The monitor keeps the link: no warning of the host-silence watchdog.
            assert!(!text.contains("link-lost fault"), "{words}: {text}");
            if *words == "stop" {
                // The motors ramp down before the next round's Idle check.
                wait_until_idle(port, round);
            }
        }
    }
    // Ctrl-C.
    let sent = Command::new("kill")
        .args(["-INT", &monitor.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let status = wait_within(&mut monitor, Duration::from_secs(5), "monitor after Ctrl-C");
    assert!(status.success(), "{status:?}");
    let summary = lines
        .iter()
        .last()
        .expect("the monitor prints its counters on Ctrl-C");
    let counters: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(counters["reconnects"], 0, "{summary}");
    // Ctrl-C flushed the log: every telemetry row the monitor counted is in the file, and the
    // log ends with the monitor's own end (link events have no device time).
    let rows = common::csv_rows(&log);
    let telemetry = rows
        .iter()
        .filter(|r| !r["device_time_ms"].is_empty())
        .count();
    assert_eq!(
        Some(telemetry as u64),
        counters["logged_rows"].as_u64(),
        "{summary}"
    );
    assert_eq!(
        rows.last().map(|r| r["event"].as_str()),
        Some("monitor end")
    );
    assert!(counters["frames_ok"].as_u64().unwrap() > 100, "{summary}");
    if clean {
        // A clean line loses nothing, though 40 clients came and went.
        assert_eq!(counters["frames_corrupt"], 0, "{summary}");
        assert_eq!(counters["frames_missing"], 0, "{summary}");
    }
}

#[test]
fn forty_commands_through_the_monitor_on_a_clean_line() {
    forty_commands_through_the_monitor("0");
}

#[test]
fn forty_commands_through_the_monitor_with_line_noise() {
    forty_commands_through_the_monitor("1");
}

/// The same 40 commands through the monitor on the emulated board (QEMU runs the firmware's
/// `qemu-rig` image, real-time profile), whose device is the firmware's own.
#[test]
fn forty_commands_through_the_monitor_on_the_qemu_rig() {
    use bowl_emulator::{image, qemu};
    assert!(
        qemu::installed(),
        "qemu-system-arm is not installed (tests/lib/ensure-tools.sh installs it)"
    );
    let elf = image::build(image::RIG_IMAGE).expect("the qemu-rig image builds");
    let board = qemu::PtyBoard::boot(&elf, qemu::Profile::RealTime, &["-append", "seconds=300"])
        .expect("the emulated board boots");
    let port = board.port.clone();
    forty_commands(&port, true);
    board.stop();
}

/// And on the QEMU rig with 1 % of the board's bytes damaged on their way to the PC (a relay
/// between QEMU's pty and a fresh one, as a noisy cable would): still every answer right.
#[test]
fn forty_commands_through_the_monitor_on_the_qemu_rig_with_line_noise() {
    use bowl_emulator::{image, qemu};
    assert!(
        qemu::installed(),
        "qemu-system-arm is not installed (tests/lib/ensure-tools.sh installs it)"
    );
    let elf = image::build(image::RIG_IMAGE).expect("the qemu-rig image builds");
    let board = qemu::PtyBoard::boot(&elf, qemu::Profile::RealTime, &["-append", "seconds=400"])
        .expect("the emulated board boots");
    let line = noisy_line(&board.port, 1.0, 7);
    forty_commands(&line, false);
    board.stop();
}

/// A pty whose other end is `port`, with `percent` % of the bytes from `port` damaged (each
/// damaged byte changes: a non-zero XOR mask). Returns the new pty's path; the relay threads
/// live until the process ends.
fn noisy_line(port: &str, percent: f64, seed: u64) -> String {
    use nix::sys::termios::{SetArg, cfmakeraw, tcgetattr, tcsetattr};
    use std::io::{Read, Write};
    use std::os::fd::AsFd;
    let raw = |f: &std::fs::File| {
        let mut t = tcgetattr(f.as_fd()).unwrap();
        cfmakeraw(&mut t);
        tcsetattr(f.as_fd(), SetArg::TCSANOW, &t).unwrap();
    };
    let open = |path: &str| {
        std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .unwrap()
    };
    let board = open(port);
    raw(&board);
    let (master, path) = common::open_pty();
    // Held open (raw) so the master never sees the line hang up between the monitor's opens.
    let slave = open(&path);
    raw(&slave);
    let master = std::fs::File::from(master.as_fd().try_clone_to_owned().unwrap());
    let (mut board_in, mut board_out) = (board.try_clone().unwrap(), board);
    let (mut pc_in, mut pc_out) = (master.try_clone().unwrap(), master);
    let threshold = (percent / 100.0 * u64::MAX as f64) as u64;
    std::thread::spawn(move || {
        let mut state = 0x9E37_79B9_7F4A_7C15u64 ^ seed;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut buf = [0u8; 4096];
        while let Ok(n) = board_in.read(&mut buf) {
            if n == 0 {
                break;
            }
            for b in &mut buf[..n] {
                if next() < threshold {
                    *b ^= (next() % 255 + 1) as u8;
                }
            }
            if pc_out.write_all(&buf[..n]).is_err() {
                break;
            }
        }
    });
    std::thread::spawn(move || {
        let _slave = slave;
        let mut buf = [0u8; 4096];
        loop {
            match pc_in.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => {
                    if board_out.write_all(&buf[..n]).is_err() {
                        break;
                    }
                }
                // No reader on the pty side for a moment: try again.
                Err(_) => std::thread::sleep(Duration::from_millis(10)),
            }
        }
    });
    path
}

#[test]
fn monitor_refuses_a_path_that_is_no_port() {
    let dir = common::temp_dir("monitor-refuses");
    let file = dir.join("capture.bin");
    std::fs::write(&file, b"$T1").unwrap();
    for (path, says) in [
        ("/nonexistent/ttyUSB9", "does not exist"),
        (file.to_str().unwrap(), "regular file, not a serial port"),
    ] {
        let out = bowl(&["monitor", path, "--plain", "--seconds", "2"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(3), "{path}: {err}");
        assert!(err.contains(says), "{path}: {err}");
    }
    let sim = Sim::start(&[]);
    let out = bowl(&["monitor", &sim.path, "--baud", "7"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("7 is not in 50..=12000000"), "{err}");
}

#[test]
fn commands_typed_into_the_plain_monitor_are_answered() {
    use std::io::Write;
    let sim = Sim::start(&[]);
    let mut child = Command::new(BOWL)
        .args(["monitor", &sim.path, "--plain", "--seconds", "3"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    std::thread::sleep(Duration::from_millis(500));
    writeln!(stdin, "speed 1500 1500").unwrap();
    writeln!(stdin, "status").unwrap();
    writeln!(stdin, "speed 1500").unwrap();
    // Refusals whose particulars need the rig's parameters or state: asked of it, as `bowl
    // send` does (before, the monitor gave the reason alone: RANGE, with no word of the limit).
    // Inside its own range but outside the rim (RIM_UM):
    writeln!(stdin, "set START_UM 200000").unwrap();
    writeln!(stdin, "speed 5000 5000").unwrap();
    writeln!(stdin, "clear").unwrap();
    // (The particulars tell the state when asked, just after the refusal: answered before the
    // motors start.)
    std::thread::sleep(Duration::from_millis(500));
    // Refused while the motors turn, with a suggestion that names the port the monitor holds,
    // to be pasted as it stands.
    writeln!(stdin, "start").unwrap();
    writeln!(stdin, "commission").unwrap();
    // The granule's gate event: a line of its own, not called an answer.
    writeln!(stdin, "release").unwrap();
    let out = child.wait_with_output().unwrap();
    let text = stdout(&out);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("speed 1500 1500 -> ok (id"), "{text}");
    assert!(text.contains("status -> status (id"), "{text}");
    assert!(text.contains("`speed 1500` not sent: MALFORMED"), "{text}");
    assert!(
        text.contains("set START_UM 200000 -> rejected (id")
            && text.contains("the granule's start radius START_UM = 200000 um must lie inside"),
        "{text}"
    );
    assert!(
        text.lines()
            .any(|l| l.starts_with("gate event: release gate at")),
        "{text}"
    );
    assert!(
        text.contains("commission -> rejected (id")
            && text.contains(&format!(
                "stop the motors first (`bowl send {} stop`)",
                sim.path
            )),
        "{text}"
    );
    assert!(
        text.contains("speed 5000 5000 -> rejected (id")
            && text.contains(
                "(the precession speed 5.000 rad/s is above SPEED_MAX1_MRAD_S = 4.000 rad/s"
            ),
        "{text}"
    );
    assert!(
        text.contains("clear -> rejected (id")
            && text.contains("(the rig is idle: there is no fault to clear"),
        "{text}"
    );
}

#[test]
fn ports_are_listed_or_their_absence_said() {
    let out = bowl(&["ports"]);
    assert_eq!(out.status.code(), Some(0));
    let text = stdout(&out);
    assert!(
        text.starts_with("/dev/") || text.starts_with("no serial ports found"),
        "{text}"
    );
}

#[test]
fn a_second_monitor_is_told_the_port_is_held() {
    let sim = Sim::start(&[]);
    let dir = common::temp_dir("second-monitor");
    let (mut first, _lines) = start_monitor(&sim.path, &dir.join("log.csv"), Stdio::null());
    let out = bowl(&["monitor", &sim.path, "--plain", "--seconds", "1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    // That the holder is a monitor, and so what to do: go through it.
    assert!(
        err.contains("another `bowl monitor` already holds"),
        "{err}"
    );
    let _ = first.kill();
    let _ = first.wait();
}

/// `bowl send` while `bowl commission` holds the port (no monitor): the busy port's holder is
/// named (on Linux), not guessed at.
#[test]
fn a_busy_port_names_its_holder() {
    let sim = Sim::start(&["--seconds", "60"]);
    let mut commission = std::process::Command::new(common::BOWL)
        .args(["commission", &sim.path, "--json"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let out = bowl(&["send", &sim.path, "status"]);
    let err = String::from_utf8_lossy(&out.stderr);
    let _ = commission.kill();
    let _ = commission.wait();
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains(&format!(
            "in use by another program: bowl (pid {})",
            commission.id()
        )),
        "{err}"
    );
}

/// A program that opened the port before us without locking it (here: this test, holding the
/// pty open as `cat` or a script would) steals bytes at random: the monitor and `bowl send` name
/// it. The virtual rig itself (holding the pty's master side) is not taken for one.
#[test]
fn a_reader_that_does_not_lock_the_port_is_named() {
    let sim = Sim::start(&[]);
    let alone = bowl(&["monitor", &sim.path, "--plain", "--seconds", "1"]);
    let text = stdout(&alone);
    assert!(alone.status.success(), "{text}");
    assert!(!text.contains("also open in"), "no one else reads: {text}");

    let _reader = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(&sim.path)
        .expect("the pty opens");
    let me = format!("pid {}", std::process::id());
    let watched = bowl(&["monitor", &sim.path, "--plain", "--seconds", "1"]);
    let text = stdout(&watched);
    assert!(
        text.contains("also open in") && text.contains(&me) && text.contains("does not lock it"),
        "the monitor names the other reader ({me}): {text}"
    );
    let sent = bowl(&["send", &sim.path, "--timeout-ms", "3000", "ping"]);
    let err = String::from_utf8_lossy(&sent.stderr);
    assert!(
        err.contains("also open in") && err.contains(&me),
        "send names the other reader ({me}): {err}"
    );
}

/// The line on `lines` that contains `text`, within 10 s.
fn wait_line(lines: &mpsc::Receiver<String>, text: &str) -> String {
    let end = std::time::Instant::now() + Duration::from_secs(10);
    while let Some(left) = end.checked_duration_since(std::time::Instant::now()) {
        match lines.recv_timeout(left) {
            Ok(line) if line.contains(text) => return line,
            Ok(_) => {}
            Err(_) => break,
        }
    }
    panic!("no line with {text:?} from the monitor within 10 s");
}

/// The port lost under the monitor: a command typed meanwhile is said not sent, and is not
/// sent later either, when the port comes back with a rig on it (here another rig: a USB
/// adapter moved to the next bench, a link re-pointed). Before, it was sent again every second
/// and the other rig started its motors after "not sent: the link is lost".
#[test]
fn a_command_typed_while_the_link_is_lost_is_never_sent() {
    use std::io::Write;
    let dir = common::temp_dir("lost-link-command");
    let link = dir.join("rig");
    let link_text = link.to_str().unwrap();
    let first = Sim::start(&["--link", link_text]);
    let second = Sim::start(&[]);
    let (mut monitor, lines) = start_monitor(link_text, &dir.join("log.csv"), Stdio::piped());
    let mut stdin = monitor.stdin.take().unwrap();
    wait_line(&lines, "frames ok");
    drop(first);
    wait_line(&lines, "lost; reopening");
    writeln!(stdin, "start").unwrap();
    let said = wait_line(&lines, "not sent");
    std::fs::remove_file(&link).unwrap();
    std::os::unix::fs::symlink(&second.path, &link).unwrap();
    wait_line(&lines, "reopened");
    // Past the monitor's resend period (1 s) on the reopened port.
    std::thread::sleep(Duration::from_millis(2500));
    let (code, status) = common::send(&second.path, "status");
    assert_eq!(code, 0, "{status}");
    assert!(status.contains("state=idle"), "{status}");
    assert!(
        said.contains("`start` not sent: the link is lost"),
        "{said}"
    );
    let sent = Command::new("kill")
        .args(["-TERM", &monitor.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    wait_within(
        &mut monitor,
        Duration::from_secs(5),
        "monitor after SIGTERM",
    );
}

/// A fault that comes and goes between two of the plain monitor's once-a-second lines (cleared
/// at once from another console, as a script does): before, the monitor never said it, and the
/// engineer found the motors stopped with no word why (only the log's fault column had it). Now
/// each change is an event line of its own: the fault with its code and words, then its clearing.
#[test]
fn a_fault_and_its_clearing_are_said_as_they_come() {
    let sim = Sim::start(&[]);
    let dir = common::temp_dir("console-fault-events");
    let (mut child, lines) = start_monitor(&sim.path, &dir.join("run.csv"), Stdio::piped());
    for words in ["speed 1800 2100", "start", "inject sensor1"] {
        assert_eq!(common::send(&sim.path, words).0, 0, "{words}");
    }
    let fault = wait_line(&lines, "FAULT 1:");
    assert!(
        fault.contains("precession motor: no sensor pulses")
            && fault.contains("the rig stopped the motors; `clear`"),
        "{fault}"
    );
    assert_eq!(common::send(&sim.path, "clear").0, 0);
    let cleared = wait_line(&lines, "fault cleared");
    assert!(
        cleared.contains("it was: precession motor: no sensor pulses")
            && cleared.contains("the motors stay off until `start`"),
        "{cleared}"
    );
    let _ = child.kill();
    let _ = child.wait();
}

/// A frame from the PC that lost its `$` on the way (here written so through the monitor's
/// socket): the rig answers `$R1,0,UNREADABLE`, id 0, which no tool sent. Before, the monitor
/// passed it over as another tool's answer and no one said the link garbled a frame; now it is
/// an event line, a counter and a row of the log.
#[test]
fn a_line_the_rig_could_not_read_is_said_and_logged() {
    let sim = Sim::start(&[]);
    let dir = common::temp_dir("console-unread-by-rig");
    let log = dir.join("run.csv");
    let (mut monitor, lines) = start_monitor(&sim.path, &log, Stdio::null());
    let mut link = rig_client::link::Link::open(&sim.path, 115_200).unwrap();
    let line = rig_client::lines::command_line(7, &["ping".into()]).unwrap();
    link.write_all(&line[1..]).unwrap();
    let said = wait_line(&lines, "the rig could not read");
    assert!(
        said.contains("the rig could not read a line it got (line noise on the link?); 1 so far"),
        "{said}"
    );
    let counters = wait_line(&lines, "unread by the rig");
    assert!(counters.contains("unread by the rig 1"), "{counters}");
    // A whole frame is answered as before, and is no such line.
    link.write_all(&line).unwrap();
    std::thread::sleep(Duration::from_millis(500));
    let sent = Command::new("kill")
        .args(["-INT", &monitor.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    wait_within(&mut monitor, Duration::from_secs(5), "monitor after Ctrl-C");
    let summary = lines.iter().last().expect("the counters on Ctrl-C");
    let counters: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(counters["unread_by_rig"], 1, "{summary}");
    let logged: Vec<_> = common::csv_rows(&log)
        .into_iter()
        .filter(|r| r["event"] == "the rig could not read a line it got (line noise on the link?)")
        .collect();
    assert_eq!(
        logged.len(),
        1,
        "{}",
        std::fs::read_to_string(&log).unwrap()
    );
}
