//! Cost points for the work-precision chart (`bowl chart work-precision`): the instructions each
//! method executes on the Cortex-M4F for each of the chart's named scenes.
//!
//! The model's own benchmarks (`particle.rs`) report the worst case over a grid against the
//! instruction budgets; the chart needs one point per (scene, model, method, setting) instead. The
//! names are `cost::SCENE::MODEL::METHOD`; `bowl chart work-precision --qemu-log FILE` reads them
//! back by that name from the QEMU run's output. The scenes are defined here once and used by the
//! chart too, so the host and the target measure the same inputs.

use crate::check::Bench;
use model_core::ode;
use model_core::particle::{self, Model, Scene, residence};
use model_core::real::micro::{MicroF32, MicroF32HwSqrt};

// The chart's named scenes are the model's (`bowl chart work-precision` draws them too): one
// definition, in model-core, measured here on the target.
pub use model_core::particle::named_scenes::{
    NEAR_RIM_E, NEAR_THRESHOLD_D, SCENE_NAMES, scene, scene_f32,
};

const fn model(coriolis: bool) -> Model {
    if coriolis {
        Model::Coriolis
    } else {
        Model::Flat
    }
}

/// The f32 scenes, rounded at compile time: the M4F has no f64 unit, so building them inside
/// the measured call would add hundreds of soft-float instructions that are not the method's.
static SCENES_F32: [Scene<f32>; 3] = [scene_f32(0), scene_f32(1), scene_f32(2)];

/// Closed-form residence time in f32 with libm (the model's `Real for f32`).
fn closed_f32<const S: usize, const CORIOLIS: bool>(_: usize) -> f32 {
    // black_box: the scene is a compile-time constant and must not be folded into the call.
    let s = core::hint::black_box(&SCENES_F32[S]);
    match residence(s, model(CORIOLIS)) {
        Ok(o) => o.residence_time_s(),
        Err(_) => f32::NAN,
    }
}

/// The f32 scenes in one of micromath's newtypes (same values), at compile time.
macro_rules! micro_scenes {
    ($t:ident) => {{
        let mut out = [Scene {
            omega_rad_s: $t(0.0),
            mu: $t(0.0),
            g_m_s2: $t(0.0),
            k2: $t(0.0),
            ri_m: $t(0.0),
            rim_radius_m: $t(0.0),
        }; 3];
        let mut i = 0;
        while i < 3 {
            let s = &SCENES_F32[i];
            out[i] = Scene {
                omega_rad_s: $t(s.omega_rad_s),
                mu: $t(s.mu),
                g_m_s2: $t(s.g_m_s2),
                k2: $t(s.k2),
                ri_m: $t(s.ri_m),
                rim_radius_m: $t(s.rim_radius_m),
            };
            i += 1;
        }
        out
    }};
}

static SCENES_MICRO: [Scene<MicroF32>; 3] = micro_scenes!(MicroF32);
static SCENES_MICRO_HW: [Scene<MicroF32HwSqrt>; 3] = micro_scenes!(MicroF32HwSqrt);

/// Closed-form residence time with micromath (its own rough sqrt).
fn closed_micro<const S: usize, const CORIOLIS: bool>(_: usize) -> f32 {
    let s = core::hint::black_box(&SCENES_MICRO[S]);
    match residence(s, model(CORIOLIS)) {
        Ok(o) => o.residence_time_s().0,
        Err(_) => f32::NAN,
    }
}

/// Closed-form residence time with micromath and the correctly rounded (VSQRT) square root.
fn closed_micro_hw<const S: usize, const CORIOLIS: bool>(_: usize) -> f32 {
    let s = core::hint::black_box(&SCENES_MICRO_HW[S]);
    match residence(s, model(CORIOLIS)) {
        Ok(o) => o.residence_time_s().0,
        Err(_) => f32::NAN,
    }
}

/// The closed-form benches of one scene: libm, micromath, micromath with VSQRT; both models.
macro_rules! closed {
    ($s:literal, $name:literal) => {
        [
            Bench {
                name: concat!("cost::", $name, "::flat::closed-f32-micromath"),
                inputs: 1,
                run: closed_micro::<$s, false>,
                budget_instructions: None,
            },
            Bench {
                name: concat!("cost::", $name, "::coriolis::closed-f32-micromath"),
                inputs: 1,
                run: closed_micro::<$s, true>,
                budget_instructions: None,
            },
            Bench {
                name: concat!("cost::", $name, "::flat::closed-f32-micromath-hwsqrt"),
                inputs: 1,
                run: closed_micro_hw::<$s, false>,
                budget_instructions: None,
            },
            Bench {
                name: concat!("cost::", $name, "::coriolis::closed-f32-micromath-hwsqrt"),
                inputs: 1,
                run: closed_micro_hw::<$s, true>,
                budget_instructions: None,
            },
            Bench {
                name: concat!("cost::", $name, "::flat::closed-f32-libm"),
                inputs: 1,
                run: closed_f32::<$s, false>,
                budget_instructions: None,
            },
            Bench {
                name: concat!("cost::", $name, "::coriolis::closed-f32-libm"),
                inputs: 1,
                run: closed_f32::<$s, true>,
                budget_instructions: None,
            },
        ]
    };
}

