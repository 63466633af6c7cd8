//! `bowl predict --model auto` on the tilted bowl: the chooser over the whole hierarchy picks
//! the least model that meets the tolerance, says why the cheaper ones do not, and its answer is
//! within the tolerance of the full bowl model run independently (docs/model.md §12).

mod common;

use common::json;

const SCENE: [&str; 8] = [
    "--rim-radius-m",
    "0.075",
    "--ri-m",
    "0.0375",
    "--release-azimuth-deg",
    "all",
    "--max-time-s",
    "5",
];

fn args<'a>(tilt: &'a str, w: &'a str, mu_s: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "predict",
        "--axes-angle-deg",
        tilt,
        "--precession-rad-s",
        w,
        "--spin-rad-s",
        w,
        "--sliding-mu",
        mu_s,
        "--json",
    ];
    a.extend(SCENE);
    a.extend(extra);
    a
}

/// The chooser's answer and the bowl model's own at rtol 1e-10 (the reference).
fn chosen_and_reference(
    tilt: &str,
    w: &str,
    mu_s: &str,
    tol: &str,
    wall: &[&str],
) -> (serde_json::Value, f64) {
    let mut extra = vec!["--tolerance", tol];
    extra.extend(wall);
    let v = json(&args(tilt, w, mu_s, &extra));
    let mut reference = vec![
        "--model",
        "bowl",
        "--tol",
        "1e-10",
        "--speed-range",
        "false",
    ];
    reference.extend(wall);
    let r = json(&args(tilt, w, mu_s, &reference));
    (v, r["residence_time_mean_s"].as_f64().unwrap())
}

fn within(v: &serde_json::Value, reference: f64, tol: f64) {
    let t = v["residence_time_mean_s"].as_f64().unwrap();
    assert!(
        (t - reference).abs() <= tol * reference,
        "{} gives {t}, the bowl model {reference}",
        v["chosen"]
    );
    assert_eq!(v["valid"], true, "{v}");
}

fn reasons(v: &serde_json::Value) -> String {
    v["not_cheaper"].to_string()
}

#[test]
fn at_the_rigs_tilt_a_loose_tolerance_takes_the_incline() {
    let (v, r) = chosen_and_reference("60", "1.0", "0.4", "0.01", &[]);
    assert_eq!(v["chosen"], "incline", "{v}");
    within(&v, r, 0.01);
}

#[test]
fn a_tight_tolerance_at_the_rigs_tilt_needs_the_sliding_disc() {
    // At 2.0 rad/s the sliding incline corrected by its second order holds 0.1 % (bound
    // 0.036 %); at 3.6 rad/s neither bound does.
    let (v, r) = chosen_and_reference("60", "3.6", "0.4", "0.001", &[]);
    assert_eq!(v["chosen"], "rolling-or-sliding", "{v}");
    assert!(reasons(&v).contains("slides at this tilt"), "{v}");
    assert!(reasons(&v).contains("the bowl's rotation changes T"), "{v}");
    within(&v, r, 0.001);
}

#[test]
fn where_it_rolls_the_rolling_model_is_enough() {
    let (v, r) = chosen_and_reference("30", "2.0", "0.4", "0.001", &[]);
    assert_eq!(v["chosen"], "rolling", "{v}");
    within(&v, r, 0.001);
}

#[test]
fn rolling_at_release_and_sliding_later_goes_on_to_the_sliding_disc() {
    // At 1.0 rad/s the incline corrected by its second order now holds 0.1 %; at 1.8 rad/s
    // it does not, and the rolling model finds the granule slides later.
    let (v, r) = chosen_and_reference("45", "1.8", "0.31", "0.001", &[]);
    assert_eq!(v["chosen"], "rolling-or-sliding", "{v}");
    assert!(
        reasons(&v).contains("it rolled at release but slides later"),
        "{v}"
    );
    within(&v, r, 0.001);
}

#[test]
fn a_wall_needs_the_bowl_and_says_where_the_lip_is() {
    let wall = ["--wall-angle-deg", "60", "--wall-height-m", "0.02"];
    let (v, r) = chosen_and_reference("60", "2.0", "0.4", "0.01", &wall);
    assert_eq!(v["chosen"], "bowl", "{v}");
    assert!(
        reasons(&v).contains("the wall matters: the lip at 0.0865 m is beyond R = 0.0750 m"),
        "{v}"
    );
    within(&v, r, 0.01);
}

