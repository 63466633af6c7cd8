//! `bowl predict --spin-up-from-rad-s W0 --time-constant-s TAU`: the chooser on a first-order
//! spin-up, from its precomputed error table when a tolerance is stated, each answer against
//! the tests' own independent RK4 reference.

mod common;

use common::{SPIN_UP_FROM_REST, bowl, json, predict_args};

/// The reference T of the Coriolis model (or the flat one) for a spin-up from `start` to
/// `end` rad/s with time constant `tau`, mu 0.029, ri 0.05 m, R 0.1 m.
fn reference(start: f64, end: f64, tau: f64, coriolis: bool) -> f64 {
    let omega = |t: f64| end + (start - end) * (-t / tau).exp();
    common::reference_residence_s(omega, 0.029, 0.05, 0.1, coriolis)
}

#[test]
fn a_spin_up_with_a_tolerance_is_read_from_the_table_and_meets_it() {
    for (start, end, tau, tolerance) in [
        (0.0, 3.0, 0.3, 1e-5),
        (1.0, 3.0, 2.0, 1e-6),
        (0.0, 6.0, 0.5, 1e-4),
    ] {
        let args = [
            "predict",
            "--omega-rad-s",
            &end.to_string(),
            "--spin-up-from-rad-s",
            &start.to_string(),
            "--time-constant-s",
            &tau.to_string(),
            "--tolerance",
            &tolerance.to_string(),
            "--json",
        ];
        let v = json(&args);
        let choice = &v["choice"];
        assert_eq!(choice["source"], "table", "{v}");
        assert_eq!(choice["choosing_evaluations"], 0, "{v}");
        assert_eq!(choice["method"], "rk4", "{v}");
        let coriolis = choice["model"] == "coriolis";
        let want = reference(start, end, tau, coriolis);
        let got = v["residence_time_s"].as_f64().unwrap();
        assert!(
            (got - want).abs() <= tolerance * want,
            "{args:?}: T {got} against {want}"
        );
        // The model answers for the Coriolis term within the tolerance too.
        let truth = reference(start, end, tau, true);
        assert!((got - truth).abs() <= tolerance * truth, "{v}");
        // The text says where the choice came from.
        let text = bowl(&args[..args.len() - 1]);
        let text = String::from_utf8_lossy(&text.stdout);
        assert!(
            text.contains("chosen from the precomputed error table, without running the scene"),
            "{text}"
        );
    }
}

#[test]
fn a_derived_tolerance_runs_only_the_spread_and_the_mcu_runs_the_pilot() {
    let base = predict_args(&SPIN_UP_FROM_REST, &["--json"]);
    // The tolerance from the parameters' uncertainty (the default): the spread's runs, then
    // the method from the table.
    let v = json(&base);
    let choice = &v["choice"];
    assert_eq!(choice["source"], "table", "{v}");
    assert!(choice["choosing_evaluations"].as_u64().unwrap() > 0, "{v}");
    let spread = choice["spread_rel"].as_f64().unwrap();
    let tolerance = choice["tolerance_rel"].as_f64().unwrap();
    assert!((tolerance - 0.1 * spread).abs() <= 1e-12, "{v}");
    let got = v["residence_time_s"].as_f64().unwrap();
    let truth = reference(0.0, 3.0, 0.3, true);
    assert!((got - truth).abs() <= tolerance * truth, "{v}");
    // The spread by the tests' own reference: mu 20 % either way moves T by most of it.
    let mu_moves = [0.8, 1.2].map(|f| {
        let omega = |t: f64| 3.0 * (1.0 - (-t / 0.3).exp());
        (common::reference_residence_s(omega, 0.029 * f, 0.05, 0.1, true) - truth).abs() / truth
    });
    let mu_part = mu_moves[0].max(mu_moves[1]);
    assert!(
        mu_part > 0.5 * spread && mu_part < spread,
        "{mu_part} of {spread}"
    );
    let text = bowl(&base[..base.len() - 1]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("chosen from the precomputed error table (the runs were the spread's"),
        "{text}"
    );
    let mut mcu = base.to_vec();
    mcu.extend(["--tolerance", "1e-4", "--target", "mcu"]);
    let v = json(&mcu);
    assert_eq!(v["choice"]["source"], "pilot-runs", "{v}");
    assert!(
        v["choice"]["choosing_evaluations"].as_u64().unwrap() > 0,
        "{v}"
    );
}

#[test]
fn bad_spin_ups_are_named_in_plain_words() {
    // A valid spin-up (from 1 rad/s, time constant 0.3 s) unless the case overrides it.
    const SPIN_UP: [&str; 4] = ["--spin-up-from-rad-s", "1", "--time-constant-s", "0.3"];
    let must_choose = "--spin-up-from-rad-s lets the chooser pick the model and the method";
    for (spin_up, extra, words) in [
        (
            vec!["--spin-up-from-rad-s", "1", "--time-constant-s", "0"],
            vec![],
            "--time-constant-s 0: the spin-up's time constant must be a positive number",
        ),
        (
            vec!["--spin-up-from-rad-s=-1", "--time-constant-s", "0.3"],
            vec![],
            "--spin-up-from-rad-s -1: the start speed must be zero or positive",
        ),
        (
            SPIN_UP.to_vec(),
            vec!["--omega-rad-s", "0"],
            "--omega-rad-s 0: the speed the spin-up approaches must be positive",
        ),
        (SPIN_UP.to_vec(), vec!["--model", "flat"], must_choose),
        (SPIN_UP.to_vec(), vec!["--model", "rolling"], must_choose),
        (
            SPIN_UP.to_vec(),
            vec!["--target-time-s", "1"],
            "cannot be used with",
        ),
    ] {
        let mut all = vec!["predict"];
        all.extend(spin_up);
        all.extend(extra);
        let out = bowl(&all);
        assert!(!out.status.success(), "{all:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(words), "{all:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// A flat-model choice claims its whole error: the integrator's plus the flat model's own (the
/// Coriolis term it leaves out), and T is within that claim of the Coriolis reference.
#[test]
fn a_flat_choice_claims_the_flat_models_own_error_too() {
    let v = json(&predict_args(
        &SPIN_UP_FROM_REST,
        &["--tolerance", "2e-2", "--json"],
    ));
    let c = &v["choice"];
    assert_eq!(c["model"], "flat", "{c}");
    let f = |k: &str| c[k].as_f64().unwrap();
    assert_eq!(f("model_error_rel"), f("coriolis_effect_rel"));
    assert!(
        (f("estimated_error_rel") - f("method_error_rel") - f("model_error_rel")).abs() < 1e-15
    );
    let t = v["residence_time_s"].as_f64().unwrap();
    let truth = reference(0.0, 3.0, 0.3, true);
    let actual = (t - truth).abs() / truth;
    assert!(
        actual <= f("estimated_error_rel"),
        "actual {actual:e} vs claimed {c}"
    );
    assert!(actual <= f("tolerance_rel"));
}
