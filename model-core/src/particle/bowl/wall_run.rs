//! One stay on the wall: roll and slide segments (as on the bottom, `rolling::modes`) with
//! the wall's events, each located on the integrator's interpolant: back onto the bottom
//! (`s` = 0), over the lip (the centre's radius reaching the lip's), lift-off (`N` = 0), and the
//! contact's changes (rolling needing more than `mu_s N`; the slip ending), and the meridian's
//! seams where its curvature jumps (the fillet's end, the lip's edge): a segment follows the
//! piece it starts on, continued past its ends, so that no step straddles a jump of the normal
//! force. A roll that comes to rest where the resistance holds it is held, a segment of its own
//! (`wall_rest`).

use core::cell::Cell;

use super::wall::{
    Contact, Meridian, Piece, WallState, slip_of, to_space, wall_forces, wall_forces_slaved,
};
use super::wall_rest::{self, Let};
use crate::Real;
use crate::ode::system::{SystemError, SystemLimits};
use crate::particle::rolling::equations::AT_REST_M_S;
use crate::particle::rolling::modes::{
    Chatter, Mode, Settle, SlipOf, StallWatch, Stop, Tally, fired, follow_slip, scene_scales,
    segment, stuck_m_s,
};
use crate::particle::rolling::rest::{follow_velocity, start_speed_m_s, turned};
use crate::particle::rolling::{RollingError, RollingMethod, RollingScene};

/// How a stay on the wall ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WallEnd<T> {
    /// Back on the bottom at this time, in this wall state (`s` = 0).
    Bottom(T, WallState<T>),
    /// Over the lip at this time, at this speed relative to the bowl, m/s.
    Lip(T, T),
    /// The normal force reached zero at this time, in this wall state: it flies.
    LiftsOff(T, WallState<T>),
    /// Still on the wall at the horizon.
    Horizon,
}

/// What a stay cost and how it went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallStay<T> {
    /// How it ended.
    pub end: WallEnd<T>,
    /// Time rolling and sliding on the wall, changes of contact, cost.
    pub tally: Tally<T>,
    /// Where it was held at rest to the horizon (its arc length `s` along the meridian, m), if
    /// it was: the report says on the fillet or by the wall.
    pub held_at_s: Option<T>,
}

fn norm<T: Real>(v: &[T; 3]) -> T {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

#[allow(clippy::too_many_arguments)]
fn events<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    t: T,
    y: &WallState<T>,
    (contact, last): (Contact<T>, [T; 3]),
    (armed, fresh_end): (bool, T),
    refs: (T, T),
    below_edge: bool,
    on_fillet: bool,
) -> [T; 7] {
    let (reference, speed_ref) = refs;
    let f = wall_forces(sc, m, t, y, contact);
    let rim = sc.rim_radius_m;
    let switch = match contact {
        Contact::Roll => (norm(&f.needed_m_s2) - sc.sliding_friction * f.normal_m_s2) / reference,
        Contact::Slide(d) => {
            let s = f.slip_m_s;
            let reversed = -(s[0] * d[0] + s[1] * d[1] + s[2] * d[2]);
            // A slide that has not yet been above the stuck threshold ends where its slip has
            // turned against the friction by more than that threshold, not at its first
            // rounding: a slide restarted from no slip (`no_slip`, exact only to rounding on
            // the wall) has its slip at zero or a rounding against the friction, so the end
            // was already at zero at the segment's start, and a step that ended with the slip
            // reversed was located there: the stay restarted from the same state at the same
            // instant, one step each, without end (docs/model.md §12).
            let stuck = if armed {
                reversed.max(stuck_m_s(speed_ref) - norm(&s))
            } else {
                // (in a chatter, by more than the rest threshold: `Chatter`).
                reversed - fresh_end
            };
            stuck / speed_ref
        }
    };
    // Reaching the lip's edge (from the cone onto the pivot about it): the path's curvature
    // jumps from 0 to 1/a there, so the normal force jumps by `|u|^2 / a`; an event on the
    // smooth arc length, not on the force's jump, decides there whether it flies off the edge.
    // Back from the pivot onto the cone likewise.
    let edge = if below_edge {
        (y[0] - m.top_s) / rim
    } else {
        (m.top_s - y[0]) / rim
    };
    // The fillet's end (onto the cone, or back onto the fillet): the path's curvature jumps
    // there from `1 / (F - a)` to 0, and with it the normal force by `|u|^2 / (F - a)`; a fixed
    // step across it lost RK4's order (its error in T went as `h`, with where the seam fell in
    // the step), so each side is a segment of its own.
    let seam = (y[0] - m.arc_length()) / rim;
    // A roll's rest: its velocity turned against its direction at the last accepted step
    // (`super::wall_rest`; none without one).
    let rest = if matches!(contact, Contact::Roll) && last != [T::ZERO; 3] {
        turned(f.velocity_m_s, last) / speed_ref
    } else {
        -T::ONE
    };
    [
        -y[0] / rim,
        (f.rho_m - m.lip_m) / rim,
        -f.normal_m_s2 / reference,
        switch,
        edge,
        if on_fillet { seam } else { -seam },
        rest,
    ]
}