#[test]
fn opposite_speeds_at_a_low_tilt_do_not_take_the_incline() {
    // 5 deg, w1 3.6, w2 -2.7 rad/s: |Omega| is only 0.9 rad/s, but the precession turns the
    // downhill direction and the incline is 7 % off (docs/model.md §12): a 5 % tolerance needs
    // an integrated model, whose answer is within it.
    let scene = |extra: &[&'static str]| {
        let mut a = vec![
            "predict",
            "--axes-angle-deg",
            "5",
            "--precession-rad-s",
            "3.6",
            "--spin-rad-s",
            "-2.7",
            "--sliding-mu",
            "0.4",
            "--json",
        ];
        a.extend(SCENE);
        a.extend(extra);
        json(&a)
    };
    let v = scene(&["--tolerance", "0.05"]);
    assert_ne!(v["chosen"], "incline", "{v}");
    assert!(reasons(&v).contains("the bowl's rotation changes T"), "{v}");
    assert!(v["rotation_estimate_rel"].as_f64().unwrap() > 0.072, "{v}");
    let r = scene(&[
        "--model",
        "bowl",
        "--tol",
        "1e-10",
        "--speed-range",
        "false",
    ]);
    within(&v, r["residence_time_mean_s"].as_f64().unwrap(), 0.05);
}

#[test]
fn a_rolling_row_the_estimate_refuses_takes_the_incline_by_its_second_order() {
    // 30 deg, 1.8 rad/s, mu_s 0.2, 1 %: the a-priori estimate says 2.1 %, the incline is 0.53 %
    // off (docs/model.md §12, "The four rotation rows"); the rotation's second order along the
    // rolling path (+0.52 %) and its remainder bound it at 0.70 %: the incline, in words.
    let (v, r) = chosen_and_reference("30", "1.8", "0.2", "0.01", &[]);
    assert_eq!(v["chosen"], "incline", "{v}");
    assert!(v["rotation_estimate_rel"].as_f64().unwrap() > 0.01, "{v}");
    let bound = v["rotation_second_order_bound_rel"].as_f64().unwrap();
    assert!(bound <= 0.01, "{v}");
    let why = v["why"].as_str().unwrap();
    assert!(
        why.contains("by the rotation's second order") && why.contains("a-priori estimate"),
        "{v}"
    );
    assert_eq!(v["not_cheaper"].as_array().unwrap().len(), 0, "{v}");
    // The bound holds against the bowl model run independently at rtol 1e-10.
    let t = v["residence_time_mean_s"].as_f64().unwrap();
    assert!((t - r).abs() <= bound * r, "{t} vs {r}, bound {bound}");
    within(&v, r, 0.01);
    // At 0.1 % the bound is above the tolerance: refused, and the reason says both.
    let (v, r) = chosen_and_reference("30", "1.8", "0.2", "0.001", &[]);
    assert_ne!(v["chosen"], "incline", "{v}");
    assert!(
        reasons(&v).contains("its second order along the incline's path bounds it at"),
        "{v}"
    );
    within(&v, r, 0.001);
}

