//! `bowl chart bowl-regimes`: the regime map's CSV against the closed forms it must show.

mod common;

use common::{bowl, temp_dir};

/// At 2 rad/s on a bare rim the granule slides from the tilt where rolling down the incline
/// needs more than mu_s: `(1 - k2) tan th > 0.4`, th > 54.5 deg (the rotation shifts it a
/// little): none at 45 deg, all at 60 deg and above; a vertical 20 mm wall with a sharp corner
/// lets no release out at any tilt up to 75 deg; the bare rim lets every release out.
#[test]
fn the_regime_map_shows_the_sliding_threshold_and_the_held_granules() {
    let d = temp_dir("chart-bowl-regimes");
    let out = d.join("r.svg");
    let o = bowl(&[
        "chart",
        "bowl-regimes",
        "--csv-only",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(d.join("r.csv")).unwrap();
    let mut checked = 0;
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (shape, tilt, slide, leaving): (&str, f64, f64, f64) = (
            f[0],
            f[1].parse().unwrap(),
            f[2].parse().unwrap(),
            f[5].parse().unwrap(),
        );
        match shape {
            "bare rim" => {
                assert_eq!(leaving, 1.0, "{line}");
                if tilt <= 45.0 {
                    assert!(slide < 0.01, "{line}");
                }
                if tilt >= 60.0 {
                    assert!(slide > 0.99, "{line}");
                }
                checked += 1;
            }
            // Up to 75 deg; at 80 deg the bowl's axis is near horizontal, the normal force
            // small, and a granule that lifts off can fly over the wall (2 of 12 do).
            "vertical wall 20 mm" if tilt <= 75.0 => {
                assert_eq!(leaving, 0.0, "{line}");
                checked += 1;
            }
            _ => {}
        }
    }
    assert_eq!(checked, 31);
}

/// The regime map over tilt and speed (rod offset 0.3 m): flight rules where the bowl's own
/// centripetal acceleration lifts the granule off the bottom at release, `w1^2 L sin th >
/// g cos th` (the carrier term of the normal force, docs/model.md §9), by 15 % or more; below
/// 95 % of that speed no cell is mostly flight; at 5 deg and 0.5 rad/s the 20 mm wall holds
/// most releases, and on the steep side (70 deg and more) they slide below the lift-off.
#[test]
fn the_regime_map_flies_where_the_rod_lifts_the_granule_off() {
    let d = temp_dir("chart-bowl-regime-map");
    let out = d.join("m.svg");
    let o = bowl(&[
        "chart",
        "bowl-regime-map",
        "--csv-only",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(d.join("m.csv")).unwrap();
    let (mut flying, mut checked) = (0, 0);
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (tilt, w): (f64, f64) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        let dominant = f[6];
        let th = tilt.to_radians();
        let lift = (9.81 * th.cos() / (0.3 * th.sin())).sqrt();
        if w > 1.15 * lift {
            assert_eq!(dominant, "fly", "{line}");
            flying += 1;
        }
        if w < 0.95 * lift {
            assert_ne!(dominant, "fly", "{line}");
            checked += 1;
        }
        if tilt >= 70.0 && w < 0.95 * lift {
            assert_eq!(dominant, "slide", "{line}");
        }
        if tilt == 5.0 && w == 0.5 {
            assert_eq!(dominant, "held by the wall", "{line}");
        }
    }
    assert!(flying >= 10 && checked >= 100, "{flying} {checked}");
}