static CLOSED: [[Bench; 6]; 3] = [
    closed!(0, "paper"),
    closed!(1, "near-threshold"),
    closed!(2, "near-rim"),
];

/// Benchmarks of this module.
pub static BENCHES: &[Bench] = CLOSED.as_flattened();

/// The integrators' settings measured on the target (paper scene): `(family, h omega or tol)`.
/// Family 0 Euler, 1 semi-implicit Euler, 2 RK4, 3 DP5(4).
const ODE_SETTINGS: [(u8, f64); 14] = [
    (0, 0.125),
    (0, 0.03125),
    (1, 0.125),
    (1, 0.03125),
    (2, 1.0),
    (2, 0.5),
    (2, 0.25),
    (2, 0.125),
    (2, 0.0625),
    (3, 1e-2),
    (3, 1e-3),
    (3, 1e-4),
    (3, 1e-5),
    (3, 1e-6),
];

/// The f32 ODE method of setting `i` on scene `s`, exactly as the chart builds it on the host:
/// step `(h omega as f32) / omega`, DP5(4) `rtol = tol`, `atol = tol R`.
const fn ode_method(i: usize, s: &Scene<f32>) -> ode::Method<f32> {
    let (family, x) = ODE_SETTINGS[i];
    let x = x as f32;
    let h = x / s.omega_rad_s;
    match family {
        0 => ode::Method::Euler { step_s: h },
        1 => ode::Method::SemiImplicitEuler { step_s: h },
        2 => ode::Method::Rk4 { step_s: h },
        _ => ode::Method::Dp54 {
            rtol: x,
            atol: x * s.rim_radius_m,
        },
    }
}

/// The methods, built at compile time (no division in the measured call).
static ODE_METHODS: [ode::Method<f32>; 14] = {
    let mut m = [ode::Method::Euler { step_s: 0.0 }; 14];
    let mut i = 0;
    while i < 14 {
        m[i] = ode_method(i, &SCENES_F32[0]);
        i += 1;
    }
    m
};

/// Residence time by integrator `M` on the paper scene in f32.
fn ode_f32<const CORIOLIS: bool, const M: usize>(_: usize) -> f32 {
    let s = core::hint::black_box(&SCENES_F32[0]);
    let m = core::hint::black_box(ODE_METHODS[M]);
    match particle::integrate_constant(s, model(CORIOLIS), m) {
        Ok(ode::Report {
            outcome: ode::OdeOutcome::Leaves {
                residence_time_s, ..
            },
            ..
        }) => residence_time_s,
        _ => f32::NAN,
    }
}

/// One integrator bench per model for setting `$m` named `$key` (the chart's method key).
macro_rules! ode {
    ($m:literal, $key:literal) => {
        [
            Bench {
                name: concat!("cost::paper::flat::", $key),
                inputs: 1,
                run: ode_f32::<false, $m>,
                budget_instructions: None,
            },
            Bench {
                name: concat!("cost::paper::coriolis::", $key),
                inputs: 1,
                run: ode_f32::<true, $m>,
                budget_instructions: None,
            },
        ]
    };
}

static ODE: [[Bench; 2]; 14] = [
    ode!(0, "euler-f32-libm-h0.125"),
    ode!(1, "euler-f32-libm-h0.03125"),
    ode!(2, "semi-implicit-euler-f32-libm-h0.125"),
    ode!(3, "semi-implicit-euler-f32-libm-h0.03125"),
    ode!(4, "rk4-f32-libm-h1"),
    ode!(5, "rk4-f32-libm-h0.5"),
    ode!(6, "rk4-f32-libm-h0.25"),
    ode!(7, "rk4-f32-libm-h0.125"),
    ode!(8, "rk4-f32-libm-h0.0625"),
    ode!(9, "dp54-f32-libm-tol1e-2"),
    ode!(10, "dp54-f32-libm-tol1e-3"),
    ode!(11, "dp54-f32-libm-tol1e-4"),
    ode!(12, "dp54-f32-libm-tol1e-5"),
    ode!(13, "dp54-f32-libm-tol1e-6"),
];

/// Integrator benchmarks of this module.
pub static ODE_BENCHES: &[Bench] = ODE.as_flattened();

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bench_names_match_the_scene_names() {
        for (i, pair) in CLOSED.iter().enumerate() {
            for b in pair {
                let rest = b
                    .name
                    .strip_prefix("cost::")
                    .and_then(|r| r.strip_prefix(SCENE_NAMES[i]));
                assert!(rest.is_some_and(|r| r.starts_with("::")), "{}", b.name);
            }
        }
    }
}
