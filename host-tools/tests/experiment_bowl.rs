//! A simulated rig whose granules follow the bowl model (`[particle] model = "bowl"`,
//! docs/rigs/bowl-60deg.toml): each release leaves when `bowl predict --model bowl` says for the
//! same scene and azimuth, and `bowl experiment` then `bowl fit --bowl-walls` on such a rig find
//! its true `mu_s` and its wall.

mod common;

use std::path::{Path, PathBuf};

use common::{bowl, success_json};
use model_core::binding::Injector;
use model_core::sim::granule::ParticleParams;
use model_core::wire::GateKind;
use virtual_rig::World;

/// The worked example's rig file.
fn rig_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/rigs/bowl-60deg.toml")
}

/// Its one rig's granule truth.
fn truth() -> ParticleParams {
    let rigs = rig_file::load(&rig_path()).unwrap();
    rigs[0].particle.unwrap()
}

/// At constant motor speeds (no plant: the world stepped at 1 ms with the speeds given), the
/// exit gate minus the release gate is the bowl model's T for that release's azimuth, as
/// `bowl predict --model bowl --rig-file` computes it from the same rig file: to the gate's
/// microsecond. Speeds equal, unequal and with the spin reversed; the rig's gate jitter off.
#[test]
fn a_release_in_the_bowl_leaves_when_bowl_predict_says() {
    let mut particle = truth();
    particle.gate_jitter_s = 0.0;
    let b = particle
        .bowl
        .expect("the example's granules follow the bowl model");
    let mut world = World::new(particle, 7, b.axes_angle_rad);
    let mut now_us = 1_000_000u32;
    for speeds in [[1.2, 1.2], [2.5, 1.4], [1.8, -0.9]] {
        world.release().unwrap();
        let (mut released, mut left) = (None, None);
        for _ in 0..5_000 {
            world.step(speeds, now_us, 1e-3);
            now_us += 1000;
            while let Some(e) = world.gate_event() {
                match e.kind {
                    GateKind::Release => released = Some(e.time_us),
                    GateKind::Exit => left = Some(e.time_us),
                }
            }
            if left.is_some() {
                break;
            }
        }
        let simulated = f64::from(left.unwrap() - released.unwrap()) * 1e-6;
        let drawn = world.last_bowl_release().unwrap();
        let (w1, w2, beta) = (
            format!("--precession-rad-s={:e}", speeds[0]),
            format!("--spin-rad-s={:e}", speeds[1]),
            format!("{:e}", drawn.azimuth_rad.to_degrees()),
        );
        let (mu, mu_s, ri, k2) = (
            particle.mu.to_string(),
            b.sliding_mu.to_string(),
            particle.release_radius_m.to_string(),
            particle.k2.to_string(),
        );
        let out = bowl(&[
            "predict",
            "--model",
            "bowl",
            "--rig-file",
            rig_path().to_str().unwrap(),
            &w1,
            &w2,
            "--mu",
            &mu,
            "--sliding-mu",
            &mu_s,
            "--ri-m",
            &ri,
            "--k2",
            &k2,
            "--release-azimuth-deg",
            &beta,
            "--max-time-s",
            "60",
            "--speed-range",
            "false",
            "--json",
        ]);
        let v = success_json(&out, "bowl predict --model bowl");
        let predicted = v["per_release"][0]["residence_time_s"].as_f64().unwrap();
        assert!(
            (simulated - predicted).abs() <= 0.5e-6 + 1e-9,
            "speeds {speeds:?}, azimuth {beta} deg: simulated {simulated} s, predicted {predicted} s"
        );
        assert!(predicted > 0.05 && predicted < 1.0, "{predicted}");
    }
}

