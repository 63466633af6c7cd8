//! What a perturbation of the incline in the bowl's rotation could give the chooser
//! (docs/model.md §12, "The four rotation rows"), measured before building one: the rotation's
//! first-order part and its exact second-order part, per scene of the rotation estimate's
//! fitting and held-out grids, against the rolling-or-sliding disc at rtol 1e-10.
//!
//! - **First order.** Mirroring the scene in the plane of the bowl's axis and the downhill
//!   direction at release turns `beta` into `-beta` and both speeds into their negatives, so
//!   `T(beta, w1, w2) = T(-beta, -w1, -w2)`; the twelve azimuths are symmetric, so the mean
//!   over them is even in the speeds: its first-order part is zero on every scene. A
//!   first-order correction (the Coriolis and gyroscopic terms along the incline's path, and
//!   the turning downhill direction) moves single releases (their odd part, printed) and
//!   leaves the mean as it is. Checked here: the mean at `(w1, w2)` and at `(-w1, -w2)` agree
//!   to the integrator's tolerance.
//! - **Second order.** `D(s) = (T(s w1, s w2) - T_incline) / T_incline` is even in `s`:
//!   `D(s) = c2 s^2 + c4 s^4 + ...`. `c2` (Richardson from `s` = 1/4 and 1/8) is what an exact
//!   second-order perturbation of the incline would give at the scene, the best any such closed
//!   form can do. Two uses, each fitted per incline mode on the fitting grid as `ROTATION_K` is
//!   (today's three modes, and with the near-threshold one split by [`mode_of`]) and checked on
//!   the held-out grid and the cost grids' bare rims:
//!   (a) the corrected incline `T_incline (1 + c2)`, its error bounded by `K4 F^2`
//!   (`F` = [`rotation_form`], the rotation's size; the remainder is fourth order);
//!   (b) the plain incline, its error bounded by `|c2| + K4 F^2`.
//!
//! `c2` comes from integrating the disc here: this measures what a closed form would give.
//! The closed form (model-core `choose::incline_rotation`, rolling only) is what the chooser
//! runs where the a-priori estimate refuses the incline: (b) with the closed-form `c2`, its
//! `K4` per mode fitted here on the fitting grid (model-core's `SECOND_ORDER_K4` and
//! `SECOND_ORDER_K4_NEAR_RIM` must cover it), and no scene of the fitting or held-out grids
//! taken beyond a tolerance (asserted).
//!
//! `cargo test --release -p lab whole::rotation_orders -- --ignored --nocapture` (with §12's
//! `--config` flags; prints `ORDERS,...` per scene, the counts per tolerance, the bounds on
//! the cost grids' rotation rows and the incline's and the choice's cost).
//!
//! [`rotation_form`]: model_core::choose::whole::rotation_form

use model_core::choose::whole::{
    CORRECTED_K4, CORRECTED_K4_NEAR_RIM, CORRECTED_K4_SLIDING, InclineMode, SECOND_ORDER_K4,
    SECOND_ORDER_K4_NEAR_RIM, SECOND_ORDER_K4_SLIDING, friction_needed_at_rim, incline_mean_s,
    incline_mode, incline_times_s, rotation_estimate, rotation_form, second_order_bound,
};

use super::rotation_fit::{Row, disc_times_s, fitting_grid, held_out_grid, scene};
use super::*;

/// Which grid a scene is from.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Fit,
    Held,
    /// The cost grids' rotation rows (docs/model.md §12).
    Row,
    /// The cost grids' bare-rim scenes (docs/model.md §12).
    Cost,
}

/// Each grid with the name its counts are printed under.
const GRIDS: [(&str, Kind); 4] = [
    ("fitting", Kind::Fit),
    ("held-out", Kind::Held),
    ("rows", Kind::Row),
    ("cost grids' bare rims", Kind::Cost),
];

