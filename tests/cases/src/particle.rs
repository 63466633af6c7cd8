//! Cases for the particle model (paper Eq. 5 to 12, corrected per docs/model.md) in `f32`, each
//! against an `f64` reference computed here from an independent formula, and the benchmarks of
//! the target path (residence time flat / Coriolis, the inverse) with their instruction budgets.

use crate::check::{Bench, Case, Failure, close, ensure};
use model_core::Real;
use model_core::particle::{
    self, InverseError, Model, Outcome, Scene, omega_for_residence_time, radial_velocity_m_s,
    residence, residence_time_s,
};
use model_core::real::micro::{MicroF32, MicroF32HwSqrt};

/// Cases of this module.
pub static CASES: &[Case] = &[
    Case {
        name: "particle::flat_time_f32_vs_f64_acosh",
        run: flat_time_vs_acosh,
    },
    Case {
        name: "particle::coriolis_time_f32_vs_f64_bisection",
        run: coriolis_time_vs_bisection,
    },
    Case {
        name: "particle::coriolis_time_f64_vs_bisection",
        run: coriolis_time_f64_vs_bisection,
    },
    Case {
        name: "particle::inverse_f32_round_trips_through_f64",
        run: inverse_round_trips,
    },
    Case {
        name: "particle::explicit_outcomes_f32",
        run: explicit_outcomes,
    },
    Case {
        name: "particle::near_threshold_is_flagged_f32",
        run: near_threshold_flagged,
    },
    Case {
        name: "particle::time_alone_is_the_full_forms_time_f32",
        run: time_alone_is_the_full_forms_time,
    },
];

/// Benchmarks of this module (instruction budgets: worst case over the grid).
pub static BENCHES: &[Bench] = &[
    Bench {
        name: "particle::residence_flat_f32",
        inputs: GRID,
        run: bench_flat,
        budget_instructions: Some(250),
    },
    // The time alone: what the rig's telemetry computes every frame.
    Bench {
        name: "particle::residence_time_flat_f32",
        inputs: GRID,
        run: bench_time_flat,
        budget_instructions: Some(150),
    },
    Bench {
        name: "particle::residence_time_coriolis_f32",
        inputs: GRID,
        run: bench_time_coriolis,
        budget_instructions: Some(600),
    },
    Bench {
        name: "particle::residence_coriolis_f32",
        inputs: GRID,
        run: bench_coriolis,
        budget_instructions: Some(600),
    },
    Bench {
        name: "particle::omega_for_residence_time_coriolis_f32",
        inputs: GRID,
        run: bench_inverse,
        budget_instructions: Some(1500),
    },
    Bench {
        name: "particle::omega_for_residence_time_flat_f32",
        inputs: GRID,
        run: bench_inverse_flat,
        budget_instructions: Some(1500),
    },
    // The same paths with micromath's functions (for the chart; no budget).
    Bench {
        name: "particle::residence_flat_micromath_hwsqrt_f32",
        inputs: GRID,
        run: |i| micro_time::<MicroF32HwSqrt>(i, Model::Flat),
        budget_instructions: None,
    },
    Bench {
        name: "particle::residence_coriolis_micromath_hwsqrt_f32",
        inputs: GRID,
        run: |i| micro_time::<MicroF32HwSqrt>(i, Model::Coriolis),
        budget_instructions: None,
    },
    Bench {
        name: "particle::residence_flat_micromath_f32",
        inputs: GRID,
        run: |i| micro_time::<MicroF32>(i, Model::Flat),
        budget_instructions: None,
    },
    Bench {
        name: "particle::residence_coriolis_micromath_f32",
        inputs: GRID,
        run: |i| micro_time::<MicroF32>(i, Model::Coriolis),
        budget_instructions: None,
    },
];

/// The bench grid's scene in a micromath newtype.
fn micro_time<T: Real + Into32>(i: usize, model: Model) -> f32 {
    let s = scene_f32(i);
    let m = Scene {
        omega_rad_s: T::from_f64(s.omega_rad_s as f64),
        mu: T::from_f64(s.mu as f64),
        g_m_s2: T::from_f64(s.g_m_s2 as f64),
        k2: T::from_f64(s.k2 as f64),
        ri_m: T::from_f64(s.ri_m as f64),
        rim_radius_m: T::from_f64(s.rim_radius_m as f64),
    };
    residence(&m, model)
        .map(|o| o.residence_time_s().into_f32())
        .unwrap_or(f32::NAN)
}

