//! Flags that say what they mean: negative numbers taken as values (and judged in words), the
//! rod's horizontal offset under its own name, and what holds a granule when nothing turns.

mod common;

use common::{bowl, bowl_args, predict_args, rig_axis_speed, tilted_rig};

fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let out = bowl(args);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_negative_speed_is_a_value_judged_in_words() {
    let (code, _, err) = run(&["predict", "--omega-rad-s", "-3"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(!err.contains("unexpected argument"), "{err}");
    assert!(
        err.contains("--omega-rad-s -3 rad/s") && err.contains("0 or more"),
        "{err}"
    );
    let (code, _, err) = run(&["predict", "--mu", "-0.1"]);
    assert_eq!(code, Some(1));
    assert!(
        err.contains("--mu -0.1: the rolling resistance must be 0 or more"),
        "{err}"
    );
}

#[test]
fn a_negative_spin_is_taken() {
    let (code, out, err) = run(&predict_args(
        &tilted_rig("bowl", "1.2"),
        &["--spin-rad-s", "-2.7", "--release-azimuth-deg", "0"],
    ));
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("w2 -2.7 rad/s"), "{out}");
    let (code, out, err) = run(&["kinematics", "--spin-rad-s", "-1.8"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!out.is_empty());
}

#[test]
fn the_rods_offset_has_its_name_and_the_old_one_still_works() {
    let w = rig_axis_speed();
    let scene = |flag: &str| {
        run(&predict_args(
            &tilted_rig("rolling", &w),
            &[flag, "0.1", "--release-azimuth-deg", "0"],
        ))
    };
    let new = scene("--rod-offset-m");
    let old = scene("--rod-length-m");
    assert_eq!(new.0, Some(0), "{}", new.2);
    assert!(new.1.contains("L 0.1 m"), "{}", new.1);
    assert_eq!(new.1, old.1, "the alias gives the same answer");
    let (_, help, _) = run(&["predict", "--help"]);
    assert!(
        help.contains("--rod-offset-m") && help.contains("rod-length-m"),
        "{help}"
    );
    assert!(help.contains("horizontal offset L"), "{help}");
}

#[test]
fn no_turning_and_no_friction_is_not_said_to_be_friction() {
    let (code, out, _) = run(&["predict", "--omega-rad-s", "0", "--mu", "0"]);
    assert_eq!(code, Some(0));
    assert!(!out.contains("friction holds it"), "{out}");
    assert!(
        out.contains("the bowl is not turning") && out.contains("no friction"),
        "{out}"
    );
    let (_, out, _) = run(&["predict", "--omega-rad-s", "3", "--mu", "0.5"]);
    assert!(out.contains("friction holds it"), "{out}");
}

#[test]
fn a_drop_share_outside_0_to_50_pct_is_said_in_words() {
    for bad in ["80", "-5"] {
        let (code, _, err) = run(&[
            "sim",
            "faults",
            "--rig-file",
            "../tests/rigs/family-60.toml",
            "--drop-pulses-pct",
            bad,
        ]);
        // A value on the command line: a usage error (docs/console.md, exit codes).
        assert_eq!(code, Some(2), "{bad}: {err}");
        assert!(
            err.contains("--drop-pulses-pct must be from 0 to 50") && err.contains(bad),
            "{bad}: {err}"
        );
    }
    // Not a number at all: said so before any range (the parser of every number flag).
    let (code, _, err) = run(&["sim", "faults", "--drop-pulses-pct", "NaN"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("`NaN` is not a number"), "{err}");
}

/// A list of negative release azimuths is a value: `--release-azimuth-deg -30,-60` was refused
/// as "unexpected argument '-3' found" (not a number, so clap read it as flags) while `-30`
/// alone and `--release-azimuth-deg=-30,-60` were taken.
#[test]
fn a_list_of_negative_azimuths_is_a_value() {
    let extra = |az: &'static str| {
        let mut v = vec!["--speed-range", "false", "--json"];
        v.extend(az.split(' '));
        v
    };
    let wall = ["60", "0.02", "0"];
    let spaced = run(&bowl_args(
        "1.2",
        "-2.7",
        "60",
        wall,
        &extra("--release-azimuth-deg -30,-60"),
    ));
    assert_eq!(spaced.0, Some(0), "{}", spaced.2);
    let joined = run(&bowl_args(
        "1.2",
        "-2.7",
        "60",
        wall,
        &extra("--release-azimuth-deg=-30,-60"),
    ));
    assert_eq!(joined.0, Some(0), "{}", joined.2);
    assert_eq!(spaced.1, joined.1, "the two spellings give one answer");
    let v: serde_json::Value = serde_json::from_str(&spaced.1).unwrap();
    let az: Vec<_> = v["per_release"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["azimuth_deg"].as_f64())
        .collect();
    assert_eq!(az, [Some(-30.0), Some(-60.0)], "{v}");
}

/// A negative value with a signed exponent, a leading dot or no finite value is a value too:
/// `--spin-rad-s -1e-3` was refused as "unexpected argument '-1' found" (clap reads only
/// unsigned exponents as numbers), where `--spin-rad-s=-1e-3` was taken.
#[test]
fn a_negative_value_in_any_spelling_is_a_value() {
    fn scene<'a>(spin: &'a str, az: &'a str) -> Vec<&'a str> {
        predict_args(
            &tilted_rig("bowl", "1.2"),
            &["--spin-rad-s", spin, "--release-azimuth-deg", az],
        )
    }
    let (code, out, err) = run(&scene("-2.7e-0", "0"));
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("w2 -2.7 rad/s"), "{out}");
    let (code, exp, err) = run(&scene("-27e-1", "-.5e+1,-1e1"));
    assert_eq!(code, Some(0), "{err}");
    let (code, plain, err) = run(&scene("-2.7", "-5,-10"));
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(exp, plain, "one answer for both spellings");
    let (code, _, err) = run(&["predict", "--omega-rad-s", "-1e-3"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        !err.contains("unexpected argument") && err.contains("0 or more"),
        "{err}"
    );
    let (code, _, err) = run(&scene("-inf", "0"));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("-inf is out of range"), "{err}");
}
