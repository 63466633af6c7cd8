//! `bowl predict --model bowl`: a release still inside at `--max-time-s` whose last mode is
//! `held` says where it is held, in the text and in the JSON's `held_at` (issue 30). Before,
//! only a vertical wall's sharp corner said "held by the wall"; a granule the rolling
//! resistance held on the fillet or on the bottom said "still inside after ...", as one still
//! moving does.

mod common;

use common::{bowl, bowl_args, json};

/// A 75 mm bowl tilted 2 deg, 0.3 and 3 rad/s, a 45 deg wall 15 mm high with a 5 mm fillet,
/// released at 30 mm: the 150 deg release parks on the fillet within 5 s, the 180 deg one is
/// held on the bottom for the first 0.2 s, the 0 deg one still rolls at 5 s.
fn scene<'a>(beta: &'a str, horizon: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "predict",
        "--model",
        "bowl",
        "--axes-angle-deg",
        "2",
        "--precession-rad-s",
        "0.3",
        "--spin-rad-s",
        "3",
        "--rim-radius-m",
        "0.075",
        "--ri-m",
        "0.03",
        "--particle-radius-m",
        "0.003",
        "--mu",
        "0.029",
        "--sliding-mu",
        "0.4",
        "--restitution",
        "0.5",
        "--wall-angle-deg",
        "45",
        "--wall-height-m",
        "0.015",
        "--fillet-radius-m",
        "0.005",
        "--release-azimuth-deg",
        beta,
        "--max-time-s",
        horizon,
    ];
    args.extend_from_slice(extra);
    args
}

fn text(args: &[&str]) -> String {
    let out = bowl(args);
    assert_eq!(out.status.code(), Some(0), "{args:?}");
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn a_granule_held_on_the_fillet_or_the_bottom_says_so() {
    for (beta, horizon, words, at) in [
        (
            "150",
            "5",
            "held on the fillet: still inside after 5 s",
            "fillet",
        ),
        (
            "180",
            "0.2",
            "held at rest on the bottom: still inside after 0.2 s",
            "bottom",
        ),
    ] {
        let t = text(&scene(beta, horizon, &[]));
        assert!(
            t.contains(&format!("release at {beta} deg: {words}; regime")),
            "{t}"
        );
        let v = json(&scene(beta, horizon, &["--json"]));
        let rel = &v["per_release"][0];
        assert_eq!(rel["left"], false, "{rel}");
        assert_eq!(rel["outcome"], "inside", "{rel}");
        assert_eq!(rel["held_at"], at, "{rel}");
        assert!(rel["regime"]["held"].as_f64().unwrap() > 0.1, "{rel}");
    }
    // Still rolling at the horizon: not held.
    let t = text(&scene("0", "5", &[]));
    assert!(
        t.contains("release at 0 deg: still inside after 5 s; regime roll 100 %"),
        "{t}"
    );
    let v = json(&scene("0", "5", &["--json"]));
    assert!(v["per_release"][0]["held_at"].is_null(), "{v}");
}

/// A vertical wall's sharp corner (60 deg tilt, 1.2 and 2 rad/s, a 20 mm wall) holds it, as
/// before, and the JSON now says where.
#[test]
fn a_granule_held_in_a_vertical_corner_is_held_by_the_wall() {
    let args = bowl_args(
        "1.2",
        "2",
        "60",
        ["90", "0.02", "0"],
        &["--release-azimuth-deg", "0", "--json"],
    );
    let v = json(&args);
    assert_eq!(v["per_release"][0]["held_at"], "wall", "{v}");
}
