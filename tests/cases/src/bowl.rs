//! Cases for paper Eq. 2 (bowl kinematics), checked against the vector form of the same law.

use crate::check::{Bench, Case, Failure, close, ensure};
use model_core::bowl::{BowlError, BowlGeometry, MotorSpeeds};

/// Cases of this module.
pub static CASES: &[Case] = &[
    Case {
        name: "bowl::combined_speed_matches_vector_sum_f32",
        run: combined_matches_vector_sum,
    },
    Case {
        name: "bowl::split_round_trips_f32",
        run: split_round_trips,
    },
    Case {
        name: "bowl::rejects_bad_input_f32",
        run: rejects_bad_input,
    },
];

/// Benchmarks of this module.
pub static BENCHES: &[Bench] = &[
    Bench {
        name: "bowl::combined_speed_f32",
        inputs: 16,
        run: bench_combined,
        budget_instructions: None,
    },
    Bench {
        name: "bowl::split_f32",
        inputs: 16,
        run: bench_split,
        budget_instructions: None,
    },
];

const ANGLES_DEG: [f32; 4] = [0.0, 30.0, 60.0, 90.0];
const SPEEDS: [f32; 4] = [0.0, 0.5, 1.8, 3.6];

fn geometry(deg: f32) -> BowlGeometry<f32> {
    BowlGeometry {
        axes_angle_rad: deg.to_radians(),
    }
}

/// Independent reference: the precession vector along z, the spin vector tilted by the angle in
/// the x-z plane; omega is the Euclidean norm of their sum, computed in f64.
fn vector_sum_norm(w1: f64, w2: f64, deg: f64) -> f64 {
    let a = deg.to_radians();
    let (x, z) = (w2 * libm::sin(a), w1 + w2 * libm::cos(a));
    libm::sqrt(x * x + z * z)
}

fn combined_matches_vector_sum() -> Result<(), Failure> {
    for &deg in &ANGLES_DEG {
        for &w1 in &SPEEDS {
            for &w2 in &SPEEDS {
                let got = geometry(deg)
                    .combined_speed_rad_s(MotorSpeeds {
                        precession_rad_s: w1,
                        spin_rad_s: w2,
                    })
                    .map_err(|_| Failure {
                        what: "combined speed errored",
                        got: 0.0,
                        want: 1.0,
                        tolerance: 0.0,
                    })?;
                let want = vector_sum_norm(w1 as f64, w2 as f64, deg as f64);
                close("combined speed vs vector sum (rel)", got as f64, want, 4e-7)?;
            }
        }
    }
    Ok(())
}

fn split_round_trips() -> Result<(), Failure> {
    for &deg in &ANGLES_DEG {
        for &rho in &[0.0f32, 0.5, 1.0, 4.0] {
            for &omega in &SPEEDS {
                let g = geometry(deg);
                let s = g.split(omega, rho).map_err(|_| Failure {
                    what: "split errored",
                    got: 0.0,
                    want: 1.0,
                    tolerance: 0.0,
                })?;
                let back =
                    vector_sum_norm(s.precession_rad_s as f64, s.spin_rad_s as f64, deg as f64);
                close(
                    "split then Eq. 2 gives the target (rel)",
                    back,
                    omega as f64,
                    6e-7,
                )?;
                close(
                    "split keeps the ratio",
                    s.spin_rad_s as f64,
                    (rho * s.precession_rad_s) as f64,
                    1e-6,
                )?;
            }
        }
    }
    Ok(())
}

fn rejects_bad_input() -> Result<(), Failure> {
    let g = geometry(60.0);
    ensure(
        "negative target rejected",
        g.split(-1.0, 1.0) == Err(BowlError::NegativeTargetSpeed),
    )?;
    ensure(
        "NaN ratio rejected",
        g.split(1.0, f32::NAN) == Err(BowlError::InvalidRatio),
    )?;
    ensure("overflow rejected", {
        let big = MotorSpeeds {
            precession_rad_s: 3e38,
            spin_rad_s: 3e38,
        };
        g.combined_speed_rad_s(big) == Err(BowlError::NonFiniteSpeed)
    })?;
    ensure(
        "angle pi rejected",
        BowlGeometry::new(core::f32::consts::PI) == Err(BowlError::InvalidAxesAngle),
    )
}

fn bench_combined(i: usize) -> f32 {
    let g = BowlGeometry::<f32>::default();
    let s = MotorSpeeds {
        precession_rad_s: SPEEDS[i % 4],
        spin_rad_s: SPEEDS[(i / 4) % 4],
    };
    g.combined_speed_rad_s(s).unwrap_or(f32::NAN)
}

fn bench_split(i: usize) -> f32 {
    let g = BowlGeometry::<f32>::default();
    g.split(SPEEDS[i % 4], [0.0, 0.5, 1.0, 4.0][(i / 4) % 4])
        .map(|s| s.spin_rad_s)
        .unwrap_or(f32::NAN)
}
