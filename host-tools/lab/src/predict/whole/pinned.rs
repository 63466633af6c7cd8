//! The chooser's decisions and answers pinned to the bit (docs/model.md §12, "The chooser's own
//! cost"): work on its speed must not move a choice, a `T` or a word. Each scene-tolerance of
//! the two cost grids is one line of `pinned.txt` (the level, the incline's mean and the
//! rotation's second order as `f64` bits, and a digest of everything else the choice holds and
//! says); the rotation estimate's fitting and held-out grids are one digest each. Written from
//! main before the chooser's overhead was cut; rewrite only for a change meant to move an
//! answer: `BOWL_PIN_WRITE=1 cargo test -p lab whole::pinned`.
//! Also the focused timing of the choice against the plain incline on the rows where the
//! chooser's own work shows: `cargo test --release` with §12's `--config` flags `-p lab
//! whole::pinned::choice_against_the_incline -- --ignored --nocapture`.

use std::fmt::Write as _;

use model_core::choose::incline_rotation::release_second_order_s;
use model_core::choose::whole::incline_mean_s;

use super::rotation_fit::{fitting_grid, held_out_grid, scene};
use super::*;

const PINNED: &str = include_str!("pinned.txt");

/// FNV-1a over the bytes of `s`.
fn digest(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn bits(x: Option<f64>) -> String {
    x.map_or("none".into(), |x| format!("{:016x}", x.to_bits()))
}

/// One scene-tolerance: the choice and what `bowl predict` answers and says with it.
fn line(s: &RollingScene<f64>, sh: &BowlShape<f64>, tol: f64) -> String {
    let c = choose_level(s, sh, tol, false);
    let mut rest = format!("{c:?}");
    for f in c.cheaper_fail.iter().flatten() {
        rest.push_str(&fails_words(f, tol));
    }
    if c.level == Level::Incline {
        rest.push_str(&incline_words(&c));
    }
    let _ = write!(
        rest,
        "{:?} {:?} {:?}",
        incline_mode(s),
        may_stick(s),
        c.rotation_estimate.to_bits()
    );
    // The per-release answers: the incline's, and to second order where it is corrected.
    for deg in AZIMUTHS_DEG {
        let b = deg.to_radians();
        let _ = write!(
            rest,
            " {} {:?}",
            bits(incline_release_s(s, b)),
            release_second_order_s(s, b).map(|(a, b, c)| (a.to_bits(), b.to_bits(), c.to_bits()))
        );
    }
    let _ = write!(rest, " {}", bits(incline_mean_s(s)));
    format!(
        "{:.0} {}/{} mu_s {} ri {} R {} wall {} fillet {} tol {tol}: {} mean {} c2 {} bound {} corrected {} rest {:016x}",
        s.axes_angle_rad.to_degrees(),
        s.precession_rad_s,
        s.spin_rad_s,
        s.sliding_friction,
        s.ri_m,
        s.rim_radius_m,
        sh.wall_height_m,
        sh.fillet_radius_m,
        c.level.name(),
        bits(c.incline_mean_s),
        bits(c.second_order.map(|b| b.c2)),
        bits(c.second_order.map(|b| b.bound)),
        c.second_order.is_some_and(|b| b.corrected),
        digest(&rest)
    )
}

const TOLERANCES: [f64; 3] = [0.05, 0.01, 0.001];

/// The cost grid and the held-out cost grid (`tests::cost_over`'s scenes).
fn cost_grids() -> Vec<(RollingScene<f64>, BowlShape<f64>)> {
    let rig = |tilt: f64, w1: f64, w2: f64, mu_s: f64| RollingScene {
        sliding_friction: mu_s,
        ..RollingScene::with_speeds(w1, w2, tilt.to_radians(), 0.075)
    };
    let shape = |angle: f64, height: f64, fillet: f64| BowlShape {
        wall_angle_rad: angle.to_radians(),
        wall_height_m: height,
        fillet_radius_m: fillet,
        restitution: 0.5,
    };
    let mut grid = Vec::new();
    for tilt in [10.0, 30.0, 45.0, 60.0] {
        for w in [0.5, 1.8, 3.6] {
            for mu_s in [0.2, 0.4, 0.6] {
                for (wa, wh) in [(90.0, 0.0), (60.0, 0.02)] {
                    grid.push((rig(tilt, w, w, mu_s), shape(wa, wh, 0.0)));
                }
            }
        }
    }
    for tilt in [20.0, 50.0, 70.0] {
        for (w1, w2) in [(0.8, 0.8), (2.5, 2.5), (2.5, -1.875)] {
            for mu_s in [0.3, 0.5] {
                for (wa, wh, fillet) in [(90.0, 0.0, 0.0), (70.0, 0.015, 0.005)] {
                    grid.push((rig(tilt, w1, w2, mu_s), shape(wa, wh, fillet)));
                }
            }
        }
    }
    grid
}

fn lines() -> Vec<String> {
    let mut out = Vec::new();
    for (s, sh) in cost_grids() {
        for tol in TOLERANCES {
            out.push(line(&s, &sh, tol));
        }
    }
    for (name, grid) in [("fitting", fitting_grid()), ("held-out", held_out_grid())] {
        let mut all = String::new();
        for row in grid {
            for tol in TOLERANCES {
                all.push_str(&line(&scene(row), &BowlShape::bare_rim(), tol));
                all.push('\n');
            }
        }
        out.push(format!(
            "rotation estimate's {name} grid: {:016x}",
            digest(&all)
        ));
    }
    out
}

/// Every choice, answer and word on the grids is the one pinned (see the module's text).
#[test]
fn the_choices_and_answers_are_the_pinned_ones() {
    let got = lines();
    if std::env::var_os("BOWL_PIN_WRITE").is_some() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/src/predict/whole/pinned.txt");
        std::fs::write(path, got.join("\n") + "\n").unwrap();
        return;
    }
    let want: Vec<&str> = PINNED.lines().collect();
    assert_eq!(got.len(), want.len(), "the pinned grids have another size");
    let moved: Vec<String> = got
        .iter()
        .zip(&want)
        .filter(|(g, w)| g != w)
        .map(|(g, w)| format!("now    {g}\npinned {w}"))
        .collect();
    assert!(
        moved.is_empty(),
        "{} moved:\n{}",
        moved.len(),
        moved.join("\n")
    );
}

