//! The chooser on a logged speed trace (`trace.rs`): its plans against independent
//! integrations, its refusals, the trace's mean speed and measurement, and the first estimate
//! of T.

use super::tests::{closed_form, scene};
use super::*;
extern crate std;

/// `(t, omega(t))` sampled every 20 ms (the console's 50 Hz log) for 3 s.
fn sampled(omega: impl Fn(f64) -> f64) -> ([f64; 150], [f64; 150]) {
    let times: [f64; 150] = core::array::from_fn(|i| i as f64 * 0.02);
    (times, times.map(omega))
}

#[test]
fn a_steady_trace_is_answered_by_the_closed_form_at_its_mean_speed() {
    let s = scene(3.0, 0.029, 0.05);
    // 0.5 % ripple at 7 Hz around 3 rad/s: a settled speed loop.
    let (ts, ws) = sampled(|t| 3.0 * (1.0 + 0.005 * (7.0 * core::f64::consts::TAU * t).sin()));
    let trace = SampledOmega::new(&ts, &ws).unwrap();
    let c = choose_trace(&s, &Need::Tolerance(1e-3), &trace).unwrap();
    let Plan::ClosedFormAtMeanSpeed { omega_rad_s } = c.plan else {
        panic!("{c:?}")
    };
    // Independently: the tight integration over the trace, and the closed form at the mean
    // speed over [0, T] by the trapezoid rule on the samples themselves.
    let limits = Limits::for_scene(&s, &trace);
    let truth = run(&s, c.model, &trace, dp(1e-12, &s), limits).unwrap().0;
    let n = ts.iter().filter(|&&t| t <= truth).count();
    let mut area = 0.0;
    for i in 1..n {
        area += 0.5 * (ws[i] + ws[i - 1]) * (ts[i] - ts[i - 1]);
    }
    // The last piece, from the last sample before T to T.
    let w_end = ws[n - 1] + (ws[n] - ws[n - 1]) * (truth - ts[n - 1]) / (ts[n] - ts[n - 1]);
    area += 0.5 * (ws[n - 1] + w_end) * (truth - ts[n - 1]);
    let mean = area / truth;
    assert!(
        (omega_rad_s - mean).abs() < 1e-4 * mean,
        "{omega_rad_s} vs {mean}"
    );
    let t_mean = closed_form(
        &Scene {
            omega_rad_s: mean,
            ..s
        },
        c.model,
    );
    let err = (t_mean - truth).abs() / truth;
    assert!(err <= c.tolerance_rel, "{c:?}: error {err:e}");
    assert!(
        (err - c.estimated_error_rel).abs() < 1e-6,
        "{c:?}: error {err:e}"
    );
    assert_eq!(c.rhs_evaluations, 0);
}

#[test]
fn a_spin_up_trace_needs_an_integrator_that_meets_the_tolerance() {
    let s = scene(3.0, 0.029, 0.05);
    let (ts, ws) = sampled(|t| 3.0 + (0.5 - 3.0) * (-t / 0.3).exp());
    let trace = SampledOmega::new(&ts, &ws).unwrap();
    let c = choose_trace(&s, &Need::Tolerance(1e-4), &trace).unwrap();
    let Plan::Integrate(method) = c.plan else {
        panic!("{c:?}")
    };
    let limits = Limits::for_scene(&s, &trace);
    let truth = run(&s, c.model, &trace, dp(1e-12, &s), limits).unwrap().0;
    let (t, _) = run(&s, c.model, &trace, method, limits).unwrap();
    assert!((t - truth).abs() <= 1e-4 * truth, "{c:?}: {t} vs {truth}");
    // The pilot's finer run answers within the tolerance too, without running the plan again.
    let answer = c.answer_s.unwrap();
    assert!(
        (answer - truth).abs() <= 1e-4 * truth,
        "{answer} vs plan {t}, truth {truth}"
    );
    // The closed form at the mean speed would miss: that is why it was not chosen.
    let mean = mean_omega_rad_s(&trace, truth);
    let t_mean = closed_form(
        &Scene {
            omega_rad_s: mean,
            ..s
        },
        c.model,
    );
    assert!((t_mean - truth).abs() > 1e-4 * truth, "{t_mean} vs {truth}");
}

#[test]
fn bad_traces_name_the_sample() {
    assert_eq!(SampledOmega::<f64>::new(&[], &[]), Err(TraceError::Empty));
    assert_eq!(
        SampledOmega::new(&[0.0, 0.02, 0.02], &[1.0, 1.0, 1.0]),
        Err(TraceError::TimeNotIncreasing { index: 2 })
    );
    assert_eq!(
        SampledOmega::new(&[0.0, 0.02], &[1.0, -0.1]),
        Err(TraceError::BadSpeed { index: 1 })
    );
    assert_eq!(
        choose_trace(
            &scene(3.0, 0.029, 0.05),
            &Need::Tolerance(0.0),
            &ConstantOmegaTrace
        ),
        Err(ChooseError::InvalidKnowledge)
    );
}

/// A constant speed as a profile (the trace tests' invalid-tolerance case).
struct ConstantOmegaTrace;

impl crate::ode::OmegaProfile<f64> for ConstantOmegaTrace {
    fn omega_rad_s(&self, _t_s: f64) -> f64 {
        3.0
    }
    fn max_omega_rad_s(&self) -> f64 {
        3.0
    }
}

#[test]
fn the_mean_of_a_ramp_is_its_midpoint() {
    let ts = [0.0, 1.0];
    let ws = [1.0, 3.0];
    let trace = SampledOmega::new(&ts, &ws).unwrap();
    assert!((mean_omega_rad_s(&trace, 1.0) - 2.0).abs() < 1e-12);
    // Held after the last sample: over [0, 2] the mean is (2 + 3) / 2.
    assert!((mean_omega_rad_s(&trace, 2.0) - 2.5).abs() < 1e-6);
}

