//! Helpers shared by the end-to-end tests that run the built `bowl` binary: a `bowl serve --pty`
//! virtual rig, one-shot `bowl` runs, scratch directories, and a pseudo-terminal standing in for
//! the user's screen.
//!
//! Each test file is its own crate and uses only some of these, hence the `dead_code` allowance.
#![allow(dead_code)]

pub mod tmux;

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use nix::fcntl::OFlag;
use nix::pty::{PtyMaster, grantpt, posix_openpt, ptsname_r, unlockpt};

/// `bowl predict --batch` on a file holding `csv` (named after `name` in the temporary folder),
/// with `extra` flags: its output and the results file's text (empty if none was written), both
/// files removed.
pub fn run_batch(name: &str, csv: &str, extra: &[&str]) -> (Output, String) {
    let temp =
        |n: &str| std::env::temp_dir().join(format!("bowl-batch-{}-{n}", std::process::id()));
    let input = temp(&format!("{name}.csv"));
    let output = temp(&format!("{name}-out.csv"));
    std::fs::write(&input, csv).unwrap();
    let out = predict_batch(&input, &output, extra);
    let text = std::fs::read_to_string(&output).unwrap_or_default();
    let _ = std::fs::remove_file(input);
    let _ = std::fs::remove_file(output);
    (out, text)
}

/// `bowl predict --batch INPUT --out OUTPUT EXTRA...` run to its end.
pub fn predict_batch(input: &Path, output: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "predict",
        "--batch",
        input.to_str().unwrap(),
        "--out",
        output.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    bowl(&args)
}

/// A `bowl predict` command line: each of `scene`'s flags with its value unless `extra` names
/// that flag too, then `extra` (so a flag in `extra` replaces the scene's).
pub fn predict_args<'a>(scene: &[(&'a str, &'a str)], extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec!["predict"];
    for &(flag, value) in scene {
        if !extra.contains(&flag) {
            v.extend([flag, value]);
        }
    }
    v.extend_from_slice(extra);
    v
}

/// `bowl predict --model bowl`: issue 30's command line with the scene's speeds, tilt and wall;
/// a flag in `extra` replaces the default one.
pub fn bowl_args<'a>(
    w1: &'a str,
    w2: &'a str,
    th: &'a str,
    wall: [&'a str; 3],
    extra: &[&'a str],
) -> Vec<&'a str> {
    let scene = [
        ("--model", "bowl"),
        ("--axes-angle-deg", th),
        ("--precession-rad-s", w1),
        ("--spin-rad-s", w2),
        ("--rim-radius-m", "0.075"),
        ("--ri-m", "0.0375"),
        ("--particle-radius-m", "0.003"),
        ("--mu", "0.029"),
        ("--sliding-mu", "0.4"),
        ("--restitution", "0.5"),
        ("--wall-angle-deg", wall[0]),
        ("--wall-height-m", wall[1]),
        ("--fillet-radius-m", wall[2]),
        ("--max-time-s", "3"),
    ];
    predict_args(&scene, extra)
}

/// The speed of each axis on the tilted rig, as a flag's value: |Omega| 3.6 rad/s with
/// w1 = w2 and the axes 60 deg apart, `3.6 / sqrt(2 (1 + cos 60))`.
pub fn rig_axis_speed() -> String {
    format!("{}", 3.6 / (2.0 * (1.0 + 60f64.to_radians().cos())).sqrt())
}

/// The tilted rig's scene (docs/model.md §9) for `--model MODEL`: axes 60 deg apart, both
/// turning at `w` ([`rig_axis_speed`] for the rig's own), rim 150 mm, the start at 75 mm.
pub fn tilted_rig<'a>(model: &'a str, w: &'a str) -> [(&'a str, &'a str); 6] {
    [
        ("--model", model),
        ("--precession-rad-s", w),
        ("--spin-rad-s", w),
        ("--axes-angle-deg", "60"),
        ("--ri-m", "0.075"),
        ("--rim-radius-m", "0.15"),
    ]
}

/// A first-order spin-up from rest with time constant 0.3 s (to `--omega-rad-s`).
pub const SPIN_UP_FROM_REST: [(&str, &str); 2] =
    [("--spin-up-from-rad-s", "0"), ("--time-constant-s", "0.3")];

/// The `bowl` binary under test.
pub const BOWL: &str = env!("CARGO_BIN_EXE_bowl");