#[test]
fn a_sliding_scene_takes_the_incline_corrected_by_its_second_order() {
    // 60 deg, 2.0 rad/s, mu_s 0.4, 0.1 % (docs/model.md §12, "The sliding incline's second
    // order"): the incline slides all the way; the a-priori estimate says 0.58 %, the sliding
    // incline's second order -0.27 % and its plain bound 0.30 %, above; corrected by that
    // second order what is left is bounded at 0.036 %: the incline, corrected, in words.
    let (v, r) = chosen_and_reference("60", "2.0", "0.4", "0.001", &[]);
    assert_eq!(v["chosen"], "incline", "{v}");
    assert_eq!(v["rotation_second_order_corrected"], true, "{v}");
    let plain = v["rotation_second_order_bound_rel"].as_f64().unwrap();
    let bound = v["rotation_second_order_corrected_bound_rel"]
        .as_f64()
        .unwrap();
    assert!(plain > 0.001 && bound <= 0.001, "{v}");
    let why = v["why"].as_str().unwrap();
    assert!(
        why.contains("corrected for the bowl's rotation to second order")
            && why.contains("which the answer includes"),
        "{v}"
    );
    // The corrected mean holds its bound against the bowl model run independently at rtol
    // 1e-10.
    let t = v["residence_time_mean_s"].as_f64().unwrap();
    assert!((t - r).abs() <= bound * r, "{t} vs {r}, bound {bound}");
    within(&v, r, 0.001);
    // Each release is the incline's to second order (T0 + T1 + T2): they differ, and their
    // mean is the answer.
    let per: Vec<f64> = v["per_release"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["residence_time_s"].as_f64().unwrap())
        .collect();
    assert_eq!(per.len(), 12);
    let mean = per.iter().sum::<f64>() / 12.0;
    assert!((mean - t).abs() <= 1e-12 * t, "{mean} vs {t}");
    // Releases picked by hand are single releases: the incline's bounds are for the mean over
    // the twelve azimuths, so it is not offered, in words.
    let v = json(&[
        "predict",
        "--axes-angle-deg",
        "60",
        "--precession-rad-s",
        "2.0",
        "--spin-rad-s",
        "2.0",
        "--sliding-mu",
        "0.4",
        "--rim-radius-m",
        "0.075",
        "--ri-m",
        "0.0375",
        "--release-azimuth-deg",
        "30,90",
        "--tolerance",
        "0.001",
        "--json",
    ]);
    assert_ne!(v["chosen"], "incline", "{v}");
    assert!(reasons(&v).contains("single releases are wanted"), "{v}");
    // At 3.6 rad/s some releases stick and roll part of the way (the bowl model's regimes):
    // no second order is offered, in words, and the disc answers.
    let (v, r) = chosen_and_reference("60", "3.6", "0.4", "0.01", &[]);
    assert_ne!(v["chosen"], "incline", "{v}");
    assert!(v["rotation_second_order_rel"].is_null(), "{v}");
    assert!(
        reasons(&v).contains("may bring the sliding granule to stick"),
        "{v}"
    );
    within(&v, r, 0.01);
}

/// A tight tolerance is written with its digits: `--tolerance 1e-9` read "chooser (tolerance
/// 0.00 %)" and "more than the tolerance 0.00 %" in the text and in the JSON's reasons.
#[test]
fn a_tight_tolerance_is_said_with_its_digits() {
    let a = args("60", "2.0", "0.4", &["--tolerance", "1e-9"]);
    let text: Vec<&str> = a.iter().copied().filter(|s| *s != "--json").collect();
    let out = common::bowl(&text);
    assert_eq!(out.status.code(), Some(0));
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(s.contains("chooser (tolerance 1.0e-7 %)"), "{s}");
    assert!(s.contains("more than the tolerance 1.0e-7 %"), "{s}");
    assert!(!s.contains("0.00 %"), "{s}");
    let v = json(&a);
    assert!(
        reasons(&v).contains("more than the tolerance 1.0e-7 %"),
        "{v}"
    );
}

/// A granule that lifts off hands the rolling level over to one that follows the flight: the
/// chooser took the rolling model there ("rolling model NOT VALID HERE: the normal force
/// reaches zero", "none of the 12 releases leaves") where the bowl model has every release
/// fly out. Now the answer is valid and the bowl model's, within the tolerance.
#[test]
fn a_lift_off_is_followed_by_the_next_level() {
    let scene = [
        "--axes-angle-deg",
        "60",
        "--precession-rad-s",
        "-4.537765650449775",
        "--spin-rad-s",
        "5",
        "--rod-offset-m",
        "0.4",
        "--rim-radius-m",
        "0.10511622245212189",
        "--ri-m",
        "0.03247409994652675",
        "--particle-radius-m",
        "0.004",
        "--mu",
        "0",
        "--sliding-mu",
        "1.04",
        "--json",
    ];
    let auto = json(
        &[
            &["predict", "--model", "auto", "--tolerance", "0.01"],
            &scene[..],
        ]
        .concat(),
    );
    assert_eq!(auto["chosen"], "rolling-or-sliding", "{auto}");
    assert_eq!(auto["valid"], true, "{auto}");
    assert!(
        reasons(&auto).contains("it lifts off at 0 deg (the normal force reaches zero at t = "),
        "{auto}"
    );
    let full = json(
        &[
            &["predict", "--model", "bowl", "--speed-range", "false"],
            &scene[..],
        ]
        .concat(),
    );
    assert_eq!(auto["releases_leaving"], 12, "{auto}");
    assert_eq!(full["releases_leaving"], 12, "{full}");
    within(&auto, full["residence_time_mean_s"].as_f64().unwrap(), 0.01);
}
