//! The granule in the real bowl (issue 30, docs/model.md §10): a flat bottom of radius `R`,
//! then a wall at `alpha` from the bottom plane (90 deg = vertical), `H` high, joined to the
//! bottom by a fillet of radius `F`; the lip is the wall's top edge at radius
//! `R + H cot alpha`, and a granule has left when its centre passes the lip's radius. On the
//! bottom the granule rolls or slides ([`crate::particle::rolling::modes`]); on the fillet and
//! the wall the same contact on a surface of revolution ([`wall`]). `H = 0` is a bare rim at
//! `R`: the flat-disc model exactly.
//!
//! A corner sharper than the granule (`F <= a`) is an impact: on a vertical wall the velocity
//! into it is reversed and scaled by the restitution `e` (back along the bottom; below a rest
//! speed it stays in the corner, held), on a flared wall the impact of [`flight`] (restitution
//! and Coulomb friction; a rebound flies). Where the normal force reaches zero the granule
//! flies ([`flight`]): ballistic until it lands (an impact, then it rolls, slides or bounces
//! again) or its centre passes over the lip.

pub mod flight;
pub mod wall;
pub mod wall_run;

mod report;

mod wall_rest;

mod shape;

use crate::Real;
use crate::ode::system::{SystemError, SystemLimits};
use crate::particle::rolling::modes::{MAX_SWITCHES, Mode, ModesOutcome, run_from};
use crate::particle::rolling::slide::SlideState;
use crate::particle::rolling::{RollingError, RollingMethod, RollingScene};
use flight::{Flight, FlightEnd, REST_SPEED, Surface, fly, impact, launch};
use wall::{WallState, from_space, onto_bottom, onto_wall, to_space};
use wall_run::{WallEnd, stay};

pub use report::{BowlReport, HeldAt};

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
    /// The fillet rises higher than the wall it rounds into (or there is no wall): the bowl it
    /// describes does not exist ([`BowlShape::fillet_rise_m`]).
    FilletAboveWall,
    /// The restitution was not in [0, 1].
    InvalidRestitution,
    /// The horizon was not a positive finite time.
    InvalidHorizon,
}

/// What happens to one granule in the bowl: as on the bottom alone.
pub type BowlOutcome<T> = ModesOutcome<T>;

/// One release at azimuth `beta_rad` (from the downhill direction, as the rolling model's), at
/// rest on the bottom at `ri`, followed (rolling, sliding, flying) until it leaves over the lip
/// or the horizon.
pub fn residence<T: Real>(
    sc: &RollingScene<T>,
    shape: &BowlShape<T>,
    beta_rad: T,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
) -> Result<BowlReport<T>, BowlError> {
    residence_watching(sc, shape, beta_rad, method, limits, None)
}

/// How many accepted steps in a row, each advancing the time by less than
/// [`crate::particle::rolling::modes::STALL_STEP`] of the scene's time scale, count as a stall for
/// [`residence_or_stall`].
pub const STALL_STEPS: u32 = 16;

/// [`residence`] that gives up early ([`SystemError::Stalled`]) where a segment stalls:
/// [`STALL_STEPS`] accepted steps in a row that do not advance the time. At a loose tolerance
/// the roll/slide switch on the wall can stall the integrator at one instant until the step cap
/// (a 60 deg wall at 45 deg tilt, 1.8 rad/s, mu_s 0.2, rtol 1e-6: 30 steps to 0.2449 s, then
/// none gets past it; docs/model.md §12); a caller that can run the release again at a tighter
/// tolerance learns it after tens of steps instead of thousands.
pub fn residence_or_stall<T: Real>(
    sc: &RollingScene<T>,
    shape: &BowlShape<T>,
    beta_rad: T,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
) -> Result<BowlReport<T>, BowlError> {
    residence_watching(sc, shape, beta_rad, method, limits, Some(STALL_STEPS))
}

