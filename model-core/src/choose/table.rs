//! Choosing without running: RK4's error constant, the Coriolis term's effect and `T` itself,
//! measured once on a grid over a first-order spin-up's dimensionless features and read here by
//! interpolation.
//!
//! With lengths in units of the rim radius `R` and time in units of `1 / omega_f` (the final
//! speed), `r'' = k2 (r omega^2 - mu g - c 2 mu omega r')` (paper Eq. 5 and 9) depends on five
//! numbers (and `k2`, fixed at 5/7, the rolling sphere's): the start over the final speed
//! `s`, `omega_f tau`, the release ratio `q = mu g / (ri omega_f^2)` (the particle is released
//! once `(omega / omega_f)^2 > q`; it never leaves for `q >= 1`), the start radius `ri / R`, and
//! the Coriolis damping `2 k2 mu`. RK4's relative error in `T` at a step `h` is `C (h omega_f)^4`.
//! At each grid point the table holds the largest `C` seen at the chooser's coarsest step and
//! twelve steps each `2^(1/4)` finer (for both models), the Coriolis effect
//! `|T_coriolis - T_flat| / T_flat` per unit of damping, and the time from the release to the
//! rim times `omega_f` (the release itself has a closed form), each against DP5(4) at `rtol`
//! 1e-13, one byte each on a logarithmic scale. A scene is read by multilinear interpolation
//! over its cell's 32 corners; outside the grid, or where a corner's particle never leaves,
//! there is no reading and the chooser runs its pilot.
//!
//! Measured on 28,675 random spin-ups (docs/model.md, the chooser): 99 % lie inside the grid,
//! no plan read from the table missed its tolerance (worst 0.87 of it), and a reading costs
//! about 0.24 us on the host, where the plan it picks costs 0.4 to 2.5 us. The table is made
//! by `bowl chart error-table`; `host-tools/tests/error_table.rs` remeasures grid points and
//! fails when the committed bytes differ.

use super::{Choice, Plan, Source, Target, plan_cost};
use crate::Real;
use crate::ode::{self, Limits, Method, OdeOutcome, OmegaProfile, SpinUp};
use crate::particle::{self, Model, Scene, radial};

/// One axis of the grid: `count` levels from `first`, `step` apart.
#[derive(Debug, Clone, Copy)]
pub struct Axis {
    /// The first level.
    pub first: f64,
    /// The distance between levels.
    pub step: f64,
    /// The number of levels.
    pub count: usize,
}

impl Axis {
    /// The level at `index`.
    pub fn level(&self, index: usize) -> f64 {
        self.first + self.step * index as f64
    }

    /// The cell below `x` and the fraction of the way across it; `None` outside the axis.
    fn locate(&self, x: f64) -> Option<(usize, f64)> {
        let g = (x - self.first) / self.step;
        let last = (self.count - 1) as f64;
        if !(0.0..=last).contains(&g) {
            return None;
        }
        let i = (libm::floor(g) as usize).min(self.count - 2);
        Some((i, g - i as f64))
    }
}

/// Start speed over final speed.
pub const START_RATIO: Axis = Axis {
    first: 0.0,
    step: 0.125,
    count: 9,
};
/// `log10(omega_f tau)`.
pub const LOG_SPIN_UP: Axis = Axis {
    first: -1.25,
    step: 0.125,
    count: 25,
};
/// `log10(q / (1 - q))` with `q = mu g / (ri omega_f^2)`: `log10 q` where the particle is
/// released early in the spin-up, `-log10(1 - q)` where it is released near the final speed
/// and `T` grows without bound as `q` nears 1.
pub const RELEASE_LOGIT: Axis = Axis {
    first: -2.75,
    step: 0.25,
    count: 18,
};
/// `ri / R`.
pub const START_RADIUS: Axis = Axis {
    first: 0.05,
    step: 0.15,
    count: 7,
};
/// `log10(2 k2 mu)`.
pub const LOG_DAMPING: Axis = Axis {
    first: -3.5,
    step: 1.0,
    count: 4,
};