/// The choice against the plain incline on the rows where the chooser's own work shows
/// (docs/model.md §12): the three rows the second order takes, rows the a-priori estimate
/// takes, and a corrected one. 1000 calls timed together, best of 5 and best of 25.
#[test]
#[ignore]
fn choice_against_the_incline() {
    let rows = [
        (
            "30 deg, 1.8 rad/s, mu_s 0.2 at 1 % (second order)",
            30.0,
            1.8,
            0.2,
            0.01,
        ),
        (
            "30 deg, 3.6 rad/s, mu_s 0.2 at 5 % (second order)",
            30.0,
            3.6,
            0.2,
            0.05,
        ),
        (
            "45 deg, 3.6 rad/s, mu_s 0.4 at 5 % (second order)",
            45.0,
            3.6,
            0.4,
            0.05,
        ),
        (
            "30 deg, 0.5 rad/s, mu_s 0.4 at 1 % (estimate)",
            30.0,
            0.5,
            0.4,
            0.01,
        ),
        (
            "60 deg, 1.8 rad/s, mu_s 0.4 at 5 % (estimate)",
            60.0,
            1.8,
            0.4,
            0.05,
        ),
        (
            "45 deg, 1.8 rad/s, mu_s 0.6 at 5 % (estimate)",
            45.0,
            1.8,
            0.6,
            0.05,
        ),
        (
            "60 deg, 2 rad/s, mu_s 0.4 at 0.1 % (corrected)",
            60.0,
            2.0,
            0.4,
            0.001,
        ),
    ];
    for (name, tilt, w, mu_s, tol) in rows {
        let s = RollingScene {
            sliding_friction: mu_s,
            ..RollingScene::with_speeds(w, w, f64::to_radians(tilt), 0.075)
        };
        let sh = BowlShape::bare_rim();
        assert_eq!(
            choose_level(&s, &sh, tol, false).level,
            Level::Incline,
            "{name}"
        );
        for batches in [5, 25] {
            let incline = per_call_s(batches, &|| {
                std::hint::black_box(incline_mean_s(std::hint::black_box(&s)));
            });
            let choice = per_call_s(batches, &|| {
                std::hint::black_box(choose_level(std::hint::black_box(&s), &sh, tol, false));
            });
            println!(
                "{name}: best of {batches:>2}: the incline {:.0} ns, the choice {:.0} ns, {:.2}x",
                incline * 1e9,
                choice * 1e9,
                choice / incline
            );
        }
    }
}

/// The time of one call of `f`, s: 1000 calls timed together, best of `batches`.
pub(super) fn per_call_s(batches: usize, f: &dyn Fn()) -> f64 {
    (0..batches)
        .map(|_| {
            let t0 = std::time::Instant::now();
            for _ in 0..1000 {
                f();
            }
            t0.elapsed().as_secs_f64() / 1000.0
        })
        .fold(f64::INFINITY, f64::min)
}