/// Back to a plain f32 (the harness wants one).
trait Into32 {
    fn into_f32(self) -> f32;
}
impl Into32 for MicroF32 {
    fn into_f32(self) -> f32 {
        self.0
    }
}
impl Into32 for MicroF32HwSqrt {
    fn into_f32(self) -> f32 {
        self.0
    }
}

const OMEGAS: [f64; 4] = [2.5, 3.0, 3.6, 5.0];
const MUS: [f64; 3] = [0.0, 0.01, 0.029];
const RIS: [f64; 4] = [0.05, 0.07, 0.09, 0.0999];
const GRID: usize = 48;
const RIM: f64 = 0.1;
const G: f64 = 9.81;
const K2: f64 = 5.0 / 7.0;

fn scene_f64(i: usize) -> Scene<f64> {
    Scene {
        omega_rad_s: OMEGAS[i % 4],
        mu: MUS[(i / 4) % 3],
        g_m_s2: G,
        k2: K2,
        ri_m: RIS[(i / 12) % 4],
        rim_radius_m: RIM,
    }
}

fn err(what: &'static str) -> Failure {
    Failure {
        what,
        got: 0.0,
        want: 1.0,
        tolerance: 0.0,
    }
}

fn leaves_f32(o: Result<Outcome<f32>, particle::SceneError>) -> Result<(f32, f32, f32), Failure> {
    match o {
        Ok(Outcome::Leaves {
            residence_time_s,
            exit_radial_velocity_m_s,
            condition_number,
            ..
        }) => Ok((residence_time_s, exit_radial_velocity_m_s, condition_number)),
        _ => Err(err("expected the particle to leave")),
    }
}

fn a_of(s: &Scene<f64>) -> f64 {
    s.mu * s.g_m_s2 / (s.omega_rad_s * s.omega_rad_s)
}

/// Reference flat time, the textbook form `acosh((R - a)/(ri - a)) / (k omega)` in f64 (fine in
/// f64 away from the rim; the grid's closest start, 0.1 mm from the rim, still keeps 12 digits).
fn flat_ref(s: &Scene<f64>) -> f64 {
    let a = a_of(s);
    libm::acosh((s.rim_radius_m - a) / (s.ri_m - a)) / (libm::sqrt(s.k2) * s.omega_rad_s)
}