/// The contact a wall state starts in (`must_slide` as on the bottom), or `None` if `N <= 0`.
fn next_contact<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    t: T,
    y: &WallState<T>,
    must_slide: bool,
) -> Option<Contact<T>> {
    let f = wall_forces(sc, m, t, y, Contact::Roll);
    let slip = f.slip_m_s;
    let sl = norm(&slip);
    if sl > T::from_f64(AT_REST_M_S) {
        return Some(Contact::Slide([slip[0] / sl, slip[1] / sl, slip[2] / sl]));
    }
    if f.normal_m_s2 <= T::ZERO {
        return None;
    }
    let need = norm(&f.needed_m_s2);
    if (need <= sc.sliding_friction * f.normal_m_s2 && !must_slide) || need <= T::ZERO {
        return Some(Contact::Roll);
    }
    let nd = f.needed_m_s2;
    Some(Contact::Slide([
        -nd[0] / need,
        -nd[1] / need,
        -nd[2] / need,
    ]))
}

/// The direction a roll from `(t, y)` starts with as its last (`super::wall_rest`): the
/// velocity's, or at rest the drive's (where it would start), zero if there is none.
fn start_direction<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    t: T,
    y: &WallState<T>,
) -> [T; 3] {
    let u = to_space(m, y)[1];
    let speed = norm(&u);
    if speed > T::from_f64(AT_REST_M_S) {
        return u.map(|c| c / speed);
    }
    let d = wall_forces(sc, m, t, y, Contact::Roll).drive_m_s2;
    let dn = norm(&d);
    if dn > T::ZERO {
        d.map(|c| c / dn)
    } else {
        [T::ZERO; 3]
    }
}

/// Makes the slip of a wall state exactly zero (its spin's tangential part follows the
/// translation, `s x n = u`), keeping the spin about the normal.
fn no_slip<T: Real>(sc: &RollingScene<T>, m: &Meridian<T>, t: T, y: &WallState<T>) -> WallState<T> {
    let f = wall_forces(sc, m, t, y, Contact::Roll);
    let p = m.at(y[0]);
    let en = (y[1] * y[1] + y[2] * y[2]).sqrt().max(T::EPSILON);
    let (ex, ey) = (y[1] / en, y[2] / en);
    let n = [-p.tangent[1] * ex, -p.tangent[1] * ey, p.tangent[0]];
    let u = f.velocity_m_s;
    let sig = [y[5], y[6], y[7]];
    let along = sig[0] * n[0] + sig[1] * n[1] + sig[2] * n[2];
    // s = n x u + (s . n) n satisfies s x n = u for u tangential.
    let nu = [
        n[1] * u[2] - n[2] * u[1],
        n[2] * u[0] - n[0] * u[2],
        n[0] * u[1] - n[1] * u[0],
    ];
    let mut out = *y;
    for i in 0..3 {
        out[5 + i] = nu[i] + along * n[i];
    }
    out
}

