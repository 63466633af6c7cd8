//! The scenarios of `tests/scenarios/*.toml` on the emulated board: the firmware's `qemu-rig`
//! image on QEMU (virtual time) with the simulated plant, each command sent by `bowl send` when
//! the board's clock reaches its time (a step no sooner after the previous step's answer than
//! the scenario spaces them), the board's raw output captured and decoded by
//! `bowl replay --csv`, then checked by the same code as on the host rig (`scenario::check`).
//! A command reaches the board later than its scenario time (the command's transit); the
//! telemetry after it is judged on the scenario's clock from when it really went out
//! (`scenario::rebase`), and the delays are printed.
//!
//! Where `qemu-system-arm` is not installed this says so and checks nothing (the host rig's
//! scenarios still run). Run: `cargo test -p host-tools --test scenarios_qemu -- --nocapture`.

#![cfg(unix)]

mod common;
mod scenario;

use std::io::Read;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use bowl_emulator::board::Board;
use bowl_emulator::splitter::Splitter;
use bowl_emulator::{image, qemu};
use common::{BOWL, temp_dir};
use scenario::Scenario;

/// `done`, or the rejection's wire token, from what `bowl send` said and its exit code.
fn answer(rc: i32, text: &str) -> scenario::Answer {
    match rc {
        0 => "done".into(),
        1 => text
            .split_once("): ")
            .and_then(|(_, rest)| rest.split_whitespace().next())
            .unwrap_or("rejected")
            .to_string(),
        _ => format!("no answer (bowl send exited {rc}: {})", text.trim()),
    }
}

/// Runs `s` on a freshly booted board; its telemetry rows (on the scenario's clock), answers,
/// and the board times from just before each command was sent to just after its answer.
fn run_on_board(
    s: &Scenario,
    elf: &Path,
    dir: &Path,
) -> (Vec<scenario::Row>, Vec<scenario::Answer>, Vec<(u32, u32)>) {
    let end_ms = (s.seconds * 1000.0) as u32;
    // The board ends its run by itself only as a safety net (it is stopped when done): room for
    // the scenario and up to 30 s of board time per command of the harness being late. The
    // board runs faster than real time while each `bowl send` is a process of its own: on a
    // loaded machine (a CI run beside other builds) 3 s a command was not enough, the board
    // ended its run in the middle of the lowest-speed scenario and the harness read that as
    // "the board stopped sending telemetry".
    let seconds = format!(
        "seconds={}",
        end_ms / 1000 + 30 * s.commands.len() as u32 + 60
    );
    let board = Board::boot_with(elf, &["-append", &seconds]);
    let split = Splitter::start(board.usart.try_clone().unwrap(), true);
    // Everything the board sends, as a capture file holds it.
    let raw = Arc::new(Mutex::new(Vec::new()));
    {
        let raw = raw.clone();
        let mut monitor = std::fs::File::open(split.monitor_pty().unwrap()).unwrap();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = monitor.read(&mut buf) {
                if n == 0 {
                    break;
                }
                raw.lock().unwrap().extend_from_slice(&buf[..n]);
            }
        });
    }
    let bowl_path = Path::new(BOWL);
    split.wait_device_ms(0, 0);
    // The host-silence check off: the harness PINGs through `bowl send`, one process a time,
    // which on a loaded machine cannot keep up with 3 s of a board running faster than real
    // time. (The host rig's scenarios run with it on; firmware/tests/qemu_rig_e2e.rs tests it.)
    let (rc, text) = split.send(bowl_path, &["set", "LINK_TIMEOUT_MS", "0"]);
    assert_eq!(rc, 0, "the board takes SET LINK_TIMEOUT_MS 0: {text}");
    let mut order: Vec<usize> = (0..s.commands.len()).collect();
    order.sort_by_key(|&i| s.commands[i].at_ms);
    let mut answers = vec![String::new(); s.commands.len()];
    let mut sent = vec![(0, 0); s.commands.len()];
    // Each step (the commands due at one scenario time) goes out no sooner after the previous
    // step's last answer than the scenario spaces them: a late step never squeezes the next.
    let mut previous: Option<(u32, u32)> = None; // (scenario time, board time of its last answer)
    let wait_until = |due_ms: u32| {
        let now = split.last().time_ms;
        if now < due_ms {
            split.wait_device_ms_alive(bowl_path, now, due_ms - now);
        }
    };
    for i in order {
        let c = &s.commands[i];
        match previous {
            Some((at, _)) if at == c.at_ms => {}
            Some((at, done)) => wait_until(done + (c.at_ms - at)),
            None => wait_until(c.at_ms),
        }
        let before = split.last().time_ms;
        let words: Vec<&str> = c.send.split_whitespace().collect();
        let (rc, text) = split.send(bowl_path, &words);
        answers[i] = answer(rc, &text);
        sent[i] = (before, split.last().time_ms);
        previous = Some((c.at_ms, sent[i].1));
    }
    // As long after the last step as the scenario runs after it.
    wait_until(previous.map_or(end_ms, |(at, done)| done + (end_ms - at)));
    // Let the relay hand over the last bytes, then stop the board.
    std::thread::sleep(std::time::Duration::from_millis(300));
    drop(board);
    let capture = dir.join("capture.bin");
    let csv = dir.join("telemetry.csv");
    std::fs::write(&capture, &*raw.lock().unwrap()).unwrap();
    let mut rows = scenario::replay_rows(&capture, &csv, "the board's output");
    scenario::rebase(s, &mut rows, &sent);
    (rows, answers, sent)
}

#[test]
fn every_scenario_holds_on_the_emulated_board() {
    if !qemu::installed() {
        eprintln!("NOTE: qemu-system-arm is not installed: the scenarios ran on the host rig only");
        return;
    }
    let elf = image::build(image::RIG_IMAGE).expect("the qemu-rig image builds");
    let dir = temp_dir("scenarios-qemu");
    let only = std::env::var("SCENARIO").ok();
    let mut failures = Vec::new();
    for path in scenario::files() {
        let file = scenario::name(&path);
        if only.as_ref().is_some_and(|o| !file.contains(o.as_str())) {
            continue;
        }
        let s = scenario::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let started = Instant::now();
        let run_dir = dir.join(path.file_stem().unwrap());
        std::fs::create_dir_all(&run_dir).unwrap();
        let (rows, answers, sent) = run_on_board(&s, &elf, &run_dir);
        let delays: Vec<u32> = s
            .commands
            .iter()
            .zip(&sent)
            .map(|(c, &(_, after))| after.saturating_sub(c.at_ms))
            .collect();
        let before: Vec<u32> = sent.iter().map(|&(b, _)| b).collect();
        let mut found = scenario::check(&file, &s, &rows, &answers, Some(&before));
        if !found.is_empty() {
            found.push(format!(
                "(the board's capture and telemetry, on its own clock: {}/capture.bin, \
                 telemetry.csv; board time before each command and after its answer: {sent:?})",
                run_dir.display()
            ));
        }
        println!(
            "{file} on the emulated board: {} ({:.1} s; commands complete {:?} ms of board time after their scenario time)",
            if found.is_empty() { "ok" } else { "FAILED" },
            started.elapsed().as_secs_f64(),
            delays
        );
        failures.extend(found);
    }
    if failures.is_empty() {
        let _ = std::fs::remove_dir_all(&dir);
    }
    assert!(
        failures.is_empty(),
        "scenario expectation(s) failed on the emulated board:\n  {}",
        failures.join("\n  ")
    );
}
