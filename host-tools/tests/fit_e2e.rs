//! `bowl fit` end to end, the binary on small results files: a good set, one with an outlier
//! (named in words on the terminal and in the JSON's `outliers`, left out), one with impossible
//! rows (refused, exit 1, each line named with its value and the limit). Six releases of a
//! Coriolis granule (mu 0.03, k2 5/7) at three steady speeds, timed by the closed form
//! (`model_core::particle::residence`, the truth) with a fixed gate jitter of at most 1 ms: the
//! steady traces take the fit's closed-form path and `--models flat,coriolis` leaves out the
//! rolling model's integrations, so each file fits in about a second of CPU in debug.

mod common;

use std::path::{Path, PathBuf};

use common::{bowl, stdout, success_json, temp_dir};
use lab::results::{Row, Writer};
use model_core::particle::{Model, Scene, residence};

const TRUE_MU: f64 = 0.03;
const RI_M: f64 = 0.05;
const RIM_M: f64 = 0.15;
const K2: f64 = 5.0 / 7.0;
/// (condition, speed rad/s, gate jitter s) of each release, in file order.
const RELEASES: [(usize, f64, f64); 6] = [
    (1, 2.9, 0.0008),
    (1, 2.9, -0.0006),
    (2, 3.5, 0.0003),
    (2, 3.5, -0.0010),
    (3, 4.2, 0.0005),
    (3, 4.2, -0.0002),
];

/// The true residence time at `omega`, s.
fn truth_s(omega: f64) -> f64 {
    let s = Scene {
        omega_rad_s: omega,
        mu: TRUE_MU,
        g_m_s2: 9.81,
        k2: K2,
        ri_m: RI_M,
        rim_radius_m: RIM_M,
    };
    residence(&s, Model::Coriolis).unwrap().residence_time_s()
}

/// A results file of the six releases, release `i`'s time replaced where `times` says so.
fn results(name: &str, times: &[(usize, f64)]) -> PathBuf {
    let dir = temp_dir(name);
    let path = dir.join("results.csv");
    let mut w = Writer::create(&path).unwrap();
    for (i, &(condition, omega, jitter)) in RELEASES.iter().enumerate() {
        let run = i + 1;
        let trace = w.write_trace(run, &[(0.0, omega), (0.5, omega)]).unwrap();
        let t = times
            .iter()
            .find(|(j, _)| *j == i)
            .map_or(truth_s(omega) + jitter, |(_, t)| *t);
        w.push(&Row {
            run,
            condition,
            bowl_rad_s: omega,
            precession_rad_s: omega / 3f64.sqrt(),
            spin_rad_s: omega / 3f64.sqrt(),
            release_radius_m: RI_M,
            rim_radius_m: RIM_M,
            k2: K2,
            status: "ok".into(),
            residence_s: Some(t),
            trace_mean_rad_s: Some(omega),
            trace_sd_rad_s: Some(0.0),
            trace_path: trace,
            release_azimuth_deg: None,
        })
        .unwrap();
    }
    path
}

/// `bowl fit` of the paper's two models (the rolling model takes 15 s of CPU in debug here; its
/// marking is tested in `lab::fit::robust`).
fn fit(path: &Path, json: bool) -> std::process::Output {
    let mut args = vec![
        "fit",
        path.to_str().unwrap(),
        "--no-charts",
        "--models",
        "flat,coriolis",
    ];
    if json {
        args.push("--json");
    }
    bowl(&args)
}

/// The Coriolis model's mu lies within 1 % of the truth and inside its own interval.
fn holds_the_truth(v: &serde_json::Value) {
    let c = &v["models"]["coriolis"];
    let mu = c["mu"].as_f64().unwrap();
    let (lo, hi) = (
        c["mu_ci95"][0].as_f64().unwrap(),
        c["mu_ci95"][1].as_f64().unwrap(),
    );
    assert!((mu - TRUE_MU).abs() < 0.01 * TRUE_MU, "{c}");
    assert!(lo <= TRUE_MU && TRUE_MU <= hi, "{c}");
}

