//! End to end on the emulated board: the firmware's application logic on QEMU netduinoplus2
//! with the simulated plant, driven over its emulated USART by `bowl send`, its telemetry read
//! with the shared host decoder, checked against the plant's true speeds (semihosting log).
//!
//! Time is the board's (`-icount shift=0,sleep=off`): every bound below is in device time,
//! taken from the telemetry frames, never from the host clock.
//!
//! Run: `cargo test -p firmware --no-default-features --test qemu_rig_e2e`.

mod common;

use std::io::{Read, Write};
use std::os::fd::{AsRawFd, OwnedFd};
use std::os::unix::net::UnixStream;
use std::path::PathBuf;
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use model_core::wire::{Decoder, DeviceState, FaultCode, Frame, Residence, Telemetry};

/// What the splitter saw from the board.
#[derive(Default)]
struct Seen {
    telemetry: Vec<Telemetry>,
    hello: usize,
}

/// Sits between the board's USART socket and a pseudo-terminal for `bowl send`: every byte
/// from the board goes to the decoder here, and to the terminal while a `bowl send` runs;
/// every byte from the terminal goes to the board.
struct Splitter {
    seen: Arc<Mutex<Seen>>,
    forward: Arc<AtomicBool>,
    pty_path: PathBuf,
    slave: OwnedFd,
}

fn raw_pty() -> (OwnedFd, OwnedFd, PathBuf) {
    use nix::sys::termios;
    let pty = nix::pty::openpty(None, None).expect("openpty");
    let mut t = termios::tcgetattr(&pty.slave).expect("tcgetattr");
    termios::cfmakeraw(&mut t);
    termios::tcsetattr(&pty.slave, termios::SetArg::TCSANOW, &t).expect("tcsetattr");
    let path = std::fs::read_link(format!("/proc/self/fd/{}", pty.slave.as_raw_fd()))
        .expect("the slave's path");
    (pty.master, pty.slave, path)
}

impl Splitter {
    fn start(usart: UnixStream) -> Splitter {
        let (master, slave, pty_path) = raw_pty();
        let seen = Arc::new(Mutex::new(Seen::default()));
        let forward = Arc::new(AtomicBool::new(false));
        let mut master_w = std::fs::File::from(master.try_clone().unwrap());
        let mut master_r = std::fs::File::from(master);
        let mut from_board = usart.try_clone().unwrap();
        let mut to_board = usart;
        {
            let (seen, forward) = (seen.clone(), forward.clone());
            std::thread::spawn(move || {
                let mut decoder = Decoder::new();
                let mut buf = [0u8; 4096];
                while let Ok(n) = from_board.read(&mut buf) {
                    if n == 0 {
                        break;
                    }
                    if forward.load(Ordering::Acquire) {
                        let _ = master_w.write_all(&buf[..n]);
                    }
                    let mut s = seen.lock().unwrap();
                    for &b in &buf[..n] {
                        match decoder.push(b) {
                            Some(Ok(Frame::Telemetry(t))) => s.telemetry.push(t),
                            Some(Ok(Frame::Hello(_))) => s.hello += 1,
                            _ => {}
                        }
                    }
                }
            });
        }
        std::thread::spawn(move || {
            let mut buf = [0u8; 256];
            while let Ok(n) = master_r.read(&mut buf) {
                if n == 0 || to_board.write_all(&buf[..n]).is_err() {
                    break;
                }
            }
        });
        Splitter {
            seen,
            forward,
            pty_path,
            slave,
        }
    }

    /// Runs `bowl send PTY words...` and returns its exit code and output.
    fn send(&self, bowl: &PathBuf, words: &[&str]) -> (i32, String) {
        // Stale telemetry queued while nobody listened must not reach this send.
        let _ = nix::sys::termios::tcflush(&self.slave, nix::sys::termios::FlushArg::TCIFLUSH);
        self.forward.store(true, Ordering::Release);
        let out = Command::new(bowl)
            .arg("send")
            .arg(&self.pty_path)
            .args(words)
            .args(["--timeout-ms", "3000"])
            .output()
            .expect("bowl runs");
        self.forward.store(false, Ordering::Release);
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        println!(
            "bowl send {} -> {:?}: {}",
            words.join(" "),
            out.status.code(),
            text.trim()
        );
        (out.status.code().unwrap_or(-1), text)
    }

