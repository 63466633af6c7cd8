//! `bowl predict` end to end: runs the built binary and checks its output against independent
//! formulas (the textbook acosh form of paper Eq. 6, the energy identity of Eq. 7). (On a logged
//! speed trace, and the chooser for the MCU: predict_trace.rs.)

mod common;

use common::{
    bowl, json, predict_args, predict_batch, rig_axis_speed, run_batch, temp, tilted_rig,
};

/// Flat residence time by the textbook formula, `acosh((R - a)/(ri - a)) / (k omega)`.
fn flat_time(w: f64, mu: f64, ri: f64, rim: f64) -> f64 {
    let a = mu * 9.81 / (w * w);
    ((rim - a) / (ri - a)).acosh() / ((5.0f64 / 7.0).sqrt() * w)
}

#[test]
fn single_case_text_names_both_models() {
    let out = bowl(&["predict"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("flat") && text.contains("coriolis"), "{text}");
    assert!(text.contains("leaves after T ="), "{text}");
}

#[test]
fn single_case_json_matches_the_textbook_formula() {
    let v = json(&[
        "predict",
        "--omega-rad-s",
        "3.6",
        "--mu",
        "0.01",
        "--ri-m",
        "0.03",
        "--model",
        "flat",
        "--json",
    ]);
    let r = &v["results"][0];
    assert_eq!(r["outcome"], "leaves");
    let t = r["residence_time_s"].as_f64().unwrap();
    let want = flat_time(3.6, 0.01, 0.03, 0.1);
    assert!((t - want).abs() < 1e-12 * want, "{t} vs {want}");
    // Energy: r'^2 = k2 omega^2 ((R - a)^2 - (ri - a)^2).
    let a: f64 = 0.01 * 9.81 / (3.6 * 3.6);
    let vr = r["exit_radial_velocity_m_s"].as_f64().unwrap();
    let vr_want = (5.0 / 7.0 * 3.6f64.powi(2) * ((0.1 - a).powi(2) - (0.03 - a).powi(2))).sqrt();
    assert!((vr - vr_want).abs() < 1e-12);
    let vt = r["exit_total_velocity_m_s"].as_f64().unwrap();
    assert!((vt - (vr * vr + 0.36f64.powi(2)).sqrt()).abs() < 1e-12);
}

#[test]
fn paper_literal_mu_never_leaves_and_says_so() {
    let v = json(&["predict", "--mu", "0.4", "--omega-rad-s", "3.6", "--json"]);
    for r in v["results"].as_array().unwrap() {
        assert_eq!(r["outcome"], "never_leaves");
        assert!(r["residence_time_s"].is_null());
    }
    let text = String::from_utf8(bowl(&["predict", "--mu", "0.4"]).stdout).unwrap();
    assert!(text.contains("NEVER LEAVES"), "{text}");
}

#[test]
fn inverse_gives_a_speed_that_gives_the_target() {
    let v = json(&[
        "predict",
        "--target-time-s",
        "0.6",
        "--model",
        "coriolis",
        "--json",
    ]);
    let w = v["inverse"][0]["omega_rad_s"].as_f64().unwrap();
    let back = json(&[
        "predict",
        "--omega-rad-s",
        &w.to_string(),
        "--model",
        "coriolis",
        "--json",
    ]);
    let t = back["results"][0]["residence_time_s"].as_f64().unwrap();
    assert!((t - 0.6).abs() < 1e-12, "{t}");
}

/// A fixed step too small for the granule's time names the step, the cap, the time and the step
/// that reaches the exit (it said "took too many steps: give a larger --step-s or a looser
/// --tol", --tol being no flag of a fixed step); the step it names does reach the exit.
#[test]
fn a_step_too_small_for_the_exit_names_the_step_that_reaches_it() {
    let scene = [
        "predict",
        "--model",
        "flat",
        "--omega-rad-s",
        "3",
        "--method",
        "euler",
    ];
    let out = bowl(&[&scene[..], &["--step-s", "1e-9"]].concat());
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "took more than 1000000 steps of 1e-9 s (--step-s): the granule takes 0.784 s to \
             leave (the closed form), so give --step-s of at least 7.9e-7 s, or --method closed"
        ),
        "{err}"
    );
    let v = json(&[&scene[..], &["--step-s", "7.9e-7", "--json"]].concat());
    assert_eq!(v["results"][0]["outcome"], "leaves", "{v}");
}