#[test]
fn a_good_set_fits_the_truth_with_nothing_dropped() {
    let path = results("fit-good", &[]);
    let v = success_json(&fit(&path, true), "bowl fit --json");
    assert_eq!(v["runs"], 6, "{v}");
    assert_eq!(v["excluded"], serde_json::json!([]), "{v}");
    assert_eq!(v["outliers"], serde_json::json!([]), "{v}");
    holds_the_truth(&v);
    let out = fit(&path, false);
    assert!(out.status.success());
    let text = stdout(&out);
    assert!(text.contains("6 runs (6 by the closed form"), "{text}");
    assert!(text.contains("0 excluded, 0 outliers left out"), "{text}");
    assert!(text.contains("preferred: coriolis"), "{text}");
    // Only the models asked for, and an unknown one refused by name.
    assert!(v["models"].get("rolling").is_none(), "{v}");
    let out = bowl(&["fit", path.to_str().unwrap(), "--models", "flat,rollin"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("invalid value 'rollin' for '--models"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(path.parent().unwrap());
}

#[test]
fn an_outlier_is_named_in_words_and_in_the_json_and_left_out() {
    // Release 4 (line 5) timed ten times too long.
    let slow = 10.0 * truth_s(3.5);
    let path = results("fit-outlier", &[(3, slow)]);
    let out = fit(&path, false);
    assert_eq!(out.status.code(), Some(0));
    let text = stdout(&out);
    assert!(
        text.contains("5 runs") && text.contains("1 outlier left out"),
        "{text}"
    );
    let said = format!("outlier line 5: residence time {slow:.4} s where the other runs say");
    assert!(text.contains(&said), "{text}");
    assert!(text.contains("left out of the fit"), "{text}");

    let out = fit(&path, true);
    let v = success_json(&out, "bowl fit --json");
    let outliers = v["outliers"].as_array().unwrap();
    assert_eq!(outliers.len(), 1, "{v}");
    assert_eq!(outliers[0]["row"], 5);
    assert_eq!(outliers[0]["value"].as_f64(), Some(slow));
    let why = outliers[0]["why"].as_str().unwrap();
    assert!(why.contains("robust standard deviations off"), "{why}");
    assert_eq!(v["runs"], 5);
    holds_the_truth(&v);
    // Said on the terminal too when standard output is JSON.
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bowl fit: outlier line 5: "), "{err}");
    let _ = std::fs::remove_dir_all(path.parent().unwrap());
}

#[test]
fn impossible_times_are_refused_with_their_lines() {
    // Release 3 (line 4) in ms typed as s: 0.6 ms; release 5 (line 6) at 1e300 s.
    let path = results("fit-impossible", &[(2, 6e-4), (4, 1e300)]);
    for json in [false, true] {
        let out = fit(&path, json);
        assert_eq!(out.status.code(), Some(1), "json {json}");
        assert!(out.stdout.is_empty(), "json {json}: {}", stdout(&out));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("line 4: residence time 6e-4 s, under the")
                && err.contains("from rest at 0.05 m to the rim at 0.15 m")
                && err.contains("shorter than any release can be"),
            "{err}"
        );
        assert!(
            err.contains("line 6: residence time 1e300 s: beyond what the rig can record"),
            "{err}"
        );
        assert!(
            err.contains("Correct the value (seconds) or delete the row"),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    let _ = std::fs::remove_dir_all(path.parent().unwrap());
}

/// `text` (a results or trace file as `bowl experiment` writes it) as a spreadsheet in a
/// comma-decimal locale saves it: a `sep=;` first line, `;` between cells, decimal commas,
/// headers uppercase and padded, cells with trailing spaces.
fn as_semicolon_sheet(text: &str) -> String {
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|h| format!(" {} ", h.to_uppercase()))
        .collect();
    let mut out = format!("sep=;\n{}\n", header.join(";"));
    for line in lines {
        let cells: Vec<String> = line
            .split(',')
            .map(|c| match c.parse::<f64>() {
                Ok(_) => format!("{} ", c.replace('.', ",")),
                Err(_) => format!("{c} "),
            })
            .collect();
        out.push_str(&cells.join(";"));
        out.push('\n');
    }
    out
}

/// The fitted Coriolis mu of a run of `bowl fit --json`.
fn coriolis_mu(path: &Path) -> f64 {
    let v = success_json(&fit(path, true), "bowl fit --json");
    assert_eq!(v["runs"], 6, "{v}");
    assert_eq!(v["excluded"], serde_json::json!([]), "{v}");
    v["models"]["coriolis"]["mu"].as_f64().unwrap()
}

#[test]
fn a_spreadsheets_files_fit_like_the_original() {
    let path = results("fit-sheet", &[]);
    let dir = path.parent().unwrap();
    let original = std::fs::read_to_string(&path).unwrap();
    let mu = coriolis_mu(&path);
    // `;`-separated with decimal commas, its traces too, and an emptied row after the second.
    let mut sheet = as_semicolon_sheet(&original);
    let at = sheet.match_indices('\n').nth(3).unwrap().0 + 1;
    sheet.insert_str(at, ";;;;;;;;;;;;;\n");
    for run in 1..=RELEASES.len() {
        let trace = dir.join(format!("results_traces/run_{run:04}.csv"));
        let text = std::fs::read_to_string(&trace).unwrap();
        std::fs::write(&trace, as_semicolon_sheet(&text)).unwrap();
    }
    let semicolon = dir.join("semicolon.csv");
    std::fs::write(&semicolon, &sheet).unwrap();
    assert_eq!(coriolis_mu(&semicolon), mu);
    // Comma-separated, the header uppercase and padded, an emptied row, trailing spaces.
    let mut lines: Vec<String> = original.lines().map(|l| format!("{l} ")).collect();
    lines[0] = lines[0]
        .split(',')
        .map(|h| format!(" {} ", h.trim().to_uppercase()))
        .collect::<Vec<_>>()
        .join(",");
    lines.insert(3, ",,,,,,,,,,,,,".into());
    let comma = dir.join("comma.csv");
    std::fs::write(&comma, lines.join("\n") + "\n").unwrap();
    assert_eq!(coriolis_mu(&comma), mu);
    // A decimal comma in a comma-separated file: refused with its one line and its column.
    // Line 6 (header, two rows, the emptied row, a row): its time written as "1,07" would be.
    let column = original.lines().next().unwrap().split(',');
    let column = column.into_iter().position(|h| h == "residence_s").unwrap();
    let mut cells: Vec<String> = lines[5].split(',').map(str::to_string).collect();
    let decimal_comma = format!("{:.2}", cells[column].parse::<f64>().unwrap()).replace('.', ",");
    cells[column] = format!("\"{decimal_comma}\"");
    lines[5] = cells.join(",");
    std::fs::write(&comma, lines.join("\n") + "\n").unwrap();
    let out = fit(&comma, false);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!(
            "comma.csv, line 6, column residence_s: \"{decimal_comma}\" is not a number (use a \
             decimal point, or a ;-separated file)"
        )),
        "{err}"
    );
    assert!(
        !err.contains("deserialize") && !err.contains("record"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

/// A model that cannot reproduce the runs (a vertical wall holds a release: no finite error or
/// AIC) shows "-" in the text table and an empty cell in the condition table, never inf.
#[test]
fn a_model_without_an_error_shows_no_inf() {
    let dir = common::temp_dir("fit-unreproducible");
    let plan = dir.join("plan.toml");
    std::fs::write(
        &plan,
        "settle_s = 0.5\n[[condition]]\nbowl_rad_s = 2\nrepeats = 3\n\
         [[condition]]\nbowl_rad_s = 4\nrepeats = 3\n",
    )
    .unwrap();
    let results = dir.join("x.csv");
    let rig = "../docs/rigs/bowl-60deg.toml";
    let out = common::bowl(&[
        "experiment",
        plan.to_str().unwrap(),
        "--rig-file",
        rig,
        "--out",
        results.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = common::bowl(&["fit", results.to_str().unwrap(), "--rig-file", rig]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("not a candidate: some run never leaves under it"),
        "{text}"
    );
    let words: Vec<&str> = text.split(|c: char| !c.is_alphanumeric()).collect();
    assert!(
        !words.iter().any(|w| ["inf", "NaN", "nan"].contains(w)),
        "{text}"
    );
    let line = text
        .lines()
        .find(|l| l.starts_with("bowl-wall-vertical-20mm "))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(line.trim_end().ends_with("-            -"), "{line}");
}

#[test]
fn a_hand_edited_results_file_is_read_as_the_person_meant() {
    // Two measurements pasted one under the other (the second header kept), a status typed
    // "OK", and a run marked "excluded" by hand.
    let path = results("fit-edited", &[]);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    lines[2] = lines[2].replace(",ok,", ",OK,");
    lines[3] = lines[3].replace(",ok,", ",excluded,");
    let header = lines[0].to_uppercase();
    let pasted = format!(
        "{}\n{header}\n{}\n",
        lines.join("\n"),
        lines[1..].join("\n")
    );
    std::fs::write(&path, pasted).unwrap();
    let out = fit(&path, false);
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
    let text = stdout(&out);
    // 12 rows: the second copy's line 11 is "excluded" too; the "OK" rows are fitted.
    assert!(text.contains("10 runs (10 by the closed form"), "{text}");
    assert!(text.contains("2 excluded, 0 outliers left out"), "{text}");
    let said = "excluded line 4: status \"excluded\" (only rows whose status is ok are fitted)";
    assert!(text.contains(said), "{text}");
    assert!(
        text.contains("excluded line 11: status \"excluded\""),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(path.parent().unwrap());
}

#[test]
fn runs_at_one_speed_say_why_no_model_is_preferred() {
    // The first condition's two releases, three times over: six runs at 2.9 rad/s.
    let path = results("fit-one-speed", &[]);
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let rows = [lines[1], lines[2]].repeat(3).join("\n");
    std::fs::write(&path, format!("{}\n{rows}\n", lines[0])).unwrap();
    let out = fit(&path, false);
    assert_eq!(out.status.code(), Some(0), "{}", stdout(&out));
    let text = stdout(&out);
    assert!(text.contains("preferred: undecided"), "{text}");
    assert!(
        text.contains("undecided because every run is at one condition (2.900 rad/s)"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(path.parent().unwrap());
}
