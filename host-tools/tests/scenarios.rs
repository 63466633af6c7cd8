//! The scenarios of `tests/scenarios/*.toml` on the host virtual rig: each one through
//! `bowl serve --capture FILE --seconds S --command AT_MS:WORDS ...` (the rig, faster than real
//! time, its raw output to a file) and `bowl replay FILE --csv OUT` (that output as telemetry
//! rows), then every expectation checked (`scenario::check`). All scenarios run; the failures
//! are listed together, each in words.
//!
//! Run: `cargo test -p host-tools --test scenarios`.

mod common;
mod scenario;

use std::path::Path;

use common::{bowl, temp_dir};
use scenario::Scenario;

/// Runs `s` on the host virtual rig in `dir`; returns its telemetry rows and answers.
fn run_on_host(s: &Scenario, dir: &Path) -> (Vec<scenario::Row>, Vec<scenario::Answer>) {
    let capture = dir.join("capture.bin");
    let csv = dir.join("telemetry.csv");
    let seconds = s.seconds.to_string();
    let mut args = vec![
        "serve",
        "--capture",
        capture.to_str().unwrap(),
        "--seconds",
        &seconds,
    ];
    let commands = s.serve_commands();
    for c in &commands {
        args.extend(["--command", c]);
    }
    let out = bowl(&args);
    assert!(
        out.status.success(),
        "bowl {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&capture).unwrap();
    (
        scenario::replay_rows(&capture, &csv, "the virtual rig's output"),
        scenario::answers(&bytes, s.commands.len()),
    )
}

/// Loads, runs and checks one file; the failures in words.
fn failures_of(path: &Path, dir: &Path, edit: impl FnOnce(&mut Scenario)) -> Vec<String> {
    let file = scenario::name(path);
    let mut s = match scenario::load(path) {
        Ok(s) => s,
        Err(e) => return vec![e],
    };
    edit(&mut s);
    let (rows, answers) = run_on_host(&s, dir);
    scenario::check(&file, &s, &rows, &answers, None)
}

#[test]
fn every_scenario_holds_on_the_host_virtual_rig() {
    let files = scenario::files();
    assert!(
        files.len() >= 8,
        "tests/scenarios holds {} files",
        files.len()
    );
    let dir = temp_dir("scenarios");
    let mut failures = Vec::new();
    for path in &files {
        let started = std::time::Instant::now();
        let run_dir = dir.join(path.file_stem().unwrap());
        std::fs::create_dir_all(&run_dir).unwrap();
        let mut found = failures_of(path, &run_dir, |_| {});
        if !found.is_empty() {
            found.push(format!(
                "(the run's capture and telemetry: {}/capture.bin, telemetry.csv)",
                run_dir.display()
            ));
        }
        println!(
            "{}: {} ({:.1} s)",
            scenario::name(path),
            if found.is_empty() { "ok" } else { "FAILED" },
            started.elapsed().as_secs_f64()
        );
        failures.extend(found);
    }
    if failures.is_empty() {
        let _ = std::fs::remove_dir_all(&dir);
    }
    assert!(
        failures.is_empty(),
        "scenario expectation(s) failed on the host virtual rig:\n  {}",
        failures.join("\n  ")
    );
}

/// The checks can fail: the speed-up scenario with its settled window moved 10 % up, a command's
/// expected answer changed, and an expected state changed, each fails in words.
#[test]
fn a_wrong_expectation_fails_and_says_where() {
    let path = scenario::folder().join("speed-up.toml");
    let dir = temp_dir("scenarios-wrong");
    let found = failures_of(&path, &dir, |s| {
        let e = s
            .expects
            .iter_mut()
            .find(|e| e.window.contains_key("prec_measured_mrad_s"))
            .expect("speed-up.toml has a precession speed window");
        let w = e.window.get_mut("prec_measured_mrad_s").unwrap();
        *w = [w[0] + 300, w[1] + 300];
        s.commands[0].answer = "RANGE".into();
        let running = s
            .expects
            .iter_mut()
            .find(|e| e.state == ["running"])
            .expect("speed-up.toml expects running");
        running.state = vec!["idle".into()];
    });
    let _ = std::fs::remove_dir_all(&dir);
    let text = found.join("\n");
    assert_eq!(found.len(), 3, "{text}");
    assert!(
        text.contains("tests/scenarios/speed-up.toml")
            && text.contains("prec_measured_mrad_s in [")
            && text.contains("command `speed 3000 3000`: expected the answer RANGE, got done")
            && text.contains("expected state idle, got running"),
        "{text}"
    );
}

#[test]
fn a_scenario_that_checks_nothing_or_outside_its_run_is_refused() {
    let dir = temp_dir("scenarios-refused");
    let cases = [
        ("seconds = 5\ndescription = \"x\"\n", "no [[expect]]"),
        (
            "seconds = 5\ndescription = \"x\"\n[[expect]]\nwhat = \"w\"\nfrom_ms = 0\nto_ms = 9000\nfault = \"none\"\n",
            "not inside the run",
        ),
        (
            "seconds = 5\ndescription = \"x\"\n[[expect]]\nwhat = \"w\"\nfrom_ms = 0\nto_ms = 1000\nstate = [\"Runing\"]\n",
            "unknown state Runing",
        ),
        (
            // The words of the CSV and `bowl send status`, not the code's names.
            "seconds = 5\ndescription = \"x\"\n[[expect]]\nwhat = \"w\"\nfrom_ms = 0\nto_ms = 1000\nstate = [\"Running\"]\n",
            "unknown state Running",
        ),
        (
            "seconds = 5\ndescription = \"x\"\n[[expect]]\nwhat = \"w\"\nfrom_ms = 0\nto_ms = 1000\nfault = \"SensorLostOrStallSpin\"\n",
            "unknown fault SensorLostOrStallSpin",
        ),
        (
            "seconds = 5\ndescription = \"x\"\n[[expect]]\nwhat = \"w\"\nfrom_ms = 0\nto_ms = 1000\n",
            "expects nothing",
        ),
    ];
    for (text, said) in cases {
        let path = dir.join("bad.toml");
        std::fs::write(&path, text).unwrap();
        let err = scenario::load(&path).expect_err(text);
        assert!(err.contains(said), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