/// The effect read is multiplied by this before it is compared with the tolerance: on 9,474
/// random spin-ups inside the grid the effect read was 0.99x to 1.12x the measured one on 98 %
/// of them and never below 0.675x (docs/model.md, the chooser). Reading it high costs nothing
/// on the host (the Coriolis plan is then taken, at the same price per evaluation).
pub const EFFECT_READING_MARGIN: f64 = 1.5;

/// The relative error of the `T` read, bounded (measured on 9,474 random spin-ups inside the
/// grid: 0.79x to 1.24x, 98 % within 7.5 %).
pub const TIME_READING_ERROR_REL: f64 = 0.25;

/// The one `k2` the table holds (a rolling solid sphere).
pub const K2: f64 = 5.0 / 7.0;

/// Points of the five-dimensional grid (the flat model's table has no damping axis).
pub const POINTS: usize = START_RATIO.count
    * LOG_SPIN_UP.count
    * RELEASE_LOGIT.count
    * START_RADIUS.count
    * LOG_DAMPING.count;
/// Points of the flat model's four-dimensional grid.
pub const FLAT_POINTS: usize = POINTS / LOG_DAMPING.count;

/// Bytes of the table file: three five-dimensional tables and the flat one.
pub const BYTES: usize = 3 * POINTS + FLAT_POINTS;

/// A value is stored as `1 + ceil((log10 v - LOG_FLOOR) * STEPS_PER_DECADE)`, 0 for "not
/// measured" (the particle never leaves, or the value is beyond the code's range). Rounding up
/// keeps the error constant and the effect on the safe side.
const LOG_FLOOR: f64 = -9.0;
const STEPS_PER_DECADE: f64 = 20.0;

/// The byte that stores `v`: `1 + ceil((log10 v + 9) * 20)`, 0 for "not measured".
pub fn encode(v: f64) -> u8 {
    if !(v.is_finite() && v >= 0.0) {
        return 0;
    }
    let steps = libm::ceil((libm::log10(v) - LOG_FLOOR) * STEPS_PER_DECADE);
    if steps > 254.0 {
        0
    } else {
        (steps.max(0.0) as u8) + 1
    }
}

/// The byte nearest `v` (for `T`, where neither side is safer).
pub fn encode_nearest(v: f64) -> u8 {
    if !(v.is_finite() && v > 0.0) {
        return 0;
    }
    let steps = libm::round((libm::log10(v) - LOG_FLOOR) * STEPS_PER_DECADE);
    if steps > 254.0 {
        0
    } else {
        (steps.max(0.0) as u8) + 1
    }
}

/// The value each byte stores (index 0, "not measured", unused): `10^(1/20)` apart from
/// `10^LOG_FLOOR`, built by repeated multiplication (255 roundings: relative error below
/// 1e-13).
static DECODED: [f64; 256] = decoded();

const fn decoded() -> [f64; 256] {
    // 10^(1/STEPS_PER_DECADE), 10^LOG_FLOOR.
    const RATIO: f64 = 1.122_018_454_301_963_3;
    let mut values = [0.0; 256];
    values[1] = 1e-9;
    let mut b = 2;
    while b < 256 {
        values[b] = values[b - 1] * RATIO;
        b += 1;
    }
    values
}

static TABLE: &[u8; BYTES] = include_bytes!("error_table.bin");

/// The dimensionless scene at a grid point (`R = 1`, `omega_f = 1`) and its speed; the point
/// indexes the five-dimensional grid, damping last.
pub fn scene_at(point: usize) -> (Scene<f64>, SpinUp<f64>) {
    let mut r = point;
    let mut next = |axis: &Axis| {
        let i = r % axis.count;
        r /= axis.count;
        axis.level(i)
    };
    let log_damping = next(&LOG_DAMPING);
    let radius = next(&START_RADIUS);
    let release_logit = next(&RELEASE_LOGIT);
    let log_spin_up = next(&LOG_SPIN_UP);
    let start = next(&START_RATIO);
    let mu = libm::pow(10.0, log_damping) / (2.0 * K2);
    let odds = libm::pow(10.0, release_logit);
    let g = odds / (1.0 + odds) * radius / mu;
    let scene = Scene {
        omega_rad_s: 1.0,
        mu,
        g_m_s2: g,
        k2: K2,
        ri_m: radius,
        rim_radius_m: 1.0,
    };
    let speed = SpinUp {
        start_rad_s: start,
        final_rad_s: 1.0,
        time_constant_s: libm::pow(10.0, log_spin_up),
    };
    (scene, speed)
}

