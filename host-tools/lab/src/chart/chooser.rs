//! `bowl chart chooser`: how good the chooser's plans are. On a grid of spin-up scenes (the
//! speed omega(t) a PI loop gives from rest or a low speed, docs/model.md) and tolerances, the
//! plan `choose::choose_varying_for` picks is compared with the cheapest plan found by brute
//! force: every method at a fine geometric grid of settings (RK4 and semi-implicit Euler steps
//! 2^(1/4) apart, DP5(4) tolerances 10^(1/4) apart), each measured against a tight DP5(4)
//! (rtol 1e-12) of the same model, priced by the same measured cost table (host ns). The chart
//! draws the chosen plan's cost over the cheapest's for each scene; the CSV has the plans, their
//! errors and whether the chosen one met the tolerance.

use anyhow::Result;
use model_core::choose::{Need, Plan, Source, Target, choose_varying_for, plan_cost};
use model_core::ode::{Limits, Method, OdeOutcome, SpinUp};
use model_core::particle::{self, Model, Scene};

// DP5(4) at a tolerance by the one rule of `bowl predict --method dp54 --tol` and the
// work-precision chart, for the reference, the brute-force grid and the baseline alike: a
// tolerance in this chart's table is the plan the CLI runs at that tolerance (the chart had its
// own absolute tolerance, `rtol R / 100`, a third rule; host-tools/tests/predict_plan.rs).
use crate::predict::ode::dp54;

use super::plot::{Figure, Mark, Scale, Series};
use super::table::Table;

/// `T` of one run and its right-hand-side evaluations; `T` infinite when it does not leave (or
/// fails).
pub fn time(s: &Scene<f64>, m: Model, p: &SpinUp<f64>, method: Method<f64>) -> (f64, u32) {
    let limits = Limits::for_scene(s, p);
    match particle::integrate(s, m, p, method, limits) {
        Ok(r) => match r.outcome {
            OdeOutcome::Leaves {
                residence_time_s, ..
            } => (residence_time_s, r.rhs_evaluations),
            _ => (f64::INFINITY, r.rhs_evaluations),
        },
        Err(_) => (f64::INFINITY, u32::MAX),
    }
}

/// Not choosing: an adaptive method told the tolerance (DP5(4) at a tenth of it), the usual way
/// to meet a tolerance without knowing the scene; the chart's baseline for what choosing saves.
pub fn not_choosing(tolerance: f64, s: &Scene<f64>) -> Method<f64> {
    dp54(tolerance * 0.1, s)
}

/// A plan found by brute force: (cost, method, error).
type Found = (f64, Method<f64>, f64);

/// The cheapest plans meeting `tolerance`: any setting that meets it, and the cheapest
/// *dependable* one, a setting that meets it together with every finer setting of its method
/// (the error of a step-size sweep is not monotone: near the rim's event a coarse step can land
/// on a cancellation of errors that a slightly finer one does not share, and no chooser can
/// know that without running the plan).
fn cheapest(
    s: &Scene<f64>,
    m: Model,
    p: &SpinUp<f64>,
    t_ref: f64,
    tolerance: f64,
) -> (Option<Found>, Option<Found>) {
    let w_max = p.final_rad_s.max(p.start_rad_s).max(1e-9);
    // Each method's settings, coarse to fine.
    let steps = |k: u32| 1.5 / w_max * 2f64.powf(-f64::from(k) / 4.0);
    let families: [Vec<Method<f64>>; 3] = [
        (0..72).map(|k| Method::Rk4 { step_s: steps(k) }).collect(),
        (0..72)
            .map(|k| Method::SemiImplicitEuler { step_s: steps(k) })
            .collect(),
        (0..44)
            .map(|k| dp54(0.1 * 10f64.powf(-f64::from(k) / 4.0), s))
            .collect(),
    ];
    let cheaper = |a: Option<Found>, b: Found| match a {
        Some(a) if a.0 <= b.0 => Some(a),
        _ => Some(b),
    };
    let (mut any, mut dependable) = (None, None);
    for family in families {
        let runs: Vec<(Found, bool)> = family
            .into_iter()
            .map(|method| {
                let (t, evals) = time(s, m, p, method);
                let err = (t - t_ref).abs() / t_ref;
                let cost = plan_cost(&Plan::Integrate(method), evals, Target::Host);
                ((cost, method, err), err <= tolerance)
            })
            .collect();
        for &(found, meets) in &runs {
            if meets {
                any = cheaper(any, found);
            }
        }
        // From the finest setting back while every one meets the tolerance.
        let held = runs.iter().rev().take_while(|(_, meets)| *meets);
        if let Some(best) = held.map(|(f, _)| *f).min_by(|a, b| a.0.total_cmp(&b.0)) {
            dependable = cheaper(dependable, best);
        }
    }
    (any, dependable)
}

/// The shortest of 7 timed calls of `f` (after one untimed), ns: the least disturbed.
fn best_ns(mut f: impl FnMut()) -> f64 {
    f();
    (0..7)
        .map(|_| {
            let start = std::time::Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e9
        })
        .fold(f64::INFINITY, f64::min)
}