/// One scene's orders.
struct Orders {
    kind: Kind,
    /// The scene, for the printout.
    label: String,
    /// The incline's mode ([`mode_of`]).
    mode: usize,
    /// `F`, the rotation estimate's form.
    form: f64,
    /// The incline's relative error against the disc (absolute value).
    err: f64,
    /// `c2`, the exact second-order part of `(T - T_incline) / T_incline`.
    c2: f64,
    /// The corrected incline's relative error against the disc (absolute value).
    corrected_err: f64,
    /// Today's estimate (`rotation_estimate`).
    estimate: f64,
    /// `|T(w1, w2) - T(-w1, -w2)| / T` of the mean (zero but for the integrator).
    mirror: f64,
    /// `c2` from the closed form of `model_core::choose::incline_rotation` (rolling only).
    closed: f64,
    /// The chooser's bound on the plain incline's error from the closed form
    /// (`second_order_bound`; infinite where it gives none).
    chooser_bound: f64,
    /// The incline corrected by the closed-form `c2`: its relative error against the disc.
    closed_corrected_err: f64,
    /// The chooser's bound on that error (`second_order_bound`'s `corrected_bound`; infinite
    /// where it gives none).
    chooser_corrected_bound: f64,
}

fn scaled(s: &RollingScene<f64>, k: f64) -> RollingScene<f64> {
    RollingScene {
        precession_rad_s: k * s.precession_rad_s,
        spin_rad_s: k * s.spin_rad_s,
        ..*s
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn orders(name: &str, kind: Kind, r: Row) -> Option<Orders> {
    let s = scene(r);
    let t0 = incline_mean_s(&s)?;
    let plus = disc_times_s(&s)?;
    let minus = disc_times_s(&scaled(&s, -1.0))?;
    let quarter = mean(&disc_times_s(&scaled(&s, 0.25))?);
    let eighth = mean(&disc_times_s(&scaled(&s, 0.125))?);
    let t = mean(&plus);
    // The mirror: the mean is even in the speeds.
    let mirror = (t - mean(&minus)).abs() / t;
    // The odd part per release: what a first-order correction would move.
    let odd = plus
        .iter()
        .zip(&minus)
        .map(|(p, m)| (p - m).abs() / 2.0 / t0)
        .fold(0.0, f64::max);
    let d = |tm: f64| (tm - t0) / t0;
    // D(s)/s^2 = c2 + c4 s^2: Richardson from s = 1/4 and 1/8.
    let (q, e) = (d(quarter) / 0.0625, d(eighth) / 0.015625);
    let c2 = (4.0 * e - q) / 3.0;
    let corrected = t0 * (1.0 + c2);
    let (tilt, w1, w2, mu_s, ri, rim) = r;
    let closed =
        model_core::choose::incline_rotation::mean_second_order(&s).map_or(f64::NAN, |m| m.1);
    let bound =
        incline_times_s(&s).and_then(|ts| second_order_bound(&s, &ts, t0, incline_mode(&s)));
    let o = Orders {
        kind,
        label: format!("{tilt} deg, {w1}/{w2} rad/s, mu_s {mu_s}, ri {ri}, R {rim}"),
        mode: mode_of(&s),
        form: rotation_form(&s, t0),
        err: ((t0 - t) / t).abs(),
        c2,
        corrected_err: ((corrected - t) / t).abs(),
        estimate: rotation_estimate(&s, t0),
        mirror,
        closed,
        chooser_bound: bound.map_or(f64::INFINITY, |b| b.bound),
        closed_corrected_err: ((t0 * (1.0 + closed) - t) / t).abs(),
        chooser_corrected_bound: bound.map_or(f64::INFINITY, |b| b.corrected_bound),
    };
    println!(
        "ORDERS,{name},{tilt},{w1},{w2},{mu_s},{ri},{rim},mode {},rim need {:.4},F {:.4},err {:.3e},D(1) {:.3e},c2 {:.3e},corrected err {:.3e},estimate {:.3e},mirror {mirror:.1e},odd per release {odd:.3e},closed c2 {closed:.3e},need at rest {:.4},closed corrected err {:.3e},chooser corrected bound {:.3e}",
        o.mode,
        friction_needed_at_rim(&s) / mu_s,
        o.form,
        o.err,
        d(t),
        o.c2,
        o.corrected_err,
        o.estimate,
        model_core::choose::whole::incline_friction_needed(&s) / mu_s,
        o.closed_corrected_err,
        o.chooser_corrected_bound
    );
    Some(o)
}

/// The incline's modes as the rotation estimate has them (0 rolls to the rim, 1 slides, 2 near
/// the stick threshold), with the last split in two: 2 where the rotation brings the granule
/// near it at the rim, 3 where the incline itself is near it at rest (model-core
/// `choose::whole::incline_mode`).
fn mode_of(s: &RollingScene<f64>) -> usize {
    match incline_mode(s) {
        InclineMode::Rolls => 0,
        InclineMode::Slides => 1,
        InclineMode::NearAtRim => 2,
        InclineMode::NearAtRest => 3,
    }
}

/// Per mode key, the constant `K4` of a bound `K4 F^2`: the least that covers `need` on every
/// fitting scene of that key.
fn fitted(
    rows: &[Orders],
    key: &dyn Fn(&Orders) -> usize,
    need: &dyn Fn(&Orders) -> f64,
) -> [f64; 4] {
    let mut k = [0.0f64; 4];
    for o in rows.iter().filter(|o| o.kind == Kind::Fit) {
        let r = need(o) / (o.form * o.form);
        if r.is_finite() {
            k[key(o)] = k[key(o)].max(r);
        }
    }
    k
}

/// Per tolerance: in how many scenes the bounded level is taken, of those where its error is
/// within the tolerance, and how many are taken beyond it.
fn counts(
    rows: &[Orders],
    kind: Kind,
    err: &dyn Fn(&Orders) -> f64,
    bound: &dyn Fn(&Orders) -> f64,
) -> String {
    let rows: Vec<&Orders> = rows.iter().filter(|o| o.kind == kind).collect();
    let cover = rows
        .iter()
        .filter(|o| bound(o) <= 0.1)
        .map(|o| err(o) / bound(o))
        .fold(0.0, f64::max);
    let per_tol = [0.05, 0.01, 0.001]
        .iter()
        .map(|&tol| {
            let ok = rows.iter().filter(|o| err(o) <= tol).count();
            let taken = rows.iter().filter(|o| bound(o) <= tol).count();
            let beyond = rows
                .iter()
                .filter(|o| bound(o) <= tol && err(o) > tol)
                .count();
            format!("{tol}: {taken} of {ok} ({beyond} beyond)")
        })
        .collect::<Vec<_>>()
        .join(", ");
    format!("{per_tol}; largest error / bound {cover:.3}")
}

/// The measurement (see the module's text).
#[test]
#[ignore]
fn rotation_orders() {
    let mut rows = Vec::new();
    for r in fitting_grid() {
        rows.extend(orders("fit", Kind::Fit, r));
    }
    for r in held_out_grid() {
        rows.extend(orders("held", Kind::Held, r));
    }
    // The cost grid's four rotation rows and the held-out cost grid's three (docs/model.md
    // §12), bare rims.
    for r in [
        (30.0, 1.8, 1.8, 0.2, 0.0375, 0.075),
        (30.0, 3.6, 3.6, 0.2, 0.0375, 0.075),
        (45.0, 3.6, 3.6, 0.4, 0.0375, 0.075),
        (60.0, 3.6, 3.6, 0.4, 0.0375, 0.075),
        (50.0, 0.8, 0.8, 0.3, 0.0375, 0.075),
        (50.0, 2.5, -1.875, 0.3, 0.0375, 0.075),
        (50.0, 2.5, 2.5, 0.3, 0.0375, 0.075),
    ] {
        rows.extend(orders("row", Kind::Row, r));
    }
    // The cost grid's and the held-out cost grid's bare rims (75 mm, ri 37.5 mm).
    for tilt in [10.0, 30.0, 45.0, 60.0] {
        for w in [0.5, 1.8, 3.6] {
            for mu_s in [0.2, 0.4, 0.6] {
                rows.extend(orders(
                    "cost",
                    Kind::Cost,
                    (tilt, w, w, mu_s, 0.0375, 0.075),
                ));
            }
        }
    }
    for tilt in [20.0, 50.0, 70.0] {
        for (w1, w2) in [(0.8, 0.8), (2.5, 2.5), (2.5, -1.875)] {
            for mu_s in [0.3, 0.5] {
                rows.extend(orders(
                    "cost",
                    Kind::Cost,
                    (tilt, w1, w2, mu_s, 0.0375, 0.075),
                ));
            }
        }
    }
    let n = |k: Kind| rows.iter().filter(|o| o.kind == k).count();
    let mirror = rows.iter().map(|o| o.mirror).fold(0.0, f64::max);
    println!(
        "{} fitting and {} held-out scenes; the mean at (w1, w2) against (-w1, -w2): {mirror:.1e}",
        n(Kind::Fit),
        n(Kind::Held)
    );
    // The closed form against the measured c2 where the incline is not near the stick threshold
    // at rest (modes 0, 1 and 2: T is smooth in the speeds there), rolling and sliding apart.
    for (name, modes) in [("rolling", [0, 2]), ("sliding", [1, 1])] {
        let of_mode = || rows.iter().filter(|o| modes.contains(&o.mode));
        let worst = of_mode()
            .map(|o| ((o.closed - o.c2) / o.c2).abs())
            .fold(0.0, f64::max);
        println!(
            "closed-form c2 against the measured one, {} {name} scenes: largest relative difference {worst:.2e}",
            of_mode().count()
        );
    }
    // Today's three modes, and the near-threshold one split (at rest / at the rim).
    let three = |o: &Orders| o.mode.min(2);
    let four = |o: &Orders| o.mode;
    let plain = |o: &Orders| o.err;
    let corr = |o: &Orders| o.corrected_err;
    let today = |o: &Orders| o.estimate;
    println!(
        "today's estimate: fitting {}; held-out {}; rows {}",
        counts(&rows, Kind::Fit, &plain, &today),
        counts(&rows, Kind::Held, &plain, &today),
        counts(&rows, Kind::Row, &plain, &today)
    );
    for (split, key) in [
        ("three modes", &three as &dyn Fn(&Orders) -> usize),
        ("four modes", &four),
    ] {
        // (a) the corrected incline, bounded by K4 F^2.
        let ka = fitted(&rows, key, &corr);
        let bound_a = |o: &Orders| ka[key(o)] * o.form * o.form;
        // (b) the plain incline, bounded by |c2| + K4 F^2.
        let kb = fitted(&rows, key, &|o: &Orders| (o.err - o.c2.abs()).max(0.0));
        let bound_b = |o: &Orders| o.c2.abs() + kb[key(o)] * o.form * o.form;
        let show = |k: &[f64]| {
            k.iter()
                .map(|k| format!("{k:.2e}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        println!("{split}: K4 (a) {}, (b) {}", show(&ka), show(&kb));
        for (name, kind) in GRIDS {
            println!(
                "  {name}: (a) corrected {}",
                counts(&rows, kind, &corr, &bound_a)
            );
            println!(
                "  {name}: (b) |c2| + K4 F^2 {}",
                counts(&rows, kind, &plain, &bound_b)
            );
            // Either: the plain incline where (b) takes it, else the corrected one where (a)
            // does; against today's estimate.
            let per_tol = [0.05, 0.01, 0.001]
                .iter()
                .map(|&tol| {
                    let rs = rows.iter().filter(|o| o.kind == kind);
                    let today_n = rs.clone().filter(|o| today(o) <= tol).count();
                    let either = rs
                        .clone()
                        .filter(|o| bound_b(o) <= tol || bound_a(o) <= tol);
                    let beyond = either
                        .clone()
                        .filter(|o| {
                            if bound_b(o) <= tol {
                                o.err > tol
                            } else {
                                o.corrected_err > tol
                            }
                        })
                        .count();
                    format!(
                        "{tol}: {} (today {today_n}, {beyond} beyond)",
                        either.count()
                    )
                })
                .collect::<Vec<_>>()
                .join(", ");
            println!("  {name}: taken by (b) or (a) {per_tol}");
        }
        for o in rows.iter().filter(|o| o.kind == Kind::Row) {
            println!(
                "  row {}: bound (a) {:.2e} (its error {:.2e}), (b) {:.2e} (its error {:.2e})",
                o.label,
                bound_a(o),
                o.corrected_err,
                bound_b(o),
                o.err
            );
        }
    }
    // The chooser's bound (model-core `second_order_bound`): (b) with the closed-form c2, where
    // the incline rolls to the rim or only the rotation brings it near the threshold there.
    // Its K4 per mode is fitted here on the fitting grid; model-core's constants must cover it.
    // Fitted where the chooser offers the bound (not where a sliding granule may stick,
    // `may_stick`).
    let kc = fitted(&rows, &four, &|o: &Orders| {
        if o.chooser_bound.is_finite() {
            (o.err - o.closed.abs()).max(0.0)
        } else {
            f64::NAN
        }
    });
    println!(
        "the chooser's bound |c2 closed| + K4 F^2: K4 fitted {:.3e} (rolls), {:.3e} (slides), {:.3e} (near at the rim); model-core {SECOND_ORDER_K4:e}, {SECOND_ORDER_K4_SLIDING:e}, {SECOND_ORDER_K4_NEAR_RIM:e}",
        kc[0], kc[1], kc[2]
    );
    // The corrected incline's K4 per mode, fitted as above with the closed-form c2.
    let kcc = fitted(&rows, &four, &|o: &Orders| {
        if o.chooser_bound.is_finite() {
            o.closed_corrected_err
        } else {
            f64::NAN
        }
    });
    println!(
        "the chooser's corrected incline, bound K4c F^2: K4c fitted {:.3e} (rolls), {:.3e} (slides), {:.3e} (near at the rim); model-core {CORRECTED_K4:e}, {CORRECTED_K4_SLIDING:e}, {CORRECTED_K4_NEAR_RIM:e}",
        kcc[0], kcc[1], kcc[2]
    );
    let chooser = |o: &Orders| o.chooser_bound;
    let either = |o: &Orders| o.estimate.min(o.chooser_bound);
    // The chooser's rule at `tol` (`choose_level`): the plain incline where the estimate or the
    // second order's bound holds, else the corrected one where its bound does; `Some(error)`
    // of what it takes.
    let takes = |o: &Orders, tol: f64| {
        if either(o) <= tol {
            Some(o.err)
        } else if o.chooser_corrected_bound <= tol {
            Some(o.closed_corrected_err)
        } else {
            None
        }
    };
    let mut beyond = 0;
    for (name, kind) in GRIDS {
        println!(
            "  {name}: the chooser's bound alone {}",
            counts(&rows, kind, &plain, &chooser)
        );
        println!(
            "  {name}: the chooser (estimate, else the bound) {}; today {}",
            counts(&rows, kind, &plain, &either),
            counts(&rows, kind, &plain, &today)
        );
        let per_tol = [0.05, 0.01, 0.001]
            .iter()
            .map(|&tol| {
                let rs = || rows.iter().filter(|o| o.kind == kind);
                let plain = rs().filter(|o| either(o) <= tol).count();
                let all = rs().filter(|o| takes(o, tol).is_some()).count();
                let out = rs()
                    .filter(|o| takes(o, tol).is_some_and(|e| e > tol))
                    .count();
                format!("{tol}: {all} ({plain} plain, {out} beyond)")
            })
            .collect::<Vec<_>>()
            .join(", ");
        println!("  {name}: the chooser, the corrected incline too: {per_tol}");
        beyond += rows
            .iter()
            .filter(|o| o.kind == kind && (kind == Kind::Fit || kind == Kind::Held))
            .filter(|o| {
                [0.05, 0.01, 0.001]
                    .iter()
                    .any(|&t| takes(o, t).is_some_and(|e| e > t))
            })
            .count();
    }
    for o in rows.iter().filter(|o| o.kind == Kind::Row) {
        println!(
            "  row {}: the chooser's bound {:.2e} (c2 closed {:.2e}, the error {:.2e}); corrected {:.2e} (the error {:.2e})",
            o.label,
            o.chooser_bound,
            o.closed,
            o.err,
            o.chooser_corrected_bound,
            o.closed_corrected_err
        );
    }
    costs();
    assert!(
        kc[0] <= SECOND_ORDER_K4
            && kc[1] <= SECOND_ORDER_K4_SLIDING
            && kc[2] <= SECOND_ORDER_K4_NEAR_RIM
            && kcc[0] <= CORRECTED_K4
            && kcc[1] <= CORRECTED_K4_SLIDING
            && kcc[2] <= CORRECTED_K4_NEAR_RIM,
        "model-core's K4 does not cover the fitting grid: {kc:?} {kcc:?}"
    );
    assert_eq!(
        beyond, 0,
        "taken beyond the tolerance on the fitting or held-out grid"
    );
    // The mirror holds on every scene to the integrator's tolerance (rtol 1e-10 per release;
    // 1.9e-8 and 6.7e-8 where the granule switches between rolling and sliding, whose time
    // the integrator locates less exactly): the mean's first-order part is zero.
    assert!(
        mirror < 1e-6,
        "the mean is not even in the speeds: {mirror:e}"
    );
}

// The two checks behind the claims above (the mirror, the closed form against the disc).
mod checks;
// What the bounds cost where they take the incline.
mod costs;
use costs::costs;
// Why the cost grid's sticking row is not taken (docs/model.md §12).
mod sticking_row;