fn residence_s(scene: &Scene<f64>, model: Model, speed: &SpinUp<f64>, method: Method<f64>) -> f64 {
    let limits = Limits::for_scene(scene, speed);
    match particle::integrate(scene, model, speed, method, limits).map(|r| r.outcome) {
        Ok(OdeOutcome::Leaves {
            residence_time_s, ..
        }) => residence_time_s,
        _ => f64::NAN,
    }
}

/// Steps measured below the coarsest, each `2^(1/4)` finer: down to an eighth of it. With few
/// steps to the rim the error swings with where the rim falls in a step, so the steps between
/// the halvings are measured too.
const STEP_LEVELS: u32 = 12;

/// RK4's largest `|error| / h^4` at the chooser's coarsest step and [`STEP_LEVELS`] finer ones
/// (dimensionless scene: `h` in units of `1 / omega_f`), against `reference_s`.
fn error_constant(scene: &Scene<f64>, model: Model, speed: &SpinUp<f64>, reference_s: f64) -> f64 {
    let coarsest = 1.5f64.min(speed.time_constant_s);
    let mut worst = 0.0f64;
    for level in 0..=STEP_LEVELS {
        let h = coarsest * libm::pow(2.0, -f64::from(level) / 4.0);
        let t = residence_s(scene, model, speed, Method::Rk4 { step_s: h });
        worst = worst.max(((t - reference_s) / reference_s).abs() / (h * h * h * h));
    }
    worst
}

/// Measures grid point `point` of the five-dimensional grid: the bytes of the Coriolis error
/// constant, the effect per unit of damping and the release-to-rim time (times `omega_f`, 1
/// here), and (where the damping index is 0, which the flat model's grid shares) the flat
/// error constant.
pub fn measure(point: usize) -> ([u8; 3], Option<u8>) {
    let (scene, speed) = scene_at(point);
    let reference = Method::Dp54 {
        rtol: 1e-13,
        atol: 1e-16,
    };
    let coriolis_s = residence_s(&scene, Model::Coriolis, &speed, reference);
    let flat_s = residence_s(&scene, Model::Flat, &speed, reference);
    let released_s = release_s(&scene, &speed);
    // The effect grows about in proportion to the damping: per unit of it, it interpolates
    // across the damping axis's decades without bias.
    let damping = 2.0 * K2 * scene.mu;
    let three = if coriolis_s.is_finite() && flat_s.is_finite() && coriolis_s > released_s {
        [
            encode(error_constant(&scene, Model::Coriolis, &speed, coriolis_s)),
            encode((coriolis_s - flat_s).abs() / flat_s / damping),
            encode_nearest(coriolis_s - released_s),
        ]
    } else {
        [0; 3]
    };
    let flat = point.is_multiple_of(LOG_DAMPING.count).then(|| {
        if flat_s.is_finite() && flat_s > 0.0 {
            encode(error_constant(&scene, Model::Flat, &speed, flat_s))
        } else {
            0
        }
    });
    (three, flat)
}

/// When the particle is released (the integration's start), s.
fn release_s<T: Real>(scene: &Scene<T>, speed: &SpinUp<T>) -> T {
    let limits = Limits::for_scene(scene, speed);
    let stiff_rate = radial::stiff_rate_per_s(scene, Model::Coriolis, speed.max_omega_rad_s());
    radial::start_time_s(scene, speed, stiff_rate, limits).unwrap_or(T::ZERO)
}