fn residence_watching<T: Real>(
    sc: &RollingScene<T>,
    shape: &BowlShape<T>,
    beta_rad: T,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
    stall_steps: Option<u32>,
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
    let mut report = BowlReport::new(limits.horizon_s);
    // Where the granule is: on the bottom (the first stay from the release, with its
    // held-at-rest check), on the wall, or in flight; each stay ends in the next.
    let mut phase = Phase::Bottom(T::ZERO, None);
    let restitution = shape.restitution;
    let rest = T::from_f64(REST_SPEED) * (sc.g_m_s2 * sc.rim_radius_m).sqrt();
    loop {
        if report.switches > MAX_SWITCHES {
            return Err(BowlError::Scene(RollingError::Integration(
                SystemError::StepLimit,
            )));
        }
        let remaining = SystemLimits {
            horizon_s: limits.horizon_s,
            max_steps: limits.max_steps.saturating_sub(report.steps),
        };
        if remaining.max_steps == 0 {
            return Err(BowlError::Scene(RollingError::Integration(
                SystemError::StepLimit,
            )));
        }
        phase = match phase {
            Phase::Bottom(t, from) => {
                let on_bottom = match from {
                    None => crate::particle::rolling::modes::roll_or_slide_watching(
                        &bottom,
                        beta_rad,
                        method,
                        limits,
                        stall_steps,
                    ),
                    Some(y) => run_from(&bottom, t, y, method, remaining, stall_steps),
                }
                .map_err(BowlError::Scene)?;
                report.add(&on_bottom.tally);
                let (te, exit_speed) = match on_bottom.outcome {
                    ModesOutcome::Leaves {
                        residence_time_s,
                        exit_speed_m_s,
                    } => (t + residence_time_s, exit_speed_m_s),
                    ModesOutcome::LiftsOff { time_s } => {
                        report.switches += 1;
                        let y = on_bottom.end_state;
                        let a = sc.particle_radius_m;
                        phase = Phase::Flight(launch(
                            sc,
                            time_s,
                            [y[0], y[1], a],
                            [y[2], y[3], T::ZERO],
                            [y[4], y[5], y[6]],
                        ));
                        continue;
                    }
                    // Still on the bottom at the horizon: the report's outcome says so, and
                    // whether it is held there.
                    ModesOutcome::Inside { .. } => {
                        if on_bottom.tally.last == Some(Mode::Held) {
                            report.held_at = Some(HeldAt::Bottom);
                        }
                        return Ok(report);
                    }
                    ModesOutcome::Held => {
                        report.outcome = ModesOutcome::Held;
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
                report.switches += 1;
                let y = on_bottom.end_state;
                let entry = just_onto_wall(sc, onto_wall(&m, &y));
                if !shape.sharp_corner(sc) {
                    Phase::Wall(te, entry)
                } else {
                    let (sa, ca) = (shape.wall_angle_rad.sin(), shape.wall_angle_rad.cos());
                    let vertical = ca <= T::from_f64(1e-9);
                    if vertical {
                        // The impact on a vertical wall: the radial velocity reversed and
                        // scaled by e, the rest kept; it goes back along the bottom.
                        let rebound = restitution * entry[3];
                        if rebound <= rest {
                            // At rest against a vertical wall in a sharp corner: its centre
                            // stays at `R - a` or nearer the axis, inside the lip at `R`, and
                            // only a flight could take it out: held by the wall for the rest
                            // of the time.
                            report.held_s = limits.horizon_s - te;
                            report.held_at = Some(HeldAt::Wall);
                            return Ok(report);
                        }
                        let mut back = y;
                        let (ex, ey) = (entry[1], entry[2]);
                        let radial = back[2] * ex + back[3] * ey;
                        back[2] -= (radial + rebound) * ex;
                        back[3] -= (radial + rebound) * ey;
                        Phase::Bottom(te, Some(back))
                    } else {
                        // A flared wall met in a sharp corner: an impact on the wall (normal
                        // (-sin alpha, cos alpha) in the meridian plane) with restitution and
                        // friction; a rebound flies, a slower one goes on along the wall.
                        let [q, u, sg] = to_space(&m, &entry);
                        let n = [-sa * entry[1], -sa * entry[2], ca];
                        let (u2, s2, rebound) = impact(sc, restitution, u, sg, n);
                        if rebound > rest {
                            // The rebound starts on the wall: at the stand-in fillet's end
                            // (on the offset cone), not its start, which is
                            // `r (1 - cos alpha)` off the cone (0.375 mm in a 75 mm bowl at 60
                            // deg): launched there, the hop fell that much further (19 ms
                            // instead of 15 ms at e 0.125, landing 50 % faster than it left;
                            // docs/model.md §10).
                            let end = m.at(m.arc_radius_m * shape.wall_angle_rad).pos;
                            let (ex, ey) = (entry[1], entry[2]);
                            let q_end = [end[0] * ex, end[0] * ey, end[1]];
                            Phase::Flight(launch(sc, te, q_end, u2, s2))
                        } else {
                            // Along the wall with what the impact left: the speed up its slope
                            // `u . (cos alpha e_rho + sin alpha e_z)` is the meridian speed the
                            // corner's stand-in fillet turns from the bottom's direction to the
                            // wall's.
                            let mut w = just_onto_wall(sc, from_space(&m, T::ZERO, &q, &u2, &s2));
                            let (ex, ey) = (entry[1], entry[2]);
                            w[3] = (u2[0] * ex + u2[1] * ey) * ca + u2[2] * sa;
                            Phase::Wall(te, w)
                        }
                    }
                }
            }
            Phase::Wall(t, entry) => {
                let Some(m) = meridian else {
                    return Ok(report);
                };
                let w = stay(
                    sc,
                    &m,
                    t,
                    entry,
                    method,
                    remaining,
                    MAX_SWITCHES,
                    stall_steps,
                )
                .map_err(BowlError::Scene)?;
                report.add(&w.tally);
                report.on_wall_s +=
                    w.tally.regime.roll_s + w.tally.regime.slide_s + w.tally.regime.held_s;
                match w.end {
                    WallEnd::Lip(tl, speed) => {
                        report.outcome = BowlOutcome::Leaves {
                            residence_time_s: tl,
                            exit_speed_m_s: speed,
                        };
                        return Ok(report);
                    }
                    WallEnd::LiftsOff(tl, yw) => {
                        report.switches += 1;
                        let [q, u, sg] = to_space(&m, &yw);
                        Phase::Flight(launch(sc, tl, q, u, sg))
                    }
                    WallEnd::Horizon => {
                        // A sharp corner's stand-in fillet is the wall's corner.
                        report.held_at = w.held_at_s.map(|s| match m.piece_at(s) {
                            wall::Piece::Fillet if !shape.sharp_corner(sc) => HeldAt::Fillet,
                            _ => HeldAt::Wall,
                        });
                        return Ok(report);
                    }
                    WallEnd::Bottom(tb, yw) => {
                        report.switches += 1;
                        Phase::Bottom(tb, Some(just_onto_bottom(onto_bottom(&m, &yw))))
                    }
                }
            }
            Phase::Flight(f) => match fly(sc, meridian.as_ref(), &f, limits.horizon_s) {
                FlightEnd::Exits(te, speed) => {
                    report.flight_s += te - f.t0_s;
                    report.left_in_flight = true;
                    report.outcome = BowlOutcome::Leaves {
                        residence_time_s: te,
                        exit_speed_m_s: speed,
                    };
                    return Ok(report);
                }
                FlightEnd::Horizon => {
                    report.flight_s += limits.horizon_s - f.t0_s;
                    return Ok(report);
                }
                FlightEnd::Lands(l) => {
                    report.flight_s += l.t_s - f.t0_s;
                    report.switches += 1;
                    report.landings += 1;
                    let (u2, s2, rebound) = landing_impact(sc, shape, meridian.as_ref(), &l);
                    let (q, t) = (l.q_m, l.t_s);
                    if rebound > rest {
                        Phase::Flight(launch(sc, t, q, u2, s2))
                    } else {
                        // Too slow to bounce: it stays on the surface, its velocity along it.
                        let n = l.normal;
                        let vn = u2[0] * n[0] + u2[1] * n[1] + u2[2] * n[2];
                        let u3: [T; 3] = core::array::from_fn(|i| u2[i] - vn * n[i]);
                        match (l.surface, meridian) {
                            (Surface::Wall(s), Some(m)) => {
                                Phase::Wall(t, from_space(&m, s, &q, &u3, &s2))
                            }
                            _ => Phase::Bottom(
                                t,
                                Some([q[0], q[1], u3[0], u3[1], s2[0], s2[1], s2[2]]),
                            ),
                        }
                    }
                }
            },
        };
    }
}

/// [`residence`] in `f64`, compiled here: a generic function is compiled (monomorphised) in the
/// crate that calls it, so a host crate built without optimisation (`cargo test`) would run its
/// own unoptimised copy; this one is built with model-core's optimisation (the workspace's
/// `profile.dev.package.model-core`), several times faster in test builds. The PC's callers
/// that run many releases (the fit, the simulated rig) use it.
pub fn residence_f64(
    sc: &RollingScene<f64>,
    shape: &BowlShape<f64>,
    beta_rad: f64,
    method: RollingMethod<f64>,
    limits: SystemLimits<f64>,
) -> Result<BowlReport<f64>, BowlError> {
    residence(sc, shape, beta_rad, method, limits)
}

/// The impact of a landing. In a sharp corner (`F <= a`) the granule lands on the stand-in
/// fillet, whose normal turns from the bottom's to the wall's; the corner it stands in for has
/// only those two, so the impact is on the wall (if the granule moves into it), then on the
/// bottom (if it then moves into that), until it moves into neither. On the stand-in's own
/// normal a granule flying level into a vertical wall's corner at 1.05 m/s went back up the
/// wall at 0.49 m/s (the normal 30 deg from level where it landed: a ramp) and climbed a 32 mm
/// wall that MuJoCo holds it in (the held-out sweep's scene 7, docs/model.md §10); now it
/// comes back level at `e` times its speed into the wall.
fn landing_impact<T: Real>(
    sc: &RollingScene<T>,
    shape: &BowlShape<T>,
    meridian: Option<&wall::Meridian<T>>,
    l: &flight::Landing<T>,
) -> ([T; 3], [T; 3], T) {
    let e = shape.restitution;
    let (Surface::Wall(s), Some(m)) = (l.surface, meridian) else {
        return impact(sc, e, l.u_m_s, l.s_m_s, l.normal);
    };
    if !shape.sharp_corner(sc) || s >= m.arc_radius_m * shape.wall_angle_rad {
        return impact(sc, e, l.u_m_s, l.s_m_s, l.normal);
    }
    let q = l.q_m;
    let rho = (q[0] * q[0] + q[1] * q[1]).sqrt().max(T::EPSILON);
    let (sa, ca) = (shape.wall_angle_rad.sin(), shape.wall_angle_rad.cos());
    let wall = [-sa * q[0] / rho, -sa * q[1] / rho, ca];
    let bottom = [T::ZERO, T::ZERO, T::ONE];
    let (mut u, mut sp, mut rebound) = (l.u_m_s, l.s_m_s, T::ZERO);
    // Each impact leaves the granule moving out of its surface; one into the other surface
    // follows (a wedge's sequence ends: each one takes a share `1 - e` or more of the speed
    // into the surface). Four rounds are plenty at any wall angle the model takes.
    for _ in 0..4 {
        let mut hit = false;
        for n in [wall, bottom] {
            if u[0] * n[0] + u[1] * n[1] + u[2] * n[2] < T::ZERO {
                let (u2, s2, r) = impact(sc, e, u, sp, n);
                (u, sp, rebound, hit) = (u2, s2, rebound.max(r), true);
            }
        }
        if !hit {
            break;
        }
    }
    (u, sp, rebound)
}

/// A few roundings, relative: how far past the seam between the bottom and the fillet a
/// granule handed from one to the other is placed.
const SEAM: f64 = 4.0 * f64::EPSILON;

/// A wall state at the fillet's start (`s` = 0) moved a few roundings of the rim onto the
/// fillet. At `s` = 0 exactly the wall's back-onto-the-bottom event is already at zero, and so
/// is, to rounding, the bottom's rim event where the granule comes back: a step of either
/// that ends past any event (a slip reversing) is then located at its start. A granule at the
/// seam moving inward went from the bottom to the wall and back at one instant, one step each,
/// without end (the held-out grid's filleted corner at 20 deg, 0.8 rad/s, mu_s 0.3, rtol 1e-6:
/// 2 000 000 steps at t = 0.3175 s; docs/model.md §12); the stall watch, one per stay, did not
/// see it.
fn just_onto_wall<T: Real>(sc: &RollingScene<T>, mut y: WallState<T>) -> WallState<T> {
    y[0] = y[0].max(T::from_f64(SEAM) * sc.rim_radius_m);
    y
}

/// A bottom state at the fillet's start moved a few roundings inside it (see
/// [`just_onto_wall`]).
fn just_onto_bottom<T: Real>(mut y: SlideState<T>) -> SlideState<T> {
    let k = T::ONE - T::from_f64(SEAM);
    y[0] *= k;
    y[1] *= k;
    y
}

/// Where a release is between its stays.
enum Phase<T> {
    /// On the bottom from this time and state (`None`: the release itself).
    Bottom(T, Option<SlideState<T>>),
    /// On the fillet or the wall from this time and state.
    Wall(T, WallState<T>),
    /// In flight.
    Flight(Flight<T>),
}

#[cfg(test)]
mod corner_tests;
#[cfg(test)]
mod flight_tests;
#[cfg(test)]
mod incline_tests;
#[cfg(test)]
mod order_tests;
#[cfg(test)]
mod stall_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod wall_rest_tests;