/// A trace's own measurement: a ramp has no scatter, independent noise of a known RMS reads
/// as that RMS (deterministic noise, 150 samples: the estimate lands within 10 %), the window
/// leaves out what came after it, and the relative uncertainty is (rounding + scatter) / mean.
#[test]
fn a_traces_measurement_uncertainty_is_its_rounding_and_scatter() {
    let (ts, ramp) = sampled(|t| 1.0 + 0.5 * t);
    let trace = SampledOmega::new(&ts, &ramp).unwrap();
    let m = trace.measurement(1e-3, f64::INFINITY);
    assert!(m.scatter_rad_s < 1e-12, "{m:?}");
    assert!(
        (m.mean_rad_s - (1.0 + 0.5 * ts[149] / 2.0)).abs() < 1e-12,
        "{m:?}"
    );
    assert!((m.relative - 0.5e-3 / m.mean_rad_s).abs() < 1e-15, "{m:?}");
    // Noise uniform in +-a: RMS a / sqrt(3).
    let a = 0.03;
    let mut uniform = crate::particle::tests::uniform_stream(12345);
    let (_, mut noisy) = sampled(|_| 3.0);
    for w in noisy.iter_mut() {
        *w += a * (2.0 * uniform() - 1.0);
    }
    let trace = SampledOmega::new(&ts, &noisy).unwrap();
    let m = trace.measurement(1e-3, f64::INFINITY);
    let rms = a / 3f64.sqrt();
    assert!((m.scatter_rad_s - rms).abs() <= 0.1 * rms, "{m:?} vs {rms}");
    let want = (0.5e-3 + m.scatter_rad_s) / m.mean_rad_s;
    assert!((m.relative - want).abs() < 1e-15, "{m:?}");
    // A quiet first second, then the noise: judged over that second, no scatter.
    let mut joined = noisy;
    joined[..51].fill(3.0);
    let trace = SampledOmega::new(&ts, &joined).unwrap();
    assert!(trace.measurement(1e-3, 1.0).scatter_rad_s < 1e-12);
    assert!(trace.measurement(1e-3, f64::INFINITY).scatter_rad_s > 0.5 * rms);
    // A speed at rest: the uncertainty is total, not a division by zero.
    let (_, rest) = sampled(|_| 0.0);
    let trace = SampledOmega::new(&ts, &rest).unwrap();
    assert_eq!(trace.measurement(1e-3, f64::INFINITY).relative, 1.0);
}

/// The first estimate of T on a trace: the flat closed form at the mean speed over itself. On
/// a constant speed it is the closed form; on a spin-up it lies between the closed forms at
/// the start and final speeds.
#[test]
fn the_first_estimate_of_t_is_a_closed_form_at_a_mean_speed() {
    let s = scene(3.0, 0.029, 0.05);
    let flat = |w: f64| {
        particle::residence(
            &Scene {
                omega_rad_s: w,
                ..s
            },
            Model::Flat,
        )
        .unwrap()
        .residence_time_s()
    };
    let (ts, steady) = sampled(|_| 3.0);
    let trace = SampledOmega::new(&ts, &steady).unwrap();
    let t = residence_estimate_s(&s, &trace).unwrap();
    assert!((t - flat(3.0)).abs() < 1e-12 * t, "{t}");
    let (ts, rise) = sampled(|t| 3.0 + (1.5 - 3.0) * (-t / 0.3).exp());
    let trace = SampledOmega::new(&ts, &rise).unwrap();
    let t = residence_estimate_s(&s, &trace).unwrap();
    assert!(t > flat(3.0) && t < flat(1.5), "{t}");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]
    /// Any valid trace, f64 and f32: the measurement is finite with its relative part in
    /// [0, 1], and the first estimate of T is finite and positive where there is one.
    #[test]
    fn a_traces_measurement_never_panics_or_is_nan(
        gaps in proptest::collection::vec(1e-6f64..10.0, 1..40),
        speeds in proptest::collection::vec(0.0f64..1e4, 40),
        until in 0.0f64..1e3,
        resolution in 0.0f64..1.0,
        mu in 0.0f64..1.0,
        ri in 0.0f64..0.2,
    ) {
        let mut times = std::vec![0.0];
        for g in &gaps {
            let next = times[times.len() - 1] + g;
            times.push(next);
        }
        let ws = &speeds[..times.len()];
        let trace = SampledOmega::new(&times, ws).unwrap();
        let m = trace.measurement(resolution, until);
        proptest::prop_assert!(m.relative >= 0.0 && m.relative <= 1.0, "{m:?}");
        proptest::prop_assert!(m.scatter_rad_s.is_finite() && m.mean_rad_s.is_finite(), "{m:?}");
        if let Some(t) = residence_estimate_s(&scene(1.0, mu, ri), &trace) {
            proptest::prop_assert!(t.is_finite() && t >= 0.0, "{t}");
        }
        let t32: std::vec::Vec<f32> = times.iter().map(|&t| t as f32).collect();
        let w32: std::vec::Vec<f32> = ws.iter().map(|&w| w as f32).collect();
        if let Ok(trace) = SampledOmega::new(&t32, &w32) {
            let m = trace.measurement(resolution as f32, until as f32);
            proptest::prop_assert!(m.relative >= 0.0 && m.relative <= 1.0, "{m:?}");
            proptest::prop_assert!(m.scatter_rad_s.is_finite(), "{m:?}");
        }
    }
}