fn method_name(m: &Method<f64>) -> String {
    match m {
        Method::Rk4 { step_s } => format!("rk4 h={step_s:.3e}"),
        Method::SemiImplicitEuler { step_s } => format!("semi-implicit h={step_s:.3e}"),
        Method::Euler { step_s } => format!("euler h={step_s:.3e}"),
        Method::Dp54 { rtol, .. } => format!("dp54 rtol={rtol:.1e}"),
    }
}

/// The optimality chart, the chart of what choosing costs, and their table.
pub fn chart() -> Result<(Figure, Figure, Table)> {
    let mut table = Table::new(&[
        "scene",
        "tolerance",
        "model",
        "chosen",
        "chosen_error",
        "chosen_cost_ns",
        "cheapest",
        "cheapest_error",
        "cheapest_cost_ns",
        "cost_ratio",
        "dependable_cheapest",
        "dependable_cost_ns",
        "cost_ratio_dependable",
        "met_tolerance",
        "choosing_evaluations",
        "choosing_ns",
        "plan_ns",
        "choosing_over_plan",
        "adaptive_ns",
        "adaptive_error",
        "saved_ns",
        "choosing_over_saved",
    ]);
    let mut series: Vec<Series> = Vec::new();
    let (mut worst, mut misses, mut n) = (0.0f64, 0, 0);
    let (mut worst_dependable, mut within, mut within_dependable) = (0.0f64, 0, 0);
    let mut choosing_ratios: Vec<f64> = Vec::new();
    let mut paybacks: Vec<f64> = Vec::new();
    let mut from_table = 0;
    let mut cost_series: Vec<Series> = Vec::new();
    for (ti, tolerance) in [1e-3, 1e-5, 1e-7].into_iter().enumerate() {
        let mut points = Vec::new();
        let mut cost_points = Vec::new();
        for mu in [0.01, 0.029, 0.1] {
            for (start, end) in [(0.0, 3.0), (1.0, 3.0), (0.0, 6.0)] {
                for tau in [0.3, 2.0] {
                    let s = Scene {
                        omega_rad_s: end,
                        mu,
                        g_m_s2: 9.81,
                        k2: 5.0 / 7.0,
                        ri_m: 0.05,
                        rim_radius_m: 0.1,
                    };
                    let p = SpinUp {
                        start_rad_s: start,
                        final_rad_s: end,
                        time_constant_s: tau,
                    };
                    let need = Need::Tolerance(tolerance);
                    let Ok(c) = choose_varying_for(&s, &need, &p) else {
                        continue;
                    };
                    // What choosing costs against what the chosen plan costs, both timed.
                    let choosing_ns = best_ns(|| {
                        std::hint::black_box(choose_varying_for(&s, &need, &p).ok());
                    });
                    let Plan::Integrate(method) = c.plan else {
                        continue;
                    };
                    let (t_ref, _) = time(&s, c.model, &p, dp54(1e-12, &s));
                    if !t_ref.is_finite() {
                        continue;
                    }
                    // The chosen plan's cost as it runs (its evaluations, not the choice's
                    // estimate of them), priced like every candidate.
                    let (t, evals) = time(&s, c.model, &p, method);
                    let chosen_cost = plan_cost(&c.plan, evals, Target::Host);
                    let plan_ns = best_ns(|| {
                        std::hint::black_box(time(&s, c.model, &p, method));
                    });
                    choosing_ratios.push(choosing_ns / plan_ns);
                    let adaptive = not_choosing(tolerance, &s);
                    let (t_adaptive, _) = time(&s, c.model, &p, adaptive);
                    let adaptive_ns = best_ns(|| {
                        std::hint::black_box(time(&s, c.model, &p, adaptive));
                    });
                    let saved_ns = adaptive_ns - plan_ns;
                    // Runs of the scene after which choosing has paid for itself (infinite
                    // when the chosen plan saves nothing).
                    let payback = if saved_ns > 0.0 {
                        choosing_ns / saved_ns
                    } else {
                        f64::INFINITY
                    };
                    paybacks.push(payback);
                    cost_points.push((cost_points.len() as f64 + 1.0, payback.min(1e3)));
                    let err = (t - t_ref).abs() / t_ref;
                    // The chooser's own plan is a candidate too: its step lies off the grid.
                    let own = (chosen_cost, method, err);
                    let or_own = |found: Option<Found>| match found {
                        Some(b) if b.0 < chosen_cost || err > tolerance => b,
                        _ => own,
                    };
                    let (any, dependable) = cheapest(&s, c.model, &p, t_ref, tolerance);
                    let (best_cost, best, best_err) = or_own(any);
                    let (dep_cost, dep, _) = or_own(dependable);
                    let ratio = chosen_cost / best_cost;
                    let ratio_dependable = chosen_cost / dep_cost;
                    n += 1;
                    worst = worst.max(ratio);
                    worst_dependable = worst_dependable.max(ratio_dependable);
                    within += usize::from(ratio <= 1.25);
                    within_dependable += usize::from(ratio_dependable <= 1.25);
                    let met = err <= tolerance;
                    from_table += usize::from(c.source == Source::Table);
                    if !met {
                        misses += 1;
                    }
                    let name = format!("mu={mu} {start}->{end} rad/s tau={tau} s");
                    points.push((points.len() as f64 + 1.0, ratio));
                    table.row(vec![
                        name,
                        format!("{tolerance:e}"),
                        format!("{:?}", c.model).to_lowercase(),
                        method_name(&method),
                        format!("{err:.3e}"),
                        format!("{chosen_cost:.0}"),
                        method_name(&best),
                        format!("{best_err:.3e}"),
                        format!("{best_cost:.0}"),
                        format!("{ratio:.3}"),
                        method_name(&dep),
                        format!("{dep_cost:.0}"),
                        format!("{ratio_dependable:.3}"),
                        met.to_string(),
                        c.choosing_evaluations.to_string(),
                        format!("{choosing_ns:.0}"),
                        format!("{plan_ns:.0}"),
                        format!("{:.2}", choosing_ns / plan_ns),
                        format!("{adaptive_ns:.0}"),
                        format!("{:.3e}", (t_adaptive - t_ref).abs() / t_ref),
                        format!("{saved_ns:.0}"),
                        format!("{payback:.2}"),
                    ]);
                }
            }
        }
        series.push(Series {
            name: format!("tolerance {tolerance:e}"),
            points,
            mark: Mark::Points,
            color: ti,
        });
        cost_series.push(Series {
            name: format!("tolerance {tolerance:e}"),
            points: cost_points,
            mark: Mark::Points,
            color: ti,
        });
    }
    choosing_ratios.sort_by(f64::total_cmp);
    let choosing_median = choosing_ratios
        .get(choosing_ratios.len() / 2)
        .copied()
        .unwrap_or(f64::NAN);
    let choosing_worst = choosing_ratios.last().copied().unwrap_or(f64::NAN);
    paybacks.sort_by(f64::total_cmp);
    let pays_in_one = paybacks.iter().filter(|&&p| p < 1.0).count();
    let payback_median = paybacks
        .get(paybacks.len() / 2)
        .copied()
        .unwrap_or(f64::NAN);
    let payback_worst = paybacks.last().copied().unwrap_or(f64::NAN);
    let fig = Figure {
        title: "The chooser's plan against the cheapest plan that meets the tolerance".into(),
        x_label: "scene (mu x spin-up x time constant; see the CSV)".into(),
        y_label: "cost of the chosen plan / cost of the cheapest (host ns, measured table)".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
        series,
        hlines: Vec::new(),
        vlines: Vec::new(),
        notes: vec![
            format!("{n} scenes: worst ratio {worst:.2}, tolerance missed {misses} times"),
            format!(
                "within 1.25x: {within} of {n}; of the dependable cheapest: {within_dependable}"
            ),
            format!("worst against the dependable cheapest: {worst_dependable:.2}"),
            "1 = the chooser found the cheapest plan".into(),
            "(the dependable cheapest, every finer setting".into(),
            "meeting the tolerance too, is in the CSV)".into(),
            "brute force: every method, steps 2^(1/4)".into(),
            "and DP5(4) tolerances 10^(1/4) apart".into(),
        ],
    };
    let cost = Figure {
        title: "What choosing costs against what it saves".into(),
        x_label: "scene (mu x spin-up x time constant; see the CSV)".into(),
        y_label: "time to choose / time saved a run (host, best of 7)".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Log,
        series: cost_series,
        hlines: Vec::new(),
        vlines: Vec::new(),
        notes: vec![
            "saved: DP5(4) at a tenth of the tolerance".into(),
            "(not choosing) less the chosen plan".into(),
            format!("below 1 (pays in one run): {pays_in_one} of {n}"),
            format!("runs to pay: median {payback_median:.2}, worst {payback_worst:.2}"),
            format!("choosing / plan: median {choosing_median:.1}x, worst {choosing_worst:.1}x"),
            format!("from the error table: {from_table} of {n} (no run);"),
            "elsewhere the RK4 pilot at h, h/2, h/4, h/8".into(),
            "and the flat model at h and h/2".into(),
        ],
    };
    super::say(&format!(
        "chooser: {n} scenes, worst cost ratio {worst:.3} ({within} within 1.25x), against the \
         dependable cheapest {worst_dependable:.3} ({within_dependable} within 1.25x), tolerance \
         missed {misses} times; choosing took {choosing_median:.1}x the plan's time (median), \
         {choosing_worst:.1}x worst; it paid for itself in one run on {pays_in_one} of {n} \
         scenes against DP5(4) at a tenth of the tolerance (runs to pay: median \
         {payback_median:.2}, worst {payback_worst:.2}); {from_table} of {n} chosen from the \
         error table"
    ));
    Ok((fig, cost, table))
}