/// A `bowl serve --pty` process (the virtual rig on a pseudo-terminal), killed when dropped.
pub struct Sim {
    child: Child,
    /// The pty's device path, as `bowl serve` printed it.
    pub path: String,
}

impl Sim {
    /// Starts `bowl serve --pty EXTRA...` and waits for the pty path it prints first.
    pub fn start(extra: &[&str]) -> Sim {
        let mut child = Command::new(BOWL)
            .args(["serve", "--pty"])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("bowl serve starts");
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .expect("bowl serve prints its pty");
        let path = line.trim().to_string();
        assert!(path.starts_with("/dev/"), "pty path, got {path:?}");
        Sim { child, path }
    }
}

impl Sim {
    /// Ends the rig its own way (SIGTERM, as `kill` sends) and waits until it has.
    pub fn terminate(&mut self) {
        use nix::sys::signal::{Signal, kill};
        let pid = nix::unistd::Pid::from_raw(self.child.id() as i32);
        kill(pid, Signal::SIGTERM).expect("SIGTERM sent");
        wait_within(
            &mut self.child,
            Duration::from_secs(5),
            "bowl serve after SIGTERM",
        );
    }
}

impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `bowl send PORT WORDS...` with a 3 s timeout: its exit code and standard output.
pub fn send(port: &str, words: &str) -> (i32, String) {
    let mut args = vec!["send", port, "--timeout-ms", "3000"];
    args.extend(words.split_whitespace());
    let out = bowl(&args);
    (out.status.code().unwrap_or(-1), stdout(&out))
}

/// `bowl serve`'s flags for a run of `seconds` with the timed commands `AT_MS:WORDS,...`.
pub fn timed(seconds: &str, commands: &[&str]) -> Vec<String> {
    let mut args = vec!["--seconds".to_string(), seconds.to_string()];
    for c in commands {
        args.extend(["--command".to_string(), (*c).to_string()]);
    }
    args
}

/// `bowl serve --pty` for `seconds` with the timed `commands`.
pub fn sim_timed(seconds: &str, commands: &[&str]) -> Sim {
    let args = timed(seconds, commands);
    Sim::start(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// `bowl serve --capture DIR/cap.bin ARGS...`: the capture's path.
pub fn sim_capture(dir: &Path, args: &[&str]) -> PathBuf {
    let capture = dir.join("cap.bin");
    let mut all = vec!["serve", "--capture", capture.to_str().unwrap()];
    all.extend_from_slice(args);
    let made = bowl(&all);
    assert!(made.status.success(), "{}", stdout(&made));
    capture
}

/// [`sim_capture`] of a run of `seconds` with the timed `commands`.
pub fn capture_timed(dir: &Path, seconds: &str, commands: &[&str]) -> PathBuf {
    let args = timed(seconds, commands);
    sim_capture(dir, &args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// `bowl replay CAPTURE --csv CSV`.
pub fn replay_to_csv(capture: &Path, csv: &Path) -> Output {
    bowl(&[
        "replay",
        capture.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ])
}

/// `bowl monitor PORT --plain --seconds SECONDS --log LOG` run to its end.
pub fn monitor_logged(port: &str, seconds: &str, log: &Path) -> Output {
    bowl(&[
        "monitor",
        port,
        "--seconds",
        seconds,
        "--plain",
        "--log",
        log.to_str().unwrap(),
    ])
}

/// All `child` wrote to its standard error.
pub fn stderr_of(child: &mut Child) -> String {
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    err
}

/// Runs `bowl ARGS` to its end and returns what it printed.
pub fn bowl(args: &[&str]) -> Output {
    Command::new(BOWL)
        .args(args)
        .env_remove("RUST_BACKTRACE")
        .env_remove("RUST_LIB_BACKTRACE")
        .output()
        .expect("bowl runs")
}

/// `bowl ARGS`, which must succeed, its standard output parsed as one JSON document.
pub fn json(args: &[&str]) -> serde_json::Value {
    success_json(&bowl(args), &format!("bowl {args:?}"))
}

/// The output of `what`, a run that must have succeeded: its standard output parsed as one
/// JSON document.
pub fn success_json(out: &Output, what: &str) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{what} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

/// Standard output as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The last line of standard output (the JSON summary), parsed.
pub fn last_json(o: &Output) -> serde_json::Value {
    let text = stdout(o);
    let line = text.lines().last().expect("a JSON summary line");
    serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"))
}

/// A path `name` in the temporary folder, named after `bowl predict` and this process (the
/// `bowl predict` tests' scratch files).
pub fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("bowl-predict-{}-{name}", std::process::id()))
}

/// A monitor's `--log` closed its own way: telemetry rows, then `monitor end` last (not a log
/// that just stops where the process died).
pub fn assert_log_closed(log: &Path) {
    let text = std::fs::read_to_string(log).unwrap();
    assert!(text.lines().count() > 3, "telemetry was logged:\n{text}");
    assert!(
        text.trim_end().ends_with(",monitor end"),
        "last row: {:?}",
        text.lines().last()
    );
}

/// An empty scratch directory named after the test and this process.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("bowl-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A fresh pseudo-terminal: its master side and the path of its slave side.
pub fn open_pty() -> (PtyMaster, String) {
    let master = posix_openpt(OFlag::O_RDWR | OFlag::O_NOCTTY).unwrap();
    grantpt(&master).unwrap();
    unlockpt(&master).unwrap();
    let path = ptsname_r(&master).unwrap();
    (master, path)
}

/// Spawns `command` with its stdout on a terminal (a fresh pty) and collects everything drawn
/// on that terminal until the child exits; join the handle to get the bytes.
pub fn spawn_on_terminal(command: &mut Command) -> (Child, JoinHandle<Vec<u8>>) {
    let (master, path) = open_pty();
    let screen = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)
        .unwrap();
    let child = command.stdout(Stdio::from(screen)).spawn().unwrap();
    let reader = std::thread::spawn(move || {
        let mut master = master;
        let mut all = Vec::new();
        let mut buf = [0u8; 8192];
        // Reading ends with EIO once the child exits and its side closes.
        while let Ok(n) = master.read(&mut buf) {
            if n == 0 {
                break;
            }
            all.extend_from_slice(&buf[..n]);
        }
        all
    });
    (child, reader)
}

/// Waits for `child` to end by itself; kills it and fails the test past `limit`.
pub fn wait_within(child: &mut Child, limit: Duration, what: &str) -> ExitStatus {
    let started = Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s;
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what} did not end by itself within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// A CSV file with a header line, as one column-name -> cell map per row.
pub fn csv_rows(path: &Path) -> Vec<HashMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|l| {
            header
                .iter()
                .zip(l.split(','))
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect()
        })
        .collect()
}