/// Reference Coriolis time: bisection on the corrected solution of docs/model.md section 3
/// `a + (ri - a)(A e^{l1 t} + B e^{l2 t}) = R`, coefficients straight from the notes.
fn coriolis_ref(s: &Scene<f64>) -> f64 {
    let k = libm::sqrt(s.k2);
    let root = libm::sqrt(1.0 + s.k2 * s.mu * s.mu);
    let (w, a) = (s.omega_rad_s, a_of(s));
    let l1 = k * w / (root + k * s.mu);
    let l2 = -k * w * (root + k * s.mu);
    let ca = (1.0 + k * s.mu / root) / 2.0;
    let cb = (1.0 - k * s.mu / root) / 2.0;
    let r = |t: f64| a + (s.ri_m - a) * (ca * libm::exp(l1 * t) + cb * libm::exp(l2 * t));
    let (mut lo, mut hi) = (0.0, 1.0);
    while r(hi) < s.rim_radius_m && hi < 1e6 {
        hi *= 2.0;
    }
    for _ in 0..120 {
        let mid = 0.5 * (lo + hi);
        if r(mid) < s.rim_radius_m {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

/// f32 target: within 2e-6 times the condition number (docs/model.md, "Speed against accuracy").
const F32_TOL: f64 = 2e-6;

fn flat_time_vs_acosh() -> Result<(), Failure> {
    for i in 0..GRID {
        let s = scene_f64(i).to_f32();
        let (t, v, c) = leaves_f32(residence(&s, Model::Flat))?;
        let w = s.to_f64();
        let want = flat_ref(&w);
        close(
            "flat T f32 vs f64 acosh (rel)",
            t as f64 / want,
            1.0,
            F32_TOL * c as f64,
        )?;
        // Energy: r'(T)^2 = k2 omega^2 ((R - a)^2 - (ri - a)^2).
        let a = a_of(&w);
        let v_want = libm::sqrt(
            w.k2 * w.omega_rad_s
                * w.omega_rad_s
                * ((w.rim_radius_m - a) * (w.rim_radius_m - a) - (w.ri_m - a) * (w.ri_m - a)),
        );
        close(
            "flat exit velocity vs energy (rel)",
            v as f64 / v_want,
            1.0,
            F32_TOL * c as f64,
        )?;
    }
    Ok(())
}

/// f64 (the host's precision) against the same bisection, with the trajectory's speed at `T`
/// (paper Eq. 11) as the exit speed and the Coriolis friction slowing the particle.
fn coriolis_time_f64_vs_bisection() -> Result<(), Failure> {
    for (w, mu, ri) in [
        (3.0, 0.029, 0.05),
        (1.8, 0.01, 0.04),
        (3.6, 0.05, 0.09),
        (3.6, 0.0, 0.05),
    ] {
        let s = Scene {
            omega_rad_s: w,
            mu,
            ri_m: ri,
            rim_radius_m: 0.1,
            ..Scene::<f64>::default()
        };
        let leaves = |model| match residence(&s, model) {
            Ok(Outcome::Leaves {
                residence_time_s,
                exit_radial_velocity_m_s,
                ..
            }) => Ok((residence_time_s, exit_radial_velocity_m_s)),
            _ => ensure("the f64 scene leaves", false).map(|()| (0.0, 0.0)),
        };
        let (t, v) = leaves(Model::Coriolis)?;
        close(
            "Coriolis T f64 vs bisection (rel)",
            t / coriolis_ref(&s),
            1.0,
            1e-13,
        )?;
        let (tf, _) = leaves(Model::Flat)?;
        if mu > 0.0 {
            ensure("Coriolis friction slows the particle", t > tf)?;
        } else {
            close("Coriolis T at mu = 0 vs flat (rel)", t / tf, 1.0, 1e-14)?;
        }
        let v_traj = radial_velocity_m_s(&s, Model::Coriolis, t).unwrap_or(f64::NAN);
        close(
            "Coriolis r'(T) vs the trajectory's (rel)",
            v / v_traj,
            1.0,
            1e-12,
        )?;
    }
    Ok(())
}

fn coriolis_time_vs_bisection() -> Result<(), Failure> {
    for i in 0..GRID {
        let s = scene_f64(i).to_f32();
        let (t, _, c) = leaves_f32(residence(&s, Model::Coriolis))?;
        let want = coriolis_ref(&s.to_f64());
        close(
            "Coriolis T f32 vs f64 bisection (rel)",
            t as f64 / want,
            1.0,
            F32_TOL * c as f64,
        )?;
        if s.mu > 0.0 {
            let tf = flat_ref(&s.to_f64());
            ensure("Coriolis slower than flat", want > tf)?;
        }
    }
    Ok(())
}

fn inverse_round_trips() -> Result<(), Failure> {
    for i in 0..GRID {
        let s64 = scene_f64(i);
        for (model, reference) in [
            (Model::Flat, flat_ref as fn(&Scene<f64>) -> f64),
            (Model::Coriolis, coriolis_ref),
        ] {
            let target = reference(&s64) as f32;
            let s = s64.to_f32();
            let w =
                omega_for_residence_time(&s, model, target).map_err(|_| err("inverse errored"))?;
            let back = reference(&Scene {
                omega_rad_s: w as f64,
                ..s.to_f64()
            });
            let (_, _, c) = leaves_f32(residence(
                &Scene {
                    omega_rad_s: w,
                    ..s
                },
                model,
            ))?;
            close(
                "T(omega(target)) (rel)",
                back / target as f64,
                1.0,
                F32_TOL * c as f64,
            )?;
        }
    }
    Ok(())
}

fn explicit_outcomes() -> Result<(), Failure> {
    // The paper's literal mu = 0.4: a = 0.30 m at 3.6 rad/s, larger than the bowl.
    let literal = Scene {
        mu: 0.4f32,
        omega_rad_s: 3.6,
        ..Scene::default()
    };
    ensure(
        "mu 0.4 never leaves",
        matches!(
            residence(&literal, Model::Coriolis),
            Ok(Outcome::NeverLeaves {
                near_threshold: false,
                ..
            })
        ),
    )?;
    let at_rim = Scene {
        ri_m: 0.1f32,
        ..Scene::default()
    };
    ensure(
        "ri = R is at the rim with speed omega R",
        residence(&at_rim, Model::Flat)
            == Ok(Outcome::AlreadyAtRim {
                exit_total_velocity_m_s: 0.3,
            }),
    )?;
    ensure(
        "NaN omega is an error",
        residence(
            &Scene {
                omega_rad_s: f32::NAN,
                ..Scene::default()
            },
            Model::Flat,
        ) == Err(particle::SceneError::InvalidOmega),
    )?;
    ensure(
        "inverse at the rim is an error",
        omega_for_residence_time(&at_rim, Model::Flat, 1.0) == Err(InverseError::AlreadyAtRim),
    )
}

fn near_threshold_flagged() -> Result<(), Failure> {
    // ri = a (1 + d): d = 1e-8 is below f32 resolution; the verdict must carry the flag, and
    // d = 1e-3 must leave with a large condition number that the flag reports.
    let base = Scene::<f32>::default();
    let a = base.equilibrium_radius_m();
    let tiny = Scene {
        ri_m: a * (1.0 + 1e-8),
        ..base
    };
    let flagged = match residence(&tiny, Model::Flat) {
        Ok(Outcome::NeverLeaves { near_threshold, .. }) => near_threshold,
        Ok(Outcome::Leaves {
            ill_conditioned, ..
        }) => ill_conditioned,
        _ => false,
    };
    ensure("d = 1e-8 flagged in f32", flagged)?;
    let small = Scene {
        ri_m: a * (1.0 + 1e-4),
        ..base
    };
    let (t, _, c) = leaves_f32(residence(&small, Model::Coriolis))?;
    ensure(
        "d = 1e-4: condition above 300 (about 1/(d ln x))",
        c > 300.0,
    )?;
    let want = coriolis_ref(&small.to_f64());
    close(
        "near-threshold T within condition (rel)",
        t as f64 / want,
        1.0,
        F32_TOL * c as f64,
    )
}

/// The benchmark grid in f32, laid out at compile time: f64 arithmetic and index arithmetic
/// would otherwise swamp the count (f64 is software on the Cortex-M4F).
static BENCH_SCENES: [Scene<f32>; GRID] = {
    const W: [f32; 4] = [2.5, 3.0, 3.6, 5.0];
    const MU: [f32; 3] = [0.0, 0.01, 0.029];
    const RI: [f32; 4] = [0.05, 0.07, 0.09, 0.0999];
    let mut out = [Scene {
        omega_rad_s: 0.0,
        mu: 0.0,
        g_m_s2: 9.81,
        k2: 5.0 / 7.0,
        ri_m: 0.0,
        rim_radius_m: 0.1,
    }; GRID];
    let mut i = 0;
    while i < GRID {
        out[i].omega_rad_s = W[i % 4];
        out[i].mu = MU[(i / 4) % 3];
        out[i].ri_m = RI[(i / 12) % 4];
        i += 1;
    }
    out
};

fn scene_f32(i: usize) -> &'static Scene<f32> {
    &BENCH_SCENES[i % GRID]
}

fn bench_flat(i: usize) -> f32 {
    residence(scene_f32(i), Model::Flat)
        .map(|o| o.residence_time_s())
        .unwrap_or(f32::NAN)
}

fn bench_time_flat(i: usize) -> f32 {
    residence_time_s(scene_f32(i), Model::Flat).unwrap_or(f32::NAN)
}

fn bench_time_coriolis(i: usize) -> f32 {
    residence_time_s(scene_f32(i), Model::Coriolis).unwrap_or(f32::NAN)
}

/// On the target too, over the bench grid: the time alone is the full outcome's, bit for bit.
fn time_alone_is_the_full_forms_time() -> Result<(), Failure> {
    for i in 0..GRID {
        for model in [Model::Flat, Model::Coriolis] {
            let full = residence(scene_f32(i), model).map(|o| o.residence_time_s().to_bits());
            let alone = residence_time_s(scene_f32(i), model).map(f32::to_bits);
            ensure(
                "residence_time_s == residence(..).residence_time_s()",
                full == alone,
            )?;
        }
    }
    Ok(())
}

fn bench_coriolis(i: usize) -> f32 {
    residence(scene_f32(i), Model::Coriolis)
        .map(|o| o.residence_time_s())
        .unwrap_or(f32::NAN)
}

/// Targets: 0.1 to 3 s, the range a controller asks for.
fn bench_target(i: usize) -> f32 {
    [0.1f32, 0.3, 1.0, 3.0][(i / 3) % 4]
}

fn bench_inverse(i: usize) -> f32 {
    omega_for_residence_time(scene_f32(i), Model::Coriolis, bench_target(i)).unwrap_or(f32::NAN)
}

fn bench_inverse_flat(i: usize) -> f32 {
    omega_for_residence_time(scene_f32(i), Model::Flat, bench_target(i)).unwrap_or(f32::NAN)
}
