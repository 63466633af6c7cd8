//! `bowl predict --model bowl` end to end (issue 30): bad input said in words. (The answers
//! themselves are checked in predict_bowl.rs.)

mod common;

use common::{bowl, bowl_args, json};

/// Bad input is said in plain words naming the flag and its limit, exit 1, no Rust names.
#[test]
fn bad_bowl_input_is_said_in_words() {
    for (wall, extra, want) in [
        (
            ["0", "0.02", "0"],
            vec![],
            "--wall-angle-deg 0: the wall's angle from the bottom must be above 0 and at most 90",
        ),
        (
            ["179.9", "0.02", "0"],
            vec![],
            "--wall-angle-deg 179.9: the wall's angle from the bottom must be above 0 and at most 90",
        ),
        (
            ["60", "-0.01", "0"],
            vec![],
            "--wall-height-m must be 0 or more",
        ),
        (
            ["90", "0.08", "0.07"],
            vec![],
            // The values and the limit: the words named the flags alone.
            "--ri-m 0.0375 m: the granule released there already touches the corner between \
             bottom and wall (--fillet-radius-m 0.07 m, widened by the granule's radius \
             --particle-radius-m 0.003 m, starts 0.00500 m from the axis); give --ri-m below \
             0.00500 m, or a smaller fillet or granule",
        ),
        // A fillet above its wall, or with no wall: the granule climbed the arc past the lip
        // and the time was a taller bowl's, without a word.
        (
            ["60", "0.01", "0.05"],
            vec![],
            "--fillet-radius-m 0.05 m rises 0.0250 m up a wall at 60 deg before it meets it, \
             above the wall's height (--wall-height-m 0.01 m): a fillet ends on its wall; give a \
             fillet of at most 0.02 m, or a taller wall",
        ),
        (
            ["90", "0", "0.005"],
            vec![],
            "--fillet-radius-m 0.005 m with no wall (--wall-height-m 0, a bare rim)",
        ),
        // A fillet wider than the bottom: "give a smaller --ri-m" was no way out at --ri-m 0.
        (
            ["45", "0.06", "0.2"],
            vec!["--ri-m", "0"],
            "--fillet-radius-m 0.2 m, widened by the granule's radius --particle-radius-m 0.003 \
             m, reaches the bowl's axis: the corner takes the whole bottom (--rim-radius-m 0.075 \
             m) and the granule has nowhere to start; give a smaller fillet",
        ),
        (
            ["60", "0.08", "0"],
            vec!["--particle-radius-m", "0.07"],
            "--particle-radius-m 0.07 m, starts 0.03415 m from the axis); give --ri-m below \
             0.03415 m",
        ),
        (
            ["60", "0.02", "0"],
            vec!["--particle-radius-m", "1"],
            "--particle-radius-m 1 m is not smaller than the bowl's radius R = 0.075 m",
        ),
        (
            ["90", "0.001", "0"],
            vec![],
            "--wall-height-m 0.001 m is lower than the granule's radius 0.003 m",
        ),
        (
            ["60", "0.02", "0"],
            vec!["--restitution", "1.5"],
            "--restitution must lie between 0 and 1",
        ),
        (
            ["60", "0.02", "0"],
            vec!["--release-azimuth-deg", "0,x"],
            "is not a number of degrees",
        ),
        (
            ["60", "0.02", "0"],
            vec!["--max-time-s", "0"],
            "--max-time-s 0 s: each release is followed this long, so it must be above 0",
        ),
        (
            ["60", "0.02", "0"],
            vec!["--method", "semi-implicit"],
            "--method semi-implicit is not offered for the bowl model",
        ),
        // A speed whose square overflows: it used to reach the integrator and come back as
        // "--step-s and --tol must be positive numbers", flags the user never gave.
        (
            ["60", "0.02", "0"],
            vec!["--spin-rad-s", "-1e200"],
            "--spin-rad-s is outside the magnitudes the model computes with (0, or 1e-75 to 1e75",
        ),
        (
            ["60", "0.02", "0"],
            vec!["--precession-rad-s", "1e-100"],
            "--precession-rad-s is outside the magnitudes",
        ),
    ] {
        let args = bowl_args("1", "1", "60", wall, &extra);
        let out = bowl(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!err.contains("Invalid"), "no Rust names: {err}");
    }
    // The same refusal through the chooser (`--model auto`, the default) and the rolling model.
    for model in ["auto", "rolling"] {
        let out = bowl(&[
            "predict",
            "--model",
            model,
            "--axes-angle-deg",
            "60",
            "--precession-rad-s",
            "1e200",
            "--spin-rad-s",
            "1",
        ]);
        assert_eq!(out.status.code(), Some(1), "{model}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--precession-rad-s is outside the magnitudes"),
            "{model}: {err}"
        );
    }
    let out = bowl(&["predict", "--model", "bowl", "--axes-angle-deg", "60"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("the bowl model needs --precession-rad-s")
    );
}

/// A tilt of 90 deg and a release radius at the rim are refused with the values given (the
/// words named neither: "--axes-angle-deg must be at least 0 and below 90 degrees"), through
/// the bowl, rolling and chooser models alike.
#[test]
fn a_refused_tilt_or_release_radius_is_echoed() {
    for model in ["bowl", "rolling", "auto"] {
        for (flag, value, want) in [
            (
                "--axes-angle-deg",
                "90",
                "--axes-angle-deg 90: the angle between the bowl's axis and the vertical must \
                 be at least 0 and below 90 degrees",
            ),
            (
                "--ri-m",
                "0.075",
                "--ri-m 0.075 m is not inside the bottom's radius --rim-radius-m 0.075 m",
            ),
        ] {
            let args = bowl_args("1", "1", "60", ["90", "0", "0"], &[flag, value]);
            let mut args: Vec<&str> = args.clone();
            let m = args.iter().position(|a| *a == "--model").unwrap();
            args[m + 1] = model;
            if model == "rolling" {
                // The rolling model has no wall.
                for f in [
                    "--wall-angle-deg",
                    "--wall-height-m",
                    "--fillet-radius-m",
                    "--restitution",
                    "--max-time-s",
                ] {
                    if let Some(i) = args.iter().position(|a| *a == f) {
                        args.drain(i..i + 2);
                    }
                }
            }
            let out = bowl(&args);
            assert_eq!(out.status.code(), Some(1), "{args:?}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(err.contains(want), "{args:?}: {err}");
        }
    }
}

/// A release that rolls to rest and is held there (5 deg, 3.3 rad/s, released at 150 deg) took
/// more than the 2 000 000 steps of the cap at `--tol 1e-16`: the steps straddled the switch of
/// the equations at rest. The rest is now an event and the run answers, in about 22 000
/// right-hand sides. (The cap's words: `rolling_words`' test.)
#[test]
fn a_release_held_on_the_way_answers_at_the_tightest_tolerance() {
    let v = json(&[
        "predict",
        "--model",
        "rolling",
        "--axes-angle-deg",
        "5",
        "--rim-radius-m",
        "0.075",
        "--ri-m",
        "0.0229",
        "--sliding-mu",
        "0.2",
        "--precession-rad-s",
        "3.3",
        "--spin-rad-s",
        "3.3",
        "--release-azimuth-deg",
        "150",
        "--tol",
        "1e-16",
        "--json",
    ]);
    assert_eq!(v["releases_leaving"], 1, "{v}");
    assert!(
        v["per_release"][0]["regime"]["held"].as_f64().unwrap() > 0.1,
        "{v}"
    );
    assert!(v["rhs_evaluations"].as_u64().unwrap() < 100_000, "{v}");
}