    fn last(&self) -> Telemetry {
        let s = self.seen.lock().unwrap();
        *s.telemetry.last().expect("telemetry arrives")
    }

    /// Waits until the board's clock has advanced `ms` past `from_ms`; returns the frames of
    /// that interval.
    fn wait_device_ms(&self, from_ms: u32, ms: u32) -> Vec<Telemetry> {
        let deadline = Instant::now() + Duration::from_secs(120);
        loop {
            {
                let s = self.seen.lock().unwrap();
                if s.telemetry
                    .last()
                    .is_some_and(|t| t.time_ms >= from_ms + ms)
                {
                    return s
                        .telemetry
                        .iter()
                        .filter(|t| t.time_ms >= from_ms)
                        .copied()
                        .collect();
                }
            }
            assert!(
                Instant::now() < deadline,
                "the board stopped sending telemetry"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

fn build_bowl() -> PathBuf {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(common::workspace_root())
        .args(["build", "-p", "host-tools", "--bin", "bowl"])
        .status()
        .expect("cargo runs");
    assert!(status.success(), "building bowl failed");
    let target_dir = std::env::var("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|_| common::workspace_root().join("target"));
    target_dir.join("debug/bowl")
}

/// `plant t_ms=.. w1=.. w2=.. d1=.. d2=..` lines of the semihosting console.
fn plant_truth(console: &[String]) -> Vec<(u32, f32, f32, f32, f32)> {
    console
        .iter()
        .filter_map(|l| l.strip_prefix("plant "))
        .filter_map(|l| {
            let v: Vec<f32> = l
                .split_whitespace()
                .filter_map(|kv| kv.split_once('=').and_then(|(_, v)| v.parse().ok()))
                .collect();
            (v.len() == 5).then(|| (v[0] as u32, v[1], v[2], v[3], v[4]))
        })
        .collect()
}

#[test]
fn rig_runs_closed_loop_and_handles_a_sensor_fault_under_qemu() {
    let bowl = build_bowl();
    let elf = common::build_image("qemu-rig");
    let board = common::Board::boot_with(&elf, &["-append", "seconds=40"]);
    let usart = board.usart.try_clone().unwrap();
    let split = Splitter::start(usart);

    // Boot: hello, idle, no fault, motors off.
    let t0 = split.wait_device_ms(0, 300);
    assert!(
        split.seen.lock().unwrap().hello >= 1,
        "the board announces itself"
    );
    assert!(t0.iter().all(|t| t.state == DeviceState::Idle
        && t.fault == FaultCode::None
        && t.precession.duty_bp == 0
        && t.spin.duty_bp == 0));

    // Speeds, start, and 6 s of device time.
    assert_eq!(split.send(&bowl, &["speed", "2000", "3000"]).0, 0);
    assert_eq!(split.send(&bowl, &["start"]).0, 0);
    let started_ms = split.last().time_ms;
    let run = split.wait_device_ms(started_ms, 6_000);
    let tail: Vec<_> = run
        .iter()
        .filter(|t| t.time_ms >= started_ms + 4_000)
        .collect();
    assert!(!tail.is_empty());
    for t in &tail {
        assert_eq!(t.state, DeviceState::Running, "{t:?}");
        assert_eq!((t.precession.set_mrad_s, t.spin.set_mrad_s), (2000, 3000));
        // Measured (from pulses) within 2 % of the setpoint once settled.
        assert!(
            (i32::from(t.precession.measured_mrad_s) - 2000).abs() <= 40,
            "{t:?}"
        );
        assert!(
            (i32::from(t.spin.measured_mrad_s) - 3000).abs() <= 60,
            "{t:?}"
        );
    }
    // Telemetry sequence: no frame lost on the way.
    for w in run.windows(2) {
        assert_eq!(
            w[1].seq,
            w[0].seq.wrapping_add(1),
            "frame lost between {w:?}"
        );
    }

    // A residence-time target: the prediction the rig reports at its measured speeds
    // converges on the target. 800 ms in the default scene needs a combined bowl speed of about
    // 3 rad/s, well above the threshold speed sqrt(mu g / ri) = 2.39 rad/s where the time
    // becomes ill-conditioned (2.5 s would sit at 2.40 rad/s: 1 % of speed, 30 % of time).
    assert_eq!(split.send(&bowl, &["rtime", "flat", "800"]).0, 0);
    let from = split.last().time_ms;
    let settled = split.wait_device_ms(from, 8_000);
    let last = settled.last().unwrap();
    match last.residence_flat {
        Residence::Ms(ms) => assert!((760..=840).contains(&ms), "{last:?}"),
        other => panic!("no flat prediction at the end: {other:?} ({last:?})"),
    }

    // The spin sensor dies: fault within max(200 ms, 3 pulse periods) (+ one telemetry period
    // and the command's transit), both outputs at zero, latched.
    assert_eq!(split.send(&bowl, &["inject", "sensor2"]).0, 0);
    let injected_ms = split.last().time_ms;
    let after = split.wait_device_ms(injected_ms, 2_000);
    let first_fault = after
        .iter()
        .find(|t| t.state == DeviceState::Faulted)
        .expect("the lost sensor faults the rig");
    assert_eq!(first_fault.fault, FaultCode::SensorLostOrStallSpin);
    let w2 = f32::from(settled.last().unwrap().spin.measured_mrad_s) * 1e-3;
    let pulse_period_ms = 1000.0 * core::f32::consts::TAU / (12.0 * w2);
    let bound_ms = (200.0f32).max(3.0 * pulse_period_ms) + 20.0 + 150.0;
    let latency = first_fault.time_ms - injected_ms;
    println!("sensor fault after {latency} ms of device time (bound {bound_ms:.0} ms)");
    assert!((latency as f32) <= bound_ms, "fault after {latency} ms");
    for t in after.iter().filter(|t| t.time_ms >= first_fault.time_ms) {
        assert_eq!(t.state, DeviceState::Faulted, "the fault latches");
        assert_eq!((t.precession.duty_bp, t.spin.duty_bp), (0, 0), "{t:?}");
    }
    // Faulted: START is refused, CLEAR works once asked.
    assert_eq!(split.send(&bowl, &["start"]).0, 2);
    assert_eq!(split.send(&bowl, &["inject", "none"]).0, 0);
    assert_eq!(split.send(&bowl, &["clear"]).0, 0);
    let from = split.last().time_ms;
    let cleared = split.wait_device_ms(from, 300);
    assert_eq!(cleared.last().unwrap().state, DeviceState::Idle);

    // The plant's own record: true speeds near the setpoints while running, duties zero
    // after the fault.
    let (ok, console) = board.finish();
    assert!(
        ok,
        "the board ended with a failure:\n{}",
        console.join("\n")
    );
    let truth = plant_truth(&console);
    let running: Vec<_> = truth
        .iter()
        .filter(|r| r.0 >= started_ms + 4_000 && r.0 <= started_ms + 6_000)
        .collect();
    assert!(!running.is_empty(), "plant log covers the run");
    for r in running {
        assert!(
            (r.1 - 2.0).abs() < 0.06 && (r.2 - 3.0).abs() < 0.09,
            "true speeds {r:?}"
        );
    }
    let faulted: Vec<_> = truth
        .iter()
        .filter(|r| r.0 > first_fault.time_ms + 100 && r.0 < first_fault.time_ms + 1_500)
        .collect();
    assert!(!faulted.is_empty());
    assert!(
        faulted.iter().all(|r| r.3 == 0.0 && r.4 == 0.0),
        "{faulted:?}"
    );
}
