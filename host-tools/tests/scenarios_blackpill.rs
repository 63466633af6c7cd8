//! The scenarios of `tests/scenarios/*.toml` on the emulated Black Pill (the exact release image
//! on the emulated STM32F411, `tests/blackpill`), checked by the same code as on the host rig and
//! QEMU (`scenario::check`). The board runs in Python: `tests/blackpill/run_scenarios.py OUTDIR`
//! sends each command by `bowl send` when the board's clock reaches its time (`inject` goes to the
//! plant) and writes, per scenario, `capture.bin` (the board's output) and `sent.json` (answers,
//! board times before each command and after its answer). This test replays, rebases and checks
//! what is there.
//!
//! It needs the image, the plant library and the emulator, which `bash tests/run` has only after
//! its host step, so it is ignored there and run by the Black Pill step:
//! `BLACKPILL_SCENARIOS=OUTDIR cargo test -p host-tools --test scenarios_blackpill -- --ignored`.

mod common;
mod scenario;

use std::path::Path;

/// What `run_scenarios.py` wrote for one scenario.
#[derive(serde::Deserialize)]
struct Sent {
    answers: Vec<String>,
    sent_ms: Vec<(u32, u32)>,
}

#[test]
#[ignore = "run by the Black Pill step of bash tests/run (needs the image and the emulator)"]
fn the_black_pill_runs_hold_every_expectation() {
    let dir = std::env::var("BLACKPILL_SCENARIOS")
        .expect("BLACKPILL_SCENARIOS names the folder tests/blackpill/run_scenarios.py wrote");
    let dir = Path::new(&dir);
    let mut failures = Vec::new();
    let mut checked = 0;
    for path in scenario::files() {
        let run_dir = dir.join(path.file_stem().unwrap());
        if !run_dir.join("sent.json").exists() {
            continue;
        }
        let file = scenario::name(&path);
        let s = scenario::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let text = std::fs::read_to_string(run_dir.join("sent.json")).unwrap();
        let sent: Sent = serde_json::from_str(&text).unwrap();
        assert_eq!(
            sent.answers.len(),
            s.commands.len(),
            "{file}: sent.json has {} answers for {} commands",
            sent.answers.len(),
            s.commands.len()
        );
        let capture = run_dir.join("capture.bin");
        let csv = run_dir.join("telemetry.csv");
        let mut rows = scenario::replay_rows(&capture, &csv, "the Black Pill's output");
        scenario::rebase(&s, &mut rows, &sent.sent_ms);
        let before: Vec<u32> = sent.sent_ms.iter().map(|&(b, _)| b).collect();
        let mut found = scenario::check(&file, &s, &rows, &sent.answers, Some(&before));
        let delays: Vec<u32> = s
            .commands
            .iter()
            .zip(&sent.sent_ms)
            .map(|(c, &(_, after))| after.saturating_sub(c.at_ms))
            .collect();
        println!(
            "{file} on the emulated Black Pill: {} (commands complete {delays:?} ms of board time after their scenario time)",
            if found.is_empty() { "ok" } else { "FAILED" }
        );
        if !found.is_empty() {
            found.push(format!(
                "(the board's capture and telemetry: {}/capture.bin, telemetry.csv)",
                run_dir.display()
            ));
        }
        failures.extend(found);
        checked += 1;
    }
    assert!(
        checked > 0,
        "no scenario run found in {} (run tests/blackpill/run_scenarios.py first)",
        dir.display()
    );
    assert!(
        failures.is_empty(),
        "scenario expectation(s) failed on the emulated Black Pill:\n  {}",
        failures.join("\n  ")
    );
}
