//! The granule in the real bowl (issue 30, docs/model.md §10): a flat bottom of radius `R`,
//! then a wall at `alpha` from the bottom plane (90 deg = vertical), `H` high, joined to the
//! bottom by a fillet of radius `F`; the lip is the wall's top edge at radius
//! `R + H cot alpha`, and a granule has left when its centre passes the lip's radius. On the
//! bottom the granule rolls or slides ([`crate::particle::rolling::modes`]); on the fillet and
//! the wall the same contact on a surface of revolution ([`wall`]). `H = 0` is a bare rim at
//! `R`: the flat-disc model exactly.
//!
//! A corner sharper than the granule (`F <= a`) is an impact: the velocity into the wall is
//! reversed and scaled by the restitution `e` (a vertical wall sends the granule back along
//! the bottom; below a rest speed it stays in the corner), the velocity along the wall kept.
//! Not modelled yet: flight (a granule whose normal force reaches zero off the lip's edge is
//! reported as lifting off there, with no residence time; the rebound off a flared sharp
//! corner, which would be a flight, is dropped as if `e = 0`).

pub mod wall;
pub mod wall_run;

use crate::Real;
use crate::ode::system::{SystemError, SystemLimits};
use crate::particle::rolling::modes::{MAX_SWITCHES, ModesOutcome, Regime, Tally, run_from};
use crate::particle::rolling::{RollingError, RollingMethod, RollingScene};
use wall::{Meridian, onto_bottom, onto_wall};
use wall_run::{WallEnd, stay};

/// The radius, in units of the rim's, of the fillet a sharp corner is given for a granule that
/// stays in it.
const SHARP_FILLET: f64 = 1e-2;

/// Below this speed towards a sharp corner's wall, in units of `sqrt(g R)`, a granule no longer
/// rebounds from it but stays in the corner (a bounce sequence would otherwise take ever
/// shorter flights without end).
const REST_SPEED: f64 = 1e-3;

/// The bowl's wall. SI units; angles in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlShape<T> {
    /// Wall angle from the bottom plane, rad (pi/2 = vertical).
    pub wall_angle_rad: T,
    /// Wall height above the bottom plane, m (0: a bare rim at `R`).
    pub wall_height_m: T,
    /// Fillet radius between bottom and wall, m (0: a sharp corner).
    pub fillet_radius_m: T,
    /// Coefficient of restitution of the impact with a sharp corner's wall.
    pub restitution: T,
}

/// Why the bowl model gave no answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BowlError {
    /// A scene input (as the rolling model's).
    Scene(RollingError),
    /// The wall angle was not in (0, 90] degrees.
    InvalidWallAngle,
    /// The wall height was NaN, infinite or negative.
    InvalidWallHeight,
    /// The fillet radius was NaN, infinite or negative.
    InvalidFillet,
    /// The fillet (with the granule's radius) reaches in to the release radius.
    FilletReachesRelease,
    /// The restitution was not in [0, 1].
    InvalidRestitution,
    /// The horizon was not a positive finite time.
    InvalidHorizon,
}

/// What happens to one granule in the bowl: as on the bottom alone.
pub type BowlOutcome<T> = ModesOutcome<T>;

/// One release in the bowl.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlReport<T> {
    /// The outcome.
    pub outcome: BowlOutcome<T>,
    /// Time rolling and sliding (bottom and wall), s.
    pub regime: Regime<T>,
    /// Time on the fillet and the wall, s.
    pub on_wall_s: T,
    /// Time held at rest in a vertical wall's sharp corner, up to the horizon, s.
    pub held_s: T,
    /// Changes of contact (roll/slide) and of surface (bottom/wall).
    pub switches: u32,
    /// Right-hand sides.
    pub evaluations: u32,
    /// Accepted steps.
    pub steps: u32,
}

impl<T: Real> BowlReport<T> {
    /// Adds a stay's time in each mode, changes and cost.
    fn add(&mut self, stay: &Tally<T>) {
        self.regime.roll_s += stay.regime.roll_s;
        self.regime.slide_s += stay.regime.slide_s;
        self.switches = self.switches.saturating_add(stay.switches);
        self.evaluations = self.evaluations.saturating_add(stay.evaluations);
        self.steps = self.steps.saturating_add(stay.steps);
    }
}

impl<T: Real> BowlShape<T> {
    /// A bare rim at `R` (no wall).
    pub fn bare_rim() -> Self {
        Self {
            wall_angle_rad: T::from_f64(core::f64::consts::FRAC_PI_2),
            wall_height_m: T::ZERO,
            fillet_radius_m: T::ZERO,
            restitution: T::HALF,
        }
    }