/// The residence time, s, of a granule started at rest at `ri` (m) in a bowl of rim `rim` (m)
/// turning at `omega(t)` rad/s: paper Eq. 5 (flat) or Eq. 9 with the corrected Coriolis term
/// (`coriolis`), g = 9.81, k2 = 5/7, static friction holding the granule while
/// r omega^2 <= mu g. RK4 at a 10 us step, the exit interpolated in its step: an independent
/// reference for the end-to-end tests.
pub fn reference_residence_s(
    omega: impl Fn(f64) -> f64,
    mu: f64,
    ri: f64,
    rim: f64,
    coriolis: bool,
) -> f64 {
    let (g, k2) = (9.81, 5.0 / 7.0);
    let c = if coriolis { 1.0 } else { 0.0 };
    let acc = |t: f64, r: f64, v: f64| {
        let w = omega(t);
        if v == 0.0 && r * w * w <= mu * g {
            0.0
        } else {
            k2 * (r * w * w - mu * g - c * 2.0 * mu * w * v)
        }
    };
    let (mut t, mut r, mut v, h) = (0.0, ri, 0.0, 1e-5);
    loop {
        let (k1r, k1v) = (v, acc(t, r, v));
        let (k2r, k2v) = (
            v + 0.5 * h * k1v,
            acc(t + 0.5 * h, r + 0.5 * h * k1r, v + 0.5 * h * k1v),
        );
        let (k3r, k3v) = (
            v + 0.5 * h * k2v,
            acc(t + 0.5 * h, r + 0.5 * h * k2r, v + 0.5 * h * k2v),
        );
        let (k4r, k4v) = (v + h * k3v, acc(t + h, r + h * k3r, v + h * k3v));
        let r1 = r + h / 6.0 * (k1r + 2.0 * k2r + 2.0 * k3r + k4r);
        let v1 = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if r1 >= rim {
            return t + h * (rim - r) / (r1 - r);
        }
        (t, r, v) = (t + h, r1, v1);
    }
}