/// What the table says of a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Reading {
    /// RK4's error constant `C` of the Coriolis model: relative error `C (h omega_f)^4`.
    pub coriolis_constant: f64,
    /// The same for the flat model.
    pub flat_constant: f64,
    /// `|T_coriolis - T_flat| / T_flat`.
    pub effect_rel: f64,
    /// `T` of the Coriolis model, s.
    pub time_s: f64,
    /// When the particle is released, s: the runs start there.
    pub release_s: f64,
}

/// A cell's corners: each one's index into the five-dimensional grid, into the flat model's
/// four-dimensional one, and its weight (the product of the fractions across each axis).
struct Corners {
    index: [usize; 32],
    flat_index: [usize; 32],
    weight: [f64; 32],
}

impl Corners {
    fn of(cell: &[(usize, f64); 5], axes: &[Axis; 5]) -> Self {
        let mut corners = Corners {
            index: [0; 32],
            flat_index: [0; 32],
            weight: [1.0; 32],
        };
        // Each axis doubles the corners: every one so far splits into its lower and upper
        // neighbour along the axis (built from the end so nothing is overwritten early).
        let mut count = 1;
        for (d, (axis, &(i, f))) in axes.iter().zip(cell).enumerate() {
            if d == 4 {
                // The flat grid ends before the damping axis: both halves of each pair read
                // the same flat point.
                for k in 0..count {
                    corners.flat_index[2 * k] = corners.index[k];
                    corners.flat_index[2 * k + 1] = corners.index[k];
                }
            }
            for k in (0..count).rev() {
                let (index, weight) = (corners.index[k] * axis.count + i, corners.weight[k]);
                corners.index[2 * k] = index;
                corners.weight[2 * k] = weight * (1.0 - f);
                corners.index[2 * k + 1] = index + 1;
                corners.weight[2 * k + 1] = weight * f;
            }
            count *= 2;
        }
        corners
    }

    /// A table's value in the cell: the multilinear interpolation of the corners' values,
    /// `None` if a corner was not measured. The flat model's table has no damping axis (the
    /// last): each pair of corners across it reads the same point, and their weights add up.
    ///
    /// Values, not their logarithms: the error constant falls like a power of `omega_f tau`
    /// and of the release logit (convex over those axes), varies about linearly with the start
    /// ratio, and changes sign in places (its magnitude then dips between corners); linear
    /// interpolation lies above all three, so the plan it gives is never too coarse from the
    /// interpolation. Logarithms read `C` up to 2.4x too small across the start ratio's last
    /// cell, where `C` is linear in it (three plans of 28,675 random spin-ups missed their
    /// tolerance, by up to 1.16x).
    fn value(&self, table: &[u8], flat: bool) -> Option<f64> {
        let indexes = if flat { &self.flat_index } else { &self.index };
        let mut sum = 0.0;
        for (&index, &weight) in indexes.iter().zip(&self.weight) {
            let b = *table.get(index)?;
            if b == 0 {
                return None;
            }
            sum += weight * DECODED[usize::from(b)];
        }
        Some(sum)
    }
}

/// The table's reading for a spin-up, `None` outside the grid, for a `k2` other than 5/7, or
/// where a corner's particle never leaves.
pub(crate) fn read<T: Real>(scene: &Scene<T>, speed: &SpinUp<T>) -> Option<Reading> {
    let f = |x: T| x.to_f64();
    let (mu, g, k2, ri, rim) = (
        f(scene.mu),
        f(scene.g_m_s2),
        f(scene.k2),
        f(scene.ri_m),
        f(scene.rim_radius_m),
    );
    let (start, w_f, tau) = (
        f(speed.start_rad_s),
        f(speed.final_rad_s),
        f(speed.time_constant_s),
    );
    if (k2 - K2).abs() > 1e-9 || !(w_f > 0.0 && rim > 0.0 && mu > 0.0 && ri > 0.0) {
        return None;
    }
    let q = mu * g / (ri * w_f * w_f);
    if q >= 1.0 {
        return None;
    }
    let damping = 2.0 * K2 * mu;
    let features = [
        start / w_f,
        libm::log10(w_f * tau),
        libm::log10(q / (1.0 - q)),
        ri / rim,
        libm::log10(damping),
    ];
    let axes = [
        START_RATIO,
        LOG_SPIN_UP,
        RELEASE_LOGIT,
        START_RADIUS,
        LOG_DAMPING,
    ];
    let mut cell = [(0usize, 0.0f64); 5];
    for ((slot, axis), x) in cell.iter_mut().zip(&axes).zip(features) {
        *slot = axis.locate(x)?;
    }
    let corners = Corners::of(&cell, &axes);
    let released_s = release_s(scene, speed).to_f64();
    let (coriolis, rest) = TABLE.split_at(POINTS);
    let (effect, rest) = rest.split_at(POINTS);
    let (time, flat) = rest.split_at(POINTS);
    Some(Reading {
        coriolis_constant: corners.value(coriolis, false)?,
        flat_constant: corners.value(flat, true)?,
        effect_rel: corners.value(effect, false)? * damping,
        time_s: released_s + corners.value(time, false)? / w_f,
        release_s: released_s,
    })
}

