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