    /// The centre's meridian on the wall for this scene (`None`: a bare rim).
    pub fn meridian(&self, sc: &RollingScene<T>) -> Option<Meridian<T>> {
        if self.wall_height_m <= T::ZERO {
            return None;
        }
        let a = sc.particle_radius_m;
        let rim = sc.rim_radius_m;
        // A corner sharper than the granule (F <= a) is an impact (`sharp_corner`); the
        // granule that stays in it then sits in a fillet of a hundredth of the rim's radius,
        // which stands in for touching the bottom and the wall at once.
        let rc = (self.fillet_radius_m - a).max(rim * T::from_f64(SHARP_FILLET));
        let fillet = rc + a;
        let alpha = self.wall_angle_rad;
        let (sa, ca) = (alpha.sin(), alpha.cos());
        // tan(alpha/2) = sin alpha / (1 + cos alpha).
        let half_tan = sa / (T::ONE + ca);
        let rho_b = rim - fillet * half_tan;
        let lip = rim + self.wall_height_m * ca / sa;
        // The centre when the contact is at the edge, and how far along the cone that is from
        // the fillet's end (0 if the fillet rises above the wall: then the pivot starts there).
        let top = [lip - a * sa, self.wall_height_m + a * ca];
        let arc_end = [rho_b + rc * sa, a + rc * (T::ONE - ca)];
        let along = ((top[0] - arc_end[0]) * ca + (top[1] - arc_end[1]) * sa).max(T::ZERO);
        Some(Meridian {
            rho_b_m: rho_b,
            z0_m: a,
            arc_radius_m: rc,
            alpha_rad: alpha,
            lip_m: lip,
            top_s: rc * alpha + along,
            pivot_m: a.max(rim * T::from_f64(1e-6)),
        })
    }

    /// Whether the corner is sharper than the granule: then reaching it is an impact.
    pub fn sharp_corner(&self, sc: &RollingScene<T>) -> bool {
        self.fillet_radius_m - sc.particle_radius_m <= sc.rim_radius_m * T::from_f64(SHARP_FILLET)
    }

    /// Checks the shape against the scene; the first bad value is named.
    pub fn validate(&self, sc: &RollingScene<T>) -> Result<(), BowlError> {
        sc.validate().map_err(BowlError::Scene)?;
        let right = T::from_f64(core::f64::consts::FRAC_PI_2);
        if !(self.wall_angle_rad.is_finite()
            && self.wall_angle_rad > T::ZERO
            && self.wall_angle_rad <= right)
        {
            return Err(BowlError::InvalidWallAngle);
        }
        if !self.wall_height_m.is_nonneg_finite() {
            return Err(BowlError::InvalidWallHeight);
        }
        if !self.fillet_radius_m.is_nonneg_finite() {
            return Err(BowlError::InvalidFillet);
        }
        if !(self.restitution.is_finite()
            && self.restitution >= T::ZERO
            && self.restitution <= T::ONE)
        {
            return Err(BowlError::InvalidRestitution);
        }
        if let Some(m) = self.meridian(sc)
            && (m.rho_b_m <= sc.ri_m || m.rho_b_m.is_nan())
        {
            return Err(BowlError::FilletReachesRelease);
        }
        Ok(())
    }
}