/// RK4's longest step, up to `step_cap`, s, whose relative error `constant (h omega_f)^4` is
/// within `error_rel`.
fn step_within(constant: f64, error_rel: f64, w_f: f64, step_cap: f64) -> f64 {
    step_cap.min(libm::sqrt(libm::sqrt(error_rel / constant)) / w_f)
}

impl Reading {
    /// RK4's longest step, up to `step_cap`, s, whose error in the Coriolis model's `T` this
    /// reading puts within `error_rel` (`w_f`: the spin-up's final speed, rad/s).
    pub(crate) fn coriolis_step_s(&self, error_rel: f64, w_f: f64, step_cap: f64) -> f64 {
        step_within(self.coriolis_constant, error_rel, w_f, step_cap)
    }
}

/// The choice from a reading of the table, `None` where the plan would need more steps than
/// the cap. The effect is read with its interpolation margin ([`EFFECT_READING_MARGIN`]); the
/// step is RK4's longest, up to `step_cap`, whose error `C (h omega_f)^4` is within the same
/// budget as the pilot's plan.
pub(crate) fn choice<T: Real>(
    reading: &Reading,
    speed: &ode::SpinUp<T>,
    tolerance: T,
    step_cap: T,
    limits: Limits<T>,
) -> Option<Choice<T>> {
    let tol = tolerance.to_f64();
    let effect_bound = reading.effect_rel * EFFECT_READING_MARGIN;
    let (model, budget, constant, time_s) = if effect_bound <= 0.75 * tol {
        let flat_time_s = reading.time_s / (1.0 + reading.effect_rel);
        (
            Model::Flat,
            (tol - effect_bound) * 0.5,
            reading.flat_constant,
            flat_time_s,
        )
    } else {
        (
            Model::Coriolis,
            tol * 0.5,
            reading.coriolis_constant,
            reading.time_s,
        )
    };
    let w_f = speed.final_rad_s.to_f64();
    let h = step_within(constant, budget, w_f, step_cap.to_f64());
    let steps = libm::ceil(((time_s - reading.release_s) / h).max(1.0));
    if !(h > 0.0 && steps <= f64::from(limits.max_steps)) {
        return None;
    }
    // RK4: four evaluations a step and one where the rim is crossed.
    let evals = steps as u32 * 4 + 1;
    let plan = Plan::Integrate(Method::Rk4 {
        step_s: T::from_f64(h),
    });
    let hw = h * w_f;
    Some(Choice {
        model,
        plan,
        tolerance_rel: tolerance,
        spread_rel: None,
        coriolis_effect_rel: T::from_f64(reading.effect_rel),
        estimated_error_rel: T::from_f64(constant * hw * hw * hw * hw),
        rhs_evaluations: evals,
        predicted_cost: plan_cost(&plan, evals, Target::for_precision::<T>()),
        time_estimate_s: T::from_f64(time_s),
        choosing_evaluations: 0,
        answer_s: None,
        source: Source::Table,
    })
}

#[cfg(test)]
#[path = "table_tests.rs"]
mod tests;