/// The example rig file with `[bowl]`/`[particle]` lines replaced (`key = value` lines,
/// matched by their key), written to `dir/name.toml`.
fn rig_variant(dir: &Path, name: &str, changes: &[(&str, &str)]) -> PathBuf {
    let mut text = String::new();
    for line in std::fs::read_to_string(rig_path()).unwrap().lines() {
        let key = line.split('=').next().unwrap_or("").trim();
        match changes.iter().find(|(k, _)| *k == key) {
            Some((k, v)) => text += &format!("{k} = {v}\n"),
            None => text += &format!("{line}\n"),
        }
    }
    for (k, _) in changes {
        assert!(
            text.lines().any(|l| l.starts_with(&format!("{k} = "))),
            "{k} not in the rig file"
        );
    }
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// `bowl experiment` of `per_speed` releases at each of 1.5, 3 and 4.5 rad/s on `rig`; the
/// results file's path.
fn experiment(dir: &Path, rig: &Path, per_speed: usize) -> PathBuf {
    let plan = dir.join("plan.toml");
    let mut text = String::from("settle_s = 0.5\n");
    for w in [1.5, 3.0, 4.5] {
        text += &format!("[[condition]]\nbowl_rad_s = {w}\nrepeats = {per_speed}\n");
    }
    std::fs::write(&plan, text).unwrap();
    let stem = rig.file_stem().unwrap().to_string_lossy();
    let out = dir.join(format!("{stem}.csv"));
    let run = bowl(&[
        "experiment",
        plan.to_str().unwrap(),
        "--rig-file",
        rig.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", common::stdout(&run));
    out
}

/// `bowl fit RESULTS --rig-file RIG --models flat --json`.
fn fit_on(results: &Path, rig: &Path) -> serde_json::Value {
    let fit = bowl(&[
        "fit",
        results.to_str().unwrap(),
        "--rig-file",
        rig.to_str().unwrap(),
        "--models",
        "flat",
        "--no-charts",
        "--json",
    ]);
    success_json(&fit, "bowl fit --rig-file")
}

/// The candidate name of the rig file's wall.
fn wall_of(rig: &Path) -> String {
    let b = rig_file::load(rig).unwrap()[0].bowl.unwrap();
    if b.wall_height_m == 0.0 {
        "bowl-bare-rim".into()
    } else {
        format!(
            "bowl-wall-{}deg-{}mm",
            b.wall_angle_deg,
            (b.wall_height_m * 1000.0).round()
        )
    }
}

/// `bowl experiment` then `bowl fit --rig-file` on rigs whose true wall is the example's 60 deg
/// wall 10 mm high, a 20 mm one, a bare rim, and a 45 deg wall 15 mm high that is none of the
/// fit's standard walls (the rig file's wall joins them; 18 releases each at random azimuths, which the
/// simulated rig records): the fit compares each release with the bowl model at its own
/// azimuth and names the true wall decisively (`preferred` and `walls.preferred`, AIC more than
/// 10 below every other wall), with a verdict in words; the true `mu_s` (0.4, the rig file's) is
/// inside its interval; the paper's flat model and the vertical wall (which holds every
/// release) cannot reproduce the times.
#[test]
fn a_bowl_experiment_names_its_true_wall_and_mu_s() {
    let dir = common::temp_dir("experiment-bowl-walls");
    let true_mu_s = truth().bowl.unwrap().sliding_mu;
    let rigs: [(&str, &[(&str, &str)]); 4] = [
        ("wall10", &[]),
        ("wall20", &[("wall_height_m", "0.02")]),
        ("bare", &[("wall_height_m", "0.0")]),
        // Not one of the fit's standard walls: the rig file's own joins them.
        (
            "wall45",
            &[("wall_angle_deg", "45.0"), ("wall_height_m", "0.015")],
        ),
    ];
    for (name, changes) in rigs {
        let rig = if changes.is_empty() {
            rig_path()
        } else {
            rig_variant(&dir, name, changes)
        };
        let out = experiment(&dir, &rig, 6);
        let rows = common::csv_rows(&out);
        assert!(
            rows.iter()
                .all(|r| r["release_azimuth_deg"].parse::<f64>().is_ok()),
            "{name}: every release's azimuth recorded"
        );
        let v = fit_on(&out, &rig);
        let true_wall = wall_of(&rig);
        assert_eq!(v["preferred"], true_wall.as_str(), "{name}: {v}");
        let walls = &v["walls"];
        assert_eq!(walls["preferred"], true_wall.as_str(), "{name}: {walls}");
        assert_eq!(walls["runs_with_azimuth"], 18, "{name}: {walls}");
        let ranked = walls["ranked"].as_array().unwrap();
        assert_eq!(ranked[0]["name"], true_wall.as_str(), "{name}: {walls}");
        assert!(
            ranked[1..]
                .iter()
                .all(|w| w["delta_aic"].as_f64().unwrap() > 10.0),
            "{name}: {walls}"
        );
        let text = walls["verdict"].as_str().unwrap();
        assert!(
            text.starts_with(&format!("the {true_wall}: AIC ")) && text.contains("lower than"),
            "{name}: {text}"
        );
        let m = &v["models"][true_wall.as_str()];
        let ci = (
            m["mu_ci95"][0].as_f64().unwrap(),
            m["mu_ci95"][1].as_f64().unwrap(),
        );
        assert!(
            ci.0 <= true_mu_s && true_mu_s <= ci.1,
            "{name}: mu_s {ci:?}: {v}"
        );
        for never in ["flat", "bowl-wall-vertical-20mm"] {
            assert!(
                v["models"][never]["cannot_reproduce"].is_string(),
                "{name}: {never}: {v}"
            );
        }
        eprintln!("{name}: {text}");
    }
}

/// A rig whose exit gate is far noisier (15 ms standard deviation, 9 % of `T`): the walls'
/// times at a known azimuth differ by less than that, and 18 releases cannot tell them apart. The
/// fit says so (`undecided`, "cannot tell ... from ..." with how far apart the walls are against
/// the scatter and how many releases would tell them), and never names a wrong wall.
#[test]
fn a_bowl_experiment_too_noisy_to_tell_the_walls_apart_says_so() {
    let dir = common::temp_dir("experiment-bowl-noisy");
    let rig = rig_variant(&dir, "noisy", &[("gate_jitter_s", "0.015")]);
    let out = experiment(&dir, &rig, 6);
    let v = fit_on(&out, &rig);
    let walls = &v["walls"];
    assert_eq!(walls["preferred"], "undecided", "{walls}");
    assert_ne!(v["preferred"], "bowl-wall-60deg-20mm", "{v}");
    let text = walls["verdict"].as_str().unwrap();
    assert!(
        text.starts_with("cannot tell the bowl-")
            && text.contains("% (RMS over the runs), the runs scatter by")
            && text.contains("releases would tell them apart"),
        "{text}"
    );
    eprintln!("{text}");
}

/// `bowl fit --rig-file` refuses in plain words: a rig file without a `[bowl]` table, a
/// `[bowl]` value out of range (the rig file's own check), a tilt given twice that disagrees,
/// and results measured on another bottom radius.
#[test]
fn bowl_fit_rig_file_refusals_are_plain_words() {
    let dir = common::temp_dir("experiment-bowl-refusals");
    let nominal = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/rigs/nominal.toml");
    // A results file with three releases (the refusals come before any fit).
    let out = experiment(&dir, &rig_path(), 1);
    let fit_err = |extra: &[&str]| {
        let mut args = vec!["fit", out.to_str().unwrap(), "--no-charts"];
        args.extend_from_slice(extra);
        let o = bowl(&args);
        assert!(!o.status.success(), "{extra:?} accepted");
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let e = fit_err(&["--rig-file", nominal.to_str().unwrap()]);
    assert!(
        e.contains("has no [bowl] table") && e.contains("docs/rigs/nominal.toml"),
        "{e}"
    );
    let bad = rig_variant(&dir, "bad", &[("wall_angle_deg", "120.0")]);
    let e = fit_err(&["--rig-file", bad.to_str().unwrap()]);
    assert!(e.contains("wall_angle_deg") && e.contains("90"), "{e}");
    let e = fit_err(&[
        "--rig-file",
        rig_path().to_str().unwrap(),
        "--axes-angle-deg",
        "45",
    ]);
    assert!(
        e.contains("--axes-angle-deg 45") && e.contains("axes_angle_deg is 60"),
        "{e}"
    );
    let wide = rig_variant(&dir, "wide", &[("rim_radius_m", "0.1")]);
    let e = fit_err(&["--rig-file", wide.to_str().unwrap()]);
    assert!(
        e.contains("rim radius 0.075 m") && e.contains("rim_radius_m = 0.1 m"),
        "{e}"
    );
    assert!(!e.contains("panicked"), "{e}");
    // Results from a rig tilted 45 deg fitted with the 60 deg rig file: refused with the tilt
    // the rows were combined at (it used to name a 20 mm wall that was not there, AIC 17 ahead).
    let at45 = experiment(
        &dir,
        &rig_variant(&dir, "tilt45", &[("axes_angle_deg", "45.0")]),
        1,
    );
    let o = bowl(&[
        "fit",
        at45.to_str().unwrap(),
        "--no-charts",
        "--rig-file",
        rig_path().to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{}", common::stdout(&o));
    assert!(
        e.contains("results line 2")
            && e.contains("tilt of 45.0 deg")
            && e.contains("tilt of 60 deg"),
        "{e}"
    );
    // Without a rig file the default 60 deg is refused too, and --axes-angle-deg 45 fits.
    let flag = |extra: &[&str]| {
        let mut args = vec![
            "fit",
            at45.to_str().unwrap(),
            "--no-charts",
            "--models",
            "flat",
        ];
        args.extend_from_slice(extra);
        args.push("--bowl-walls");
        bowl(&args)
    };
    let o = flag(&[]);
    assert!(
        !o.status.success() && String::from_utf8_lossy(&o.stderr).contains("--axes-angle-deg 45.0"),
        "{}",
        common::stdout(&o)
    );
    assert!(flag(&["--axes-angle-deg", "45"]).status.success());
}

/// `bowl experiment` writes a condition given as two motor speeds with the combined bowl speed
/// of paper Eq. 2 at the rig's own tilt (here a `[bowl]` tilted 30 deg), not a fixed 60 deg.
#[test]
fn an_experiment_combines_motor_speeds_at_the_rigs_tilt() {
    let dir = common::temp_dir("experiment-bowl-tilt");
    let rig = rig_variant(&dir, "tilt30", &[("axes_angle_deg", "30.0")]);
    let plan = dir.join("plan.toml");
    std::fs::write(
        &plan,
        "settle_s = 0.2\n[[condition]]\nprecession_rad_s = 2.0\nspin_rad_s = 3.0\nrepeats = 1\n",
    )
    .unwrap();
    let out = dir.join("tilt.csv");
    let run = bowl(&[
        "experiment",
        plan.to_str().unwrap(),
        "--rig-file",
        rig.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", common::stdout(&run));
    let rows = common::csv_rows(&out);
    let w: f64 = rows[0]["bowl_rad_s"].parse().unwrap();
    // |w1 z + w2 n| with the axes 30 deg apart: sqrt(4 + 9 + 12 cos 30).
    let want = (13.0 + 12.0 * 30f64.to_radians().cos()).sqrt();
    assert!((w - want).abs() < 1e-12, "{w} against {want}");
    let at_60 = (13.0 + 12.0 * 0.5f64).sqrt();
    assert!((w - at_60).abs() > 0.1);
}

/// `--suggest` on a bowl-model rig refuses in words and says what plan to run: it printed a
/// plan separating the paper's flat and Coriolis models (D = 14.9), neither of which can
/// reproduce this rig's times.
#[test]
fn suggest_on_a_bowl_rig_says_what_to_run() {
    let out = bowl(&[
        "experiment",
        "--suggest",
        "--rig-file",
        rig_path().to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{}", common::stdout(&out));
    assert!(
        e.contains("follow the bowl model")
            && e.contains("plan-bowl.toml")
            && e.contains("bowl fit RESULTS --rig-file"),
        "{e}"
    );
    assert!(!common::stdout(&out).contains("[[condition]]"));
}