#[test]
fn bad_scene_is_a_clear_error() {
    let out = bowl(&["predict", "--k2", "1.5"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(err.contains("--k2 1.5: must lie in (0, 1]"), "{err}");
    assert!(!err.contains("InvalidK2"), "no Rust names: {err}");
    // The rig refuses a start at or beyond the rim: so does predict (it answered T = 0).
    let out = bowl(&["predict", "--ri-m", "0.2", "--rim-radius-m", "0.1"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--ri-m 0.2 m is not inside the rim"), "{err}");
}

#[test]
fn batch_with_a_bad_row_names_every_bad_line_and_writes_nothing() {
    let input = temp("in-bad.csv");
    let output = temp("out-bad.csv");
    std::fs::write(
        &input,
        "label,model,w_rad_s,mu,ri_m,R_m,g,k2\n\
         \"a, quoted\",flat,3.6,0.01,0.03,0.1,9.81,0.7142857142857143\n\
         b,coriolis,3.6,0.4,0.05,0.1,9.81,0.7142857142857143,extra\n\
         c,flat,2,0.029,0.1,0.1,9.81,0.7142857142857143\n\
         d,flat,fast,0.029,0.05,0.1,9.81,0.7142857142857143\n\
         e,sideways,3,0.029,0.05,0.1,9.81,0.7142857142857143\n\
         f,coriolis,3,0.029,0.05,0.1,9.81,0.7142857142857143\n",
    )
    .unwrap();
    std::fs::write(&output, "an older result\n").unwrap();
    let out = predict_batch(&input, &output, &[]);
    assert_eq!(out.status.code(), Some(1), "a failed row fails the run");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("line 3: 9 cells, but the header names 8 columns"),
        "{err}"
    );
    assert!(err.contains("line 5") && err.contains("\"fast\""), "{err}");
    assert!(err.contains("line 6") && err.contains("sideways"), "{err}");
    assert!(
        err.contains("line 4") && err.contains("not inside the rim"),
        "{err}"
    );
    assert!(
        err.contains("4 of 6 row(s)") && err.contains("not written"),
        "{err}"
    );
    // Nothing written: the old file stands, no partial file is left beside it.
    assert_eq!(
        std::fs::read_to_string(&output).unwrap(),
        "an older result\n"
    );
    let dir = output.parent().unwrap();
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| {
            e.file_name()
                .to_string_lossy()
                .contains("out-bad.csv.partial")
        })
        .collect();
    assert!(leftovers.is_empty(), "partial files left: {leftovers:?}");
    let _ = std::fs::remove_file(input);
    let _ = std::fs::remove_file(output);
}

/// Every result column against the single-scene `bowl predict --json` of the same scene.
#[test]
fn batch_rows_carry_the_results_condition_and_flags_of_single_predictions() {
    // a: ordinary; b: never leaves; f: Coriolis; t: a start just above the threshold.
    let a_thr = 0.029 * 9.81 / (3.0f64 * 3.0);
    let ri_t = a_thr * (1.0 + 1e-11);
    let (out, text) = run_batch(
        "good",
        &format!(
            "label,model,w_rad_s,mu,ri_m,R_m,g,k2\n\
             \"a, quoted\",flat,3.6,0.01,0.03,0.1,9.81,0.7142857142857143\n\
             b,coriolis,3.6,0.4,0.05,0.1,9.81,0.7142857142857143\n\
             f,coriolis,3,0.029,0.05,0.1,9.81,0.7142857142857143\n\
             t,flat,3,0.029,{ri_t:e},0.1,9.81,0.7142857142857143\n"
        ),
        &[],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut rdr = csv::Reader::from_reader(text.as_bytes());
    let header: Vec<String> = rdr.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(
        &header[8..],
        [
            "residence_time_s",
            "exit_radial_velocity_m_s",
            "exit_total_velocity_m_s",
            "condition_number",
            "flags"
        ]
    );
    let rows: Vec<csv::StringRecord> = rdr.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 4);
    assert_eq!(&rows[0][0], "a, quoted", "extra column carried through");
    let single = |model: &str, w: &str, mu: &str, ri: &str| {
        json(&[
            "predict",
            "--model",
            model,
            "--omega-rad-s",
            w,
            "--mu",
            mu,
            "--ri-m",
            ri,
            "--rim-radius-m",
            "0.1",
            "--json",
        ])["results"][0]
            .clone()
    };
    let ri_t_text = format!("{ri_t:e}");
    for (row, (model, w, mu, ri)) in rows.iter().zip([
        ("flat", "3.6", "0.01", "0.03"),
        ("coriolis", "3.6", "0.4", "0.05"),
        ("coriolis", "3", "0.029", "0.05"),
        ("flat", "3", "0.029", ri_t_text.as_str()),
    ]) {
        let one = single(model, w, mu, ri);
        match one["outcome"].as_str().unwrap() {
            "leaves" => {
                for (k, key) in [
                    (8, "residence_time_s"),
                    (9, "exit_radial_velocity_m_s"),
                    (10, "exit_total_velocity_m_s"),
                    (11, "condition_number"),
                ] {
                    let v: f64 = row[k].parse().unwrap();
                    // serde_json's default reader may round the JSON text's last digit by an
                    // ulp; the two outputs are the same computation.
                    let j = one[key].as_f64().unwrap();
                    assert!(
                        (v - j).abs() <= 2.0 * f64::EPSILON * v.abs(),
                        "{key} of {row:?}: {j}"
                    );
                    assert_eq!(v.to_string(), &row[k], "shortest round-trip form");
                }
                let ill = one["ill_conditioned"].as_bool().unwrap();
                assert_eq!(&row[12] == "ill_conditioned", ill, "{row:?}");
            }
            "never_leaves" => {
                assert_eq!(
                    (&row[8], &row[9], &row[10], &row[11]),
                    ("", "", "", ""),
                    "never leaves: empty cells, never inf or nan"
                );
                assert!(row[12].starts_with("never_leaves"), "{row:?}");
            }
            other => panic!("{other}"),
        }
    }
    assert_eq!(
        &rows[3][12], "ill_conditioned",
        "a start 1e-11 above the threshold"
    );
}

#[test]
fn batch_without_g_and_k2_uses_the_defaults() {
    let (out, text) = run_batch(
        "defaults",
        "R_m,ri_m,mu,w_rad_s,model\n0.1,0.03,0.01,3.6,flat\n",
        &[],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let last = text.lines().nth(1).unwrap();
    let t: f64 = last.split(',').nth(5).unwrap().parse().unwrap();
    let want = flat_time(3.6, 0.01, 0.03, 0.1);
    assert!((t - want).abs() < 1e-12 * want);
}

/// `--throughput` times each model the file holds (and only those), on one thread and on every
/// core, after writing the results as usual.
#[test]
fn batch_throughput_is_measured_per_model() {
    let (out, text) = run_batch(
        "throughput",
        "model,w_rad_s,mu,ri_m,R_m\nflat,3.6,0.01,0.03,0.1\nflat,4,0.02,0.05,0.1\n",
        &["--throughput"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let flat = &j["flat"];
    assert_eq!(flat["scenes"], 2, "{j}");
    for key in ["ns_per_scene_one_thread", "ns_per_scene_all_cores"] {
        let ns = flat[key].as_f64().unwrap();
        assert!(ns > 0.0 && ns < 1e6, "{key} {ns}");
    }
    assert!(flat["threads"].as_u64().unwrap() >= 1);
    assert!(j.get("coriolis").is_none(), "{j}");
    assert_eq!(text.lines().count(), 3);
}

#[test]
fn batch_without_required_column_fails_naming_it() {
    let (out, _) = run_batch("nocol", "model,mu,ri_m,R_m\nflat,0.01,0.03,0.1\n", &[]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("w_rad_s"));
}

#[test]
fn integrators_agree_with_the_closed_form_and_report_cost() {
    let closed = json(&["predict", "--model", "coriolis", "--json"]);
    let t_ref = closed["results"][0]["residence_time_s"].as_f64().unwrap();
    let dp = json(&[
        "predict", "--model", "coriolis", "--method", "dp54", "--tol", "1e-11", "--json",
    ]);
    let r = &dp["results"][0];
    assert!((r["residence_time_s"].as_f64().unwrap() - t_ref).abs() < 1e-9 * t_ref);
    assert!(r["rhs_evaluations"].as_u64().unwrap() > 6);
    let rk = json(&[
        "predict", "--model", "coriolis", "--method", "rk4", "--step-s", "0.001", "--json",
    ]);
    assert!((rk["results"][0]["residence_time_s"].as_f64().unwrap() - t_ref).abs() < 1e-9 * t_ref);
}

#[test]
fn a_step_beyond_stability_is_an_error_not_a_number() {
    let out = bowl(&[
        "predict",
        "--method",
        "euler",
        "--step-s",
        "1.0",
        "--omega-rad-s",
        "3",
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("beyond the method's stability limit"), "{err}");
}

/// `--model rolling` on the tilted rig's reference scene (60 deg, R 150 mm, mu_r 0.029,
/// |Omega| 3.6 with w1 = w2): mean 0.211 s over the twelve azimuths, in [0.153, 0.287]
/// (docs/model.md §9); one azimuth gives `residence_time_s`.
#[test]
fn rolling_model_on_the_tilted_rig() {
    let w = rig_axis_speed();
    let rig = tilted_rig("rolling", &w);
    let at = |azimuths| {
        predict_args(
            &rig,
            &["--mu", "0.029", "--json", "--release-azimuth-deg", azimuths],
        )
    };
    let v = json(&at("all"));
    let get = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k} in {v}"));
    assert!((get("residence_time_mean_s") - 0.211).abs() < 5e-4, "{v}");
    assert!((get("residence_time_min_s") - 0.153).abs() < 5e-4, "{v}");
    assert!((get("residence_time_max_s") - 0.287).abs() < 5e-4, "{v}");
    // One azimuth, or a list: the same shape as --model bowl (per_release, releases).
    let v = json(&at("0"));
    let t = v["per_release"][0]["residence_time_s"].as_f64().unwrap();
    assert!(t > 0.15 && t < 0.29, "{v}");
    assert_eq!(v["residence_time_mean_s"].as_f64(), Some(t));
    assert_eq!(v["per_release"][0]["regime"]["roll"], 1.0, "{v}");
    let v = json(&at("0,90"));
    assert_eq!(v["releases"], 2, "{v}");
    assert_eq!(v["per_release"][1]["azimuth_deg"], 90.0, "{v}");
    assert_eq!(v["releases_leaving"], 2, "{v}");
    // A missing speed is said plainly, exit code 1.
    let out = bowl(&["predict", "--model", "rolling", "--axes-angle-deg", "30"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--precession-rad-s"), "{err}");
}

/// A step far beyond a method's accuracy gets a warning that says how far off the answer is and
/// which step to use; the step it suggests does bring the answer within 1 % of the closed form.
#[test]
fn a_coarse_step_is_warned_and_the_suggested_step_is_accurate() {
    for (method, model, step) in [
        ("semi-implicit", "coriolis", "1"),
        ("euler", "flat", "0.5"),
        ("rk4", "flat", "0.6"),
    ] {
        let out = bowl(&[
            "predict", "--method", method, "--model", model, "--step-s", step, "--json",
        ]);
        assert_eq!(out.status.code(), Some(0), "a warning, not a refusal");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("% off the closed form"), "{method}: {err}");
        let suggested = err
            .split("use --step-s ")
            .nth(1)
            .and_then(|t| t.split_whitespace().next())
            .unwrap_or_else(|| panic!("{method}: no step suggested: {err}"));
        let again = bowl(&[
            "predict", "--method", method, "--model", model, "--step-s", suggested, "--json",
        ]);
        let err2 = String::from_utf8_lossy(&again.stderr);
        assert!(!err2.contains("warning"), "{method} at {suggested}: {err2}");
        let v: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
        let e = v["results"][0]["error_vs_closed_form"].as_f64().unwrap();
        assert!(e < 0.01, "{method} at {suggested}: {e}");
        let closed = json(&["predict", "--model", model, "--json"]);
        let t_ref = closed["results"][0]["residence_time_s"].as_f64().unwrap();
        let t = v["results"][0]["residence_time_s"].as_f64().unwrap();
        assert!((t - t_ref).abs() / t_ref < 0.01, "{method}: {t} vs {t_ref}");
    }
}

#[test]
fn the_chooser_answers_by_default_and_its_reason_holds() {
    let auto = json(&["predict", "--json"]);
    let both = json(&["predict", "--model", "both", "--json"]);
    let t = |v: &serde_json::Value, i: usize| v["results"][i]["residence_time_s"].as_f64().unwrap();
    let (tf, tc) = (t(&both, 0), t(&both, 1));
    let effect = (tc - tf).abs() / tf;
    let c = &auto["choice"];
    assert!(
        (c["coriolis_effect_rel"].as_f64().unwrap() - effect).abs() < 1e-12,
        "{c}"
    );
    // The default uncertainty (mu 20 %): the spread of T, measured here by moving mu alone by
    // 20 %, exceeds the Coriolis term, so flat is enough and the chooser says so.
    let at_mu = |mu: &str| {
        t(
            &json(&["predict", "--model", "coriolis", "--mu", mu, "--json"]),
            0,
        )
    };
    let mu_spread = (at_mu("0.0348") - tc)
        .abs()
        .max((at_mu("0.0232") - tc).abs())
        / tc;
    assert!(mu_spread > 10.0 * effect, "{mu_spread} vs {effect}");
    assert_eq!(c["model"], "flat", "{c}");
    assert_eq!(c["coriolis_below_uncertainty"], true, "{c}");
    assert_eq!(auto["results"].as_array().unwrap().len(), 1);
    assert_eq!(t(&auto, 0), tf);
    let text = String::from_utf8(bowl(&["predict"]).stdout).unwrap();
    assert!(
        text.contains("chosen: flat model, closed form")
            && text.contains("the Coriolis term is below the uncertainty here"),
        "{text}"
    );
    // A tolerance tighter than the Coriolis term: the Coriolis model answers.
    let tight = json(&["predict", "--tolerance", "1e-6", "--json"]);
    assert_eq!(tight["choice"]["model"], "coriolis");
    assert_eq!(t(&tight, 0), tc);
    let out = bowl(&["predict", "--tolerance", "2"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("between 0 and 0.1"));
}
