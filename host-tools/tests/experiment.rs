//! `bowl experiment` end to end on simulated rigs described by rig files: the plant keys and
//! the `[particle]` truth come from the one rig-file reader.

mod common;

use common::{bowl, csv_rows, temp_dir};

const PLAN: &str = "settle_s = 1.0\n[[condition]]\nbowl_rad_s = 3.5\nrepeats = 3\n";

fn rig_with_particle(dir: &std::path::Path, plant: &str) -> std::path::PathBuf {
    let path = dir.join("rig.toml");
    std::fs::write(
        &path,
        format!("{plant}\n[particle]\nmodel = \"coriolis\"\nmu = 0.03\nrim_radius_m = 0.15\n"),
    )
    .unwrap();
    path
}

/// The `status` column of the results file.
fn statuses(results: &std::path::Path) -> Vec<String> {
    csv_rows(results)
        .iter()
        .map(|r| r["status"].clone())
        .collect()
}

#[test]
fn an_experiment_runs_on_the_plant_and_the_particle_of_its_rig_file() {
    let dir = temp_dir("experiment-rig");
    let plan = dir.join("plan.toml");
    std::fs::write(&plan, PLAN).unwrap();
    let mut outcomes = Vec::new();
    // The nominal rig, and one on a 3 V supply whose motors cannot reach the speeds.
    for (name, plant) in [("nominal", ""), ("flat-battery", "supply_v = 3.0")] {
        let rig = rig_with_particle(&dir, plant);
        let out = dir.join(format!("{name}.csv"));
        let run = bowl(&[
            "experiment",
            plan.to_str().unwrap(),
            "--rig-file",
            rig.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(run.status.success(), "{name}: {}", common::stdout(&run));
        outcomes.push(statuses(&out));
    }
    assert_eq!(outcomes[0], ["ok", "ok", "ok"]);
    assert!(
        outcomes[1].iter().all(|s| s != "ok"),
        "the 3 V rig reached the speeds: {:?}",
        outcomes[1]
    );
    // A rig file without [particle] and a family file are refused in words.
    let bare = dir.join("bare.toml");
    std::fs::write(&bare, "supply_v = 12.0\n").unwrap();
    let out = bowl(&[
        "experiment",
        plan.to_str().unwrap(),
        "--rig-file",
        bare.to_str().unwrap(),
        "--out",
        dir.join("x.csv").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no [particle] table"), "{err}");
}

#[test]
fn an_experiment_over_a_port_times_granules_by_the_rigs_gate_events() {
    let dir = temp_dir("experiment-port");
    let rig = dir.join("rig.toml");
    std::fs::write(
        &rig,
        "seed = 3\n[particle]\nmodel = \"coriolis\"\nmu = 0.03\nrim_radius_m = 0.15\n",
    )
    .unwrap();
    let sim = common::Sim::start(&["--rig-file", rig.to_str().unwrap()]);
    let plan = dir.join("plan.toml");
    std::fs::write(
        &plan,
        "settle_s = 0.3\n[[condition]]\nbowl_rad_s = 3.5\nrepeats = 2\n",
    )
    .unwrap();
    let out = dir.join("port.csv");
    let run = bowl(&[
        "experiment",
        plan.to_str().unwrap(),
        "--port",
        &sim.path,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", common::stdout(&run));
    let rows = csv_rows(&out);
    assert_eq!(rows.len(), 2, "{rows:?}");
    // The rig's parameters give the geometry columns: the virtual rig's table describes the
    // bowl of its rig file (START_UM, RIM_UM, K2_PPM), as an engineer sets a real rig's.
    let want = common::reference_residence_s(|_| 3.5, 0.03, 0.05, 0.15, true);
    for r in &rows {
        assert_eq!(r["status"], "ok", "{r:?}");
        let geometry: Vec<f64> = ["release_radius_m", "rim_radius_m", "k2"]
            .iter()
            .map(|k| r[*k].parse().unwrap())
            .collect();
        assert_eq!(geometry, [0.05, 0.15, 0.714286], "{r:?}");
        let t: f64 = r["residence_s"].parse().unwrap();
        // The speed loop holds 3.5 rad/s to about 0.3 %; T moves about 2x as much.
        assert!((t - want).abs() < 0.01 * want, "{t} s vs {want} s: {r:?}");
        let trace = std::fs::read_to_string(dir.join(&r["trace_path"])).unwrap();
        assert!(trace.lines().count() > 20, "{trace}");
    }
    // RELEASE twice at once: the second is refused in words (one granule at a time).
    bowl(&["send", &sim.path, "speed", "1800", "2100"]);
    bowl(&["send", &sim.path, "start"]);
    assert!(bowl(&["send", &sim.path, "release"]).status.success());
    let again = bowl(&["send", &sim.path, "release"]);
    assert_eq!(again.status.code(), Some(1));
    let text = common::stdout(&again);
    assert!(text.contains("still has its granule in the bowl"), "{text}");
}

/// `--suggest` refuses, with exit 1 and in words, the values that printed a NaN speed, a
/// `D = NaN` or `inf`, or a plan `bowl experiment` itself refuses; nothing goes to stdout then.
#[test]
fn suggest_refuses_bad_values_in_words_with_a_failing_exit() {
    let dir = temp_dir("experiment-suggest");
    let rig = rig_with_particle(&dir, "");
    let rig = rig.to_str().unwrap();
    // Not a number at all: refused as the command line is, with every number flag (exit 2).
    let out = bowl(&[
        "experiment",
        "--suggest",
        "--rig-file",
        rig,
        "--mu-guess",
        "nan",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("`nan` is not a number: give a decimal number"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
    let cases: [(&str, &str, &str); 7] = [
        (
            "--mu-guess",
            "0",
            "--mu-guess 0: the guessed rolling resistance must be",
        ),
        (
            "--mu-guess",
            "-1",
            "--mu-guess -1: the guessed rolling resistance must be",
        ),
        (
            "--mu-guess",
            "1e9",
            "--mu-guess 1000000000: the guessed rolling resistance must be",
        ),
        (
            "--conditions",
            "0",
            "--conditions 0: a suggested plan holds 1 to 40 conditions",
        ),
        (
            "--conditions",
            "1000",
            "--conditions 1000: a suggested plan holds 1 to 40 conditions",
        ),
        (
            "--repeats",
            "0",
            "--repeats 0: releases per condition must lie in 1 to 10000",
        ),
        (
            "--repeats",
            "100000",
            "--repeats 100000: releases per condition must lie in 1 to 10000",
        ),
    ];
    for (flag, value, words) in cases {
        let out = bowl(&["experiment", "--suggest", "--rig-file", rig, flag, value]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{flag} {value}: {err}");
        assert!(err.contains(words), "{flag} {value}: {err}");
        assert!(
            out.stdout.is_empty(),
            "{flag} {value}: {}",
            common::stdout(&out)
        );
        assert!(!err.contains("panicked"), "{flag} {value}: {err}");
    }
    // The defaults still suggest a plan that `bowl experiment` reads.
    let out = bowl(&["experiment", "--suggest", "--rig-file", rig]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = common::stdout(&out);
    assert_eq!(text.matches("[[condition]]").count(), 4, "{text}");
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A plan beyond the motors' limits is refused before anything runs, naming the condition,
/// the speed, the limit and the fastest bowl speed (it ran, every row a motor fault without
/// the limit); a plan value of the wrong type is said in words with its key; no rig names
/// both ways to give one, exit 2; one release is singular.
#[test]
fn a_plan_is_checked_against_the_rig_before_it_runs() {
    let dir = temp_dir("experiment-limits");
    let rig = rig_with_particle(&dir, "seed = 3");
    let plan = dir.join("fast.toml");
    std::fs::write(&plan, "[[condition]]\nbowl_rad_s = 50\nrepeats = 2\n").unwrap();
    let out = dir.join("out").join("x.csv");
    let args = |plan: &std::path::Path| {
        vec![
            "experiment".to_string(),
            plan.display().to_string(),
            "--rig-file".into(),
            rig.display().to_string(),
            "--out".into(),
            out.display().to_string(),
        ]
    };
    let run = |a: &[String]| bowl(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let o = run(&args(&plan));
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("condition 1: bowl_rad_s = 50, which needs a precession speed of")
            && err.contains("above the rig's limit of")
            && err.contains("the fastest bowl speed this rig can run is"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
    std::fs::write(&plan, "[[condition]]\nbowl_rad_s = 3\nrepeats = 1.5\n").unwrap();
    let err = String::from_utf8_lossy(&run(&args(&plan)).stderr).into_owned();
    assert!(
        err.contains("line 3") && err.contains("repeats:") && err.contains("a whole number"),
        "{err}"
    );
    assert!(!err.contains("usize"), "{err}");
    std::fs::write(
        &plan,
        "settle_s = 0.5\n[[condition]]\nbowl_rad_s = 3\nrepeats = 1\n",
    )
    .unwrap();
    let o = run(&args(&plan));
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("1 release written to"));
    let o = bowl(&["experiment", plan.to_str().unwrap(), "--out", "x.csv"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("--rig-file FILE") && err.contains("--port PORT"),
        "{err}"
    );
}
