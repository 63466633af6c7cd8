//! `bowl serve` and `bowl sim` split: a transport must be named, and the reports no longer take
//! the transport's flags.

mod common;

use common::bowl;

#[test]
fn serve_without_a_transport_says_which_to_pick() {
    let out = bowl(&["serve"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--pty") && err.contains("--capture FILE --seconds S"),
        "{err}"
    );
    let out = bowl(&["serve", "--pty", "--line-noise-percent", "120"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--line-noise-percent must be between 0 and 100 (got 120)"),
        "{err}"
    );
}

#[test]
fn sim_is_reports_only() {
    for args in [&["sim"][..], &["sim", "--pty"]] {
        let out = bowl(args);
        assert!(!out.status.success(), "{args:?}");
    }
    let help = String::from_utf8_lossy(&bowl(&["sim", "--help"]).stdout).into_owned();
    for report in [
        "step",
        "family",
        "commission",
        "sweep",
        "stability",
        "trace",
    ] {
        assert!(help.contains(report), "{help}");
    }
    assert!(!help.contains("--pty"), "{help}");
}

/// The time constants (us) of the MODELS answer in a `bowl serve --capture` of 0.1 s.
fn served_time_constants_us(dir: &std::path::Path, rig_file: Option<&str>) -> [u64; 2] {
    let capture = dir.join("models.bin");
    let mut args = vec![
        "serve",
        "--capture",
        capture.to_str().unwrap(),
        "--seconds",
        "0.1",
        "--command",
        "0:models",
    ];
    if let Some(path) = rig_file {
        args.extend(["--rig-file", path]);
    }
    let out = bowl(&args);
    assert!(out.status.success(), "{}", common::stdout(&out));
    let raw = String::from_utf8_lossy(&std::fs::read(&capture).unwrap()).into_owned();
    // $M1,<per axis: identified, back-EMF, friction, time constant, ...>*CRC
    let line = raw
        .lines()
        .find(|l| l.starts_with("$M1,"))
        .expect("a MODELS answer");
    let fields: Vec<&str> = line.split(['*', ','].as_ref()).collect();
    [fields[5].parse().unwrap(), fields[11].parse().unwrap()]
}

#[test]
fn serve_runs_the_rig_a_rig_file_describes() {
    let dir = common::temp_dir("serve-rig-file");
    let heavy = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/rigs/heavy-bowl.toml");
    let nominal = served_time_constants_us(&dir, None);
    let found = served_time_constants_us(&dir, Some(heavy));
    // The virtual rig commissions itself on the heavy bowl (2.25x the precession and 3x the
    // spin inertia): the models it identifies answer that much slower.
    assert!(
        found[0] as f64 > 1.5 * nominal[0] as f64 && found[1] as f64 > 2.0 * nominal[1] as f64,
        "heavy {found:?} us, nominal {nominal:?} us"
    );
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[spin]\ninertia_kg_m2 = 0.0\n").unwrap();
    let out = bowl(&[
        "serve",
        "--capture",
        dir.join("x.bin").to_str().unwrap(),
        "--seconds",
        "1",
        "--rig-file",
        bad.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("line 2") && err.contains("inertia_kg_m2 = 0 is outside its range"),
        "{err}"
    );
}