/// Follows the granule on the wall from `(t0, y0)` until it leaves the wall. With
/// `stall_steps`, a stay that stalls gives up (`SystemError::Stalled`)
/// (`rolling::modes::StallWatch`, [`super::residence_or_stall`]).
#[allow(clippy::too_many_arguments)]
pub fn stay<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    t0: T,
    y0: WallState<T>,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
    max_switches: u32,
    stall_steps: Option<u32>,
) -> Result<WallStay<T>, RollingError> {
    let (refs, scales) = scene_scales(sc);
    // A growing slip below the velocities' absolute tolerance: its friction opposes its free
    // acceleration (`rolling::slide::friction_direction`, as on the bottom).
    let slaved = match method {
        RollingMethod::Dp54 { rtol } => rtol * scales.1,
        RollingMethod::Rk4 { .. } => T::ZERO,
    };
    let mut out = WallStay {
        end: WallEnd::Horizon,
        tally: Tally::new(),
        held_at_s: None,
    };
    let (mut t, mut y) = (t0, y0);
    let mut must_slide = false;
    let mut previous: Option<Mode> = None;
    // One watch over the whole stay (as the bottom's `run_from`), at the wall's own length: the
    // tightest of the bottom's radius, the fillet's arc and the pivot over the lip. Through a
    // fillet of `F - a` = 1.2 mm at 1 m/s the normal force is 50 g, and a slide starting there
    // from no slip takes steps of 7e-10 s (the explicit step's stability limit against the
    // friction's turning of the slip) for hundreds of steps before its slip grows: real
    // progress, which the bottom's scale (R over the scene's speed, 0.07 s) called a stall
    // (docs/model.md §10).
    let length = scales.0.min(m.arc_radius_m).min(m.pivot_m);
    let watch = StallWatch::new(stall_steps, (length, scales.1), t0, method);
    let mut chatter = Chatter::new();
    // The hold just ended where the drive began to exceed the resistance: the roll that follows
    // restarts from rest, a stretch of its own ([`start_speed_m_s`], as on the bottom).
    let mut restart = false;
    loop {
        let restarts = core::mem::take(&mut restart);
        let remaining = out.tally.remaining(limits, max_switches)?;
        let steps_before = out.tally.steps;
        let fresh_end = chatter.fresh_end_m_s(refs.1);
        let Some(contact) = next_contact(sc, m, t, &y, must_slide) else {
            out.end = WallEnd::LiftsOff(t, y);
            return Ok(out);
        };
        let rolling = matches!(contact, Contact::Roll);
        let mode = if rolling { Mode::Roll } else { Mode::Slide };
        out.tally.enter(&mut previous, mode);
        if rolling {
            y = no_slip(sc, m, t, &y);
        }
        let dir = Cell::new(match contact {
            Contact::Slide(d) => d,
            Contact::Roll => [T::ZERO; 3],
        });
        let armed = Cell::new(false);
        // The segment follows the piece of the meridian it starts on (continued past its
        // ends); where it leaves it is an event.
        let piece = m.piece_at(y[0]);
        let below_edge = piece != Piece::Pivot;
        let on_fillet = piece == Piece::Fillet;
        let mp = &m.on_piece(y[0]);
        let now = |d: [T; 3]| {
            if rolling {
                Contact::Roll
            } else {
                Contact::Slide(d)
            }
        };
        let settle = Settle::new(sc.k2);
        // A roll's velocity direction at its last accepted step: the resistance keeps it
        // through rest, where the rest event fires (`super::wall_rest`).
        let last = Cell::new(if rolling {
            start_direction(sc, mp, t, &y)
        } else {
            [T::ZERO; 3]
        });
        // A restart from a hold: up to its start speed, its velocity held to `rtol` of that
        // speed instead of the scene's (`rest::start_speed_m_s`).
        let start = (rolling && restarts).then(|| start_speed_m_s(sc));
        let Some((te, ye, settled)) = segment(
            &mut out.tally,
            mode,
            |t, y: &WallState<T>| {
                wall_forces_slaved(sc, mp, t, y, now(dir.get()), (slaved, last.get())).derivative
            },
            (t, y),
            method,
            start.map_or(scales, |speed| (scales.0, speed)),
            |t, y: &WallState<T>| {
                let e = events(
                    sc,
                    mp,
                    t,
                    y,
                    (now(dir.get()), last.get()),
                    (armed.get(), fresh_end),
                    refs,
                    below_edge,
                    on_fillet,
                );
                e.iter().fold(e[0], |a, b| a.max(*b))
            },
            |t, y: &WallState<T>| {
                watch.check(t)?;
                if rolling {
                    let u = to_space(mp, y)[1];
                    follow_velocity(u, &last);
                    return match start {
                        Some(s) if norm(&u) >= s => core::ops::ControlFlow::Break(Stop::Started),
                        _ => core::ops::ControlFlow::Continue(()),
                    };
                }
                let s = wall_forces(sc, mp, t, y, now(dir.get())).slip_m_s;
                follow_slip(&s, &dir, &armed, stuck_m_s(refs.1));
                settle.step(t, &s, || {
                    let f = wall_forces(sc, mp, t, &no_slip(sc, mp, t, y), Contact::Roll);
                    let limit = sc.sliding_friction * f.normal_m_s2;
                    (norm(&f.needed_m_s2) <= limit).then_some(limit)
                })
            },
            // A slide's slip held to its own tolerance, as on the bottom.
            (!rolling).then_some(SlipOf::OfState(&|y: &WallState<T>| slip_of(mp, y))),
            remaining,
        )?
        else {
            return Ok(out);
        };
        if watch.step(te).is_break() {
            return Err(RollingError::Integration(SystemError::Stalled));
        }
        if rolling && settled {
            // A restart from a hold under way: the roll goes on at the scene's tolerances.
            (t, y, must_slide) = (te, no_slip(sc, mp, te, &ye), false);
            continue;
        }
        let e = events(
            sc,
            mp,
            te,
            &ye,
            (now(dir.get()), last.get()),
            (armed.get(), fresh_end),
            refs,
            below_edge,
            on_fillet,
        );
        // A roll's state keeps its no-slip only to the integrator's error (the wall's state
        // carries the spin apart from the translation): made exact at the roll's end, so that
        // what comes next (the contact at a seam or the edge, the bottom's mode) is not decided
        // by that error against the rest threshold. With it a roll across the fillet's end at
        // RK4's step went on sliding for microseconds (its drift above `AT_REST_M_S`), by
        // more the longer the step: an extra change and an error in T of order `h`.
        let ye = if rolling {
            no_slip(sc, mp, te, &ye)
        } else {
            ye
        };
        // A settled slide ends as at its slip's end (a change of contact).
        let which = if settled { 3 } else { fired(&e) };
        chatter.after(
            out.tally.steps - steps_before,
            !rolling && which == 3 && !settle.left_rest(),
        );
        match which {
            0 => {
                let mut back = ye;
                back[0] = T::ZERO;
                out.end = WallEnd::Bottom(te, back);
                return Ok(out);
            }
            1 => {
                out.end = WallEnd::Lip(
                    te,
                    norm(&wall_forces(sc, m, te, &ye, now(dir.get())).velocity_m_s),
                );
                return Ok(out);
            }
            4 => {
                // At the edge: on, just onto the pivot; the next contact flies if the pivot
                // needs a pull (`N <= 0`), else it pivots on.
                must_slide = false;
                t = te;
                y = ye;
                let past = (m.top_s.abs() + m.pivot_m) * T::from_f64(4.0) * T::EPSILON;
                y[0] = if below_edge {
                    m.top_s + past
                } else {
                    m.top_s - past
                };
            }
            5 => {
                // Across the fillet's end: on in the same contact from just past it (the side
                // it is moving to), so that the next segment's seam event starts below zero.
                must_slide = false;
                t = te;
                y = ye;
                let past = (m.arc_length().abs() + m.pivot_m) * T::from_f64(4.0) * T::EPSILON;
                y[0] = if on_fillet {
                    m.arc_length() + past
                } else {
                    m.arc_length() - past
                };
            }
            2 => {
                // Airborne (from the wall, or from the lip's edge: the flight decides whether
                // it goes over or falls back in).
                out.end = WallEnd::LiftsOff(te, ye);
                return Ok(out);
            }
            6 => {
                // At rest: held there with no velocity at all, or rolling on.
                (t, y, must_slide) = (te, ye, false);
                let Some(rest) = wall_rest::held_at(sc, mp, te, &ye) else {
                    continue;
                };
                out.tally.enter(&mut previous, Mode::Held);
                let held = wall_rest::hold(sc, mp, te, &rest, limits.horizon_s, refs.0);
                out.tally.evaluations = out.tally.evaluations.saturating_add(held.evaluations);
                let Some((t1, y1, why)) = held.end else {
                    out.tally.spend(Mode::Held, limits.horizon_s - te);
                    out.held_at_s = Some(rest[0]);
                    return Ok(out);
                };
                out.tally.spend(Mode::Held, t1 - te);
                (t, y) = (t1, y1);
                match why {
                    Let::Rolls => restart = true,
                    Let::Slides => must_slide = true,
                    Let::LiftsOff => {
                        out.end = WallEnd::LiftsOff(t1, y1);
                        return Ok(out);
                    }
                }
            }
            _ => {
                must_slide = rolling;
                t = te;
                y = if rolling {
                    ye
                } else {
                    no_slip(sc, mp, te, &ye)
                };
            }
        }
    }
}