/// One release at azimuth `beta_rad` (from the downhill direction, as the rolling model's), at
/// rest on the bottom at `ri`, followed until it leaves over the lip, lifts off, or the horizon.
pub fn residence<T: Real>(
    sc: &RollingScene<T>,
    shape: &BowlShape<T>,
    beta_rad: T,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
) -> Result<BowlReport<T>, BowlError> {
    shape.validate(sc)?;
    if !(limits.horizon_s.is_finite() && limits.horizon_s > T::ZERO) {
        return Err(BowlError::InvalidHorizon);
    }
    if !beta_rad.is_finite() {
        return Err(BowlError::Scene(RollingError::InvalidAzimuth));
    }
    let meridian = shape.meridian(sc);
    let bottom = RollingScene {
        rim_radius_m: meridian.map_or(sc.rim_radius_m, |m| m.rho_b_m),
        ..*sc
    };
    let mut report = BowlReport {
        outcome: BowlOutcome::Inside {
            horizon_s: limits.horizon_s,
        },
        regime: Regime {
            roll_s: T::ZERO,
            slide_s: T::ZERO,
        },
        on_wall_s: T::ZERO,
        held_s: T::ZERO,
        switches: 0,
        evaluations: 0,
        steps: 0,
    };
    // The first stay on the bottom starts from the release (with its held-at-rest check).
    let first =
        crate::particle::rolling::modes::roll_or_slide_within(&bottom, beta_rad, method, limits)
            .map_err(BowlError::Scene)?;
    let mut on_bottom = first;
    let mut t = T::ZERO;
    loop {
        report.add(&on_bottom.tally);
        let (te, exit_speed) = match on_bottom.outcome {
            ModesOutcome::Leaves {
                residence_time_s,
                exit_speed_m_s,
            } => (t + residence_time_s, exit_speed_m_s),
            // Still on the bottom at the horizon: the report's outcome already says so.
            ModesOutcome::Inside { .. } => return Ok(report),
            held_or_lifted => {
                report.outcome = held_or_lifted;
                return Ok(report);
            }
        };
        let Some(m) = meridian else {
            report.outcome = BowlOutcome::Leaves {
                residence_time_s: te,
                exit_speed_m_s: exit_speed,
            };
            return Ok(report);
        };
        if report.switches > MAX_SWITCHES {
            return Err(BowlError::Scene(RollingError::Integration(
                SystemError::StepLimit,
            )));
        }
        report.switches += 1;
        let remaining = SystemLimits {
            horizon_s: limits.horizon_s,
            max_steps: limits.max_steps.saturating_sub(report.steps),
        };
        let mut entry = onto_wall(&m, &on_bottom.end_state);
        if shape.sharp_corner(sc) {
            // The impact: the velocity's part into the wall (normal (-sin alpha, cos alpha) in
            // the meridian plane) is reversed and scaled by e, the part along the wall kept.
            let (sa, ca) = (shape.wall_angle_rad.sin(), shape.wall_angle_rad.cos());
            let into = entry[3] * sa;
            let rebound = shape.restitution * into;
            let rest = T::from_f64(REST_SPEED) * (sc.g_m_s2 * sc.rim_radius_m).sqrt();
            let vertical = ca <= T::from_f64(1e-9);
            if vertical && rebound <= rest {
                // At rest against a vertical wall in a sharp corner: its centre stays at
                // `R - a` or nearer the axis, inside the lip at `R`, and only a flight could
                // take it out: held by the wall for the rest of the time.
                report.held_s = limits.horizon_s - te;
                return Ok(report);
            }
            if vertical {
                // A vertical wall sends it straight back along the bottom.
                let mut back = on_bottom.end_state;
                let rho = (back[0] * back[0] + back[1] * back[1])
                    .sqrt()
                    .max(T::EPSILON);
                let (ex, ey) = (back[0] / rho, back[1] / rho);
                let radial = back[2] * ex + back[3] * ey;
                back[2] -= (radial + rebound) * ex;
                back[3] -= (radial + rebound) * ey;
                t = te;
                on_bottom =
                    run_from(&bottom, te, back, method, remaining).map_err(BowlError::Scene)?;
                continue;
            }
            // A flared wall: it goes on along the wall with what is left (the rebound off the
            // wall would be a flight, which is not modelled: it is dropped, as if e = 0).
            entry[3] *= ca;
        }
        let w =
            stay(sc, &m, te, entry, method, remaining, MAX_SWITCHES).map_err(BowlError::Scene)?;
        report.add(&w.tally);
        report.on_wall_s += w.tally.regime.roll_s + w.tally.regime.slide_s;
        match w.end {
            WallEnd::Lip(tl, speed) => {
                report.outcome = BowlOutcome::Leaves {
                    residence_time_s: tl,
                    exit_speed_m_s: speed,
                };
                return Ok(report);
            }
            WallEnd::LiftsOff(tl) => {
                report.outcome = BowlOutcome::LiftsOff { time_s: tl };
                return Ok(report);
            }
            WallEnd::Horizon => return Ok(report),
            WallEnd::Bottom(tb, yw) => {
                report.switches += 1;
                let remaining = SystemLimits {
                    horizon_s: limits.horizon_s,
                    max_steps: limits.max_steps.saturating_sub(report.steps),
                };
                t = tb;
                on_bottom = run_from(&bottom, tb, onto_bottom(&m, &yw), method, remaining)
                    .map_err(BowlError::Scene)?;
            }
        }
    }
}

#[cfg(test)]
mod tests;
