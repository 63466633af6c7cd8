//! `bowl chart stability`: beyond each fixed-step method's stability bound (computed here from
//! the fast mode `l2 = -k omega (s + k mu)` and the methods' real-axis limits) the model refuses
//! the step; below it the method returns a T whose error shrinks with the step at the method's
//! order.

mod common;

use std::collections::HashMap;
use std::process::Command;

use common::csv_rows;

fn rows() -> Vec<HashMap<String, String>> {
    let dir = std::env::temp_dir().join(format!("bowl-chart-stab-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("stability.svg");
    let o = Command::new(env!("CARGO_BIN_EXE_bowl"))
        .args(["chart", "stability", "--csv-only", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    csv_rows(&out.with_extension("csv"))
}

/// |l2| / omega for the two scenes of the chart (k2 = 5/7): mu 0.4 with Coriolis, mu 0 flat.
fn fast_rate(scene: &str) -> f64 {
    let k: f64 = (5.0f64 / 7.0).sqrt();
    let m = if scene == "mu0.4-coriolis" {
        k * 0.4
    } else {
        0.0
    };
    k * ((1.0 + m * m).sqrt() + m)
}

#[test]
fn refused_exactly_beyond_the_bound_and_convergent_below() {
    let rows = rows();
    let mut refused = 0;
    for scene in ["mu0.4-coriolis", "mu0-flat"] {
        for (method, limit, order) in [
            ("euler", Some(2.0), 1.0),
            ("rk4", Some(2.785_293_563_405_282), 4.0),
            ("semi-implicit-euler", None, 1.0),
        ] {
            let mine: Vec<_> = rows
                .iter()
                .filter(|r| r["scene"] == scene && r["method"] == method)
                .collect();
            assert!(mine.len() > 30, "{scene} {method}");
            let bound = limit.map(|c: f64| c / fast_rate(scene));
            let mut small = Vec::new();
            for r in &mine {
                let h: f64 = r["h_omega"].parse().unwrap();
                let beyond = bound.is_some_and(|b| h > b * (1.0 + 1e-9));
                if beyond {
                    assert_eq!(r["outcome"], "refused", "{r:?}");
                    refused += 1;
                } else {
                    assert_eq!(r["outcome"], "leaves", "{r:?}");
                    let e: f64 = r["rel_error"].parse().unwrap();
                    assert!(e.is_finite(), "{r:?}");
                    if h <= 0.05 {
                        small.push((h, e));
                    }
                }
            }
            // Observed order over the small steps: log-log slope between the ends.
            small.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (h0, e0) = small[0];
            let (h1, e1) = small[small.len() - 1];
            let slope = (e1 / e0).ln() / (h1 / h0).ln();
            assert!(
                (slope - order).abs() < 0.35,
                "{scene} {method}: observed order {slope}, expected {order}"
            );
        }
    }
    // Both explicit methods are refused somewhere on both scenes.
    assert!(refused >= 8, "{refused} refusals");
}
