//! The granule on the bowl's wall: a sphere rolling or sliding on a surface of revolution about
//! the bowl's axis, in the tilted, precessing bowl frame (docs/model.md §10). The paper has no
//! wall (its model ends at the rim radius R on a flat bottom); a real bowl's wall decides
//! whether and when the granule leaves.
//!
//! **Geometry.** The centre of a sphere of radius `a` touching the surface runs on the surface
//! offset by `a`; for the bowl (flat bottom, a fillet of radius `F` into a cone at `alpha` from
//! the bottom plane) the centre's meridian, by arc length `s` from where the fillet starts
//! (radius `rho_b = R - F tan(alpha/2)`), is an arc of radius `F - a` about the fillet's centre
//! turning by `alpha`, then a straight line at `alpha` (the cone offset by `a`) up to where the
//! contact reaches the wall's top edge, then an arc of radius `a` about that edge (the granule
//! pivots over the lip); it has left when its centre passes the lip radius `R + H cot alpha`,
//! i.e. is over the edge. A granule whose normal force vanishes on that pivot flies off the
//! lip outwards: that counts as leaving there.
//!
//! **Dynamics** (one set for every surface; on the flat bottom it is [`super::super::rolling`]'s
//! equations, a test holds them equal there). Centre `q`, its velocity `u` relative to the bowl,
//! `n` the surface normal towards the centre, `s = a w` the spin relative to the bowl:
//!
//! ```text
//! b      = gB - A_O - alpha x q - Omega x (Omega x q) - 2 Omega x u     (per unit mass)
//! N/m    = -u . dn/dt - b . n                     keeps the centre on its surface
//! c      = -a alpha - Omega x s
//! roll:  f/m = (1 - k2) (-b_t + P_t(c x n + s x dn/dt)) - k2 mu_r (N/m) u/|u|
//!        (d/dt of the no-slip condition u = s x n; the resistance is a torque mu_r a N)
//! slide: f/m = -mu_s (N/m) v_c/|v_c|,  v_c = u - s x n
//! du/dt = b + (N/m) n + f/m;   ds/dt = -(k2/(1 - k2)) n x (f/m + [roll] mu_r (N/m) u/|u|) + c
//! ```
//!
//! State `[s, ex, ey, sdot, phidot, sx, sy, sz]`: `(ex, ey)` is the horizontal unit vector
//! from the axis to the centre (no angle, so no trigonometry in the right-hand side), with
//! `d(ex, ey)/dt = phidot (-ey, ex)`; `s`'s rate is `u . T` with `T` the meridian's tangent.

use super::super::rolling::RollingScene;
use super::super::rolling::equations::{AT_REST_M_S, cross, frame};
use super::super::rolling::slide::friction_direction;
use crate::Real;

/// The wall state `[s, ex, ey, sdot, phidot, sx, sy, sz]`.
pub type WallState<T> = [T; 8];

/// The centre's meridian on the wall: a fillet arc of radius `rc = F - a` turning by
/// `alpha`, then the offset cone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Meridian<T> {
    /// Radius where the bottom ends and the fillet starts, m.
    pub rho_b_m: T,
    /// Height of the centre on the bottom (`a`), m.
    pub z0_m: T,
    /// Radius of the centre's arc, `F - a`, m.
    pub arc_radius_m: T,
    /// The wall's angle from the bottom plane, rad.
    pub alpha_rad: T,
    /// The lip radius the centre must pass to leave, m.
    pub lip_m: T,
    /// Arc length where the contact reaches the lip's edge (the wall's top), m: beyond it the
    /// granule pivots about the edge, its centre on a circle of radius `pivot_m` about it.
    pub top_s: T,
    /// The pivot's radius (the granule's, at least a micrometre of the rim so that a point
    /// granule still has a finite curvature there), m.
    pub pivot_m: T,
    /// Which piece [`Meridian::at`] follows: all of them ([`Piece::Whole`], as built), or one
    /// continued past its ends ([`Meridian::on_piece`]).
    pub piece: Piece,
}

/// A piece of the centre's meridian on the wall. The path's curvature jumps where they meet
/// (from `1 / (F - a)` to 0 at the fillet's end, from 0 to `-1 / a` at the lip's edge): a
/// segment integrated across a meeting point would step over a jump of the normal force.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Piece {
    /// Every piece, each where it is (the bottom below `s` = 0).
    Whole,
    /// The fillet's arc, continued past both its ends.
    Fillet,
    /// The cone, continued past both its ends.
    Cone,
    /// The pivot about the lip's edge, continued past both its ends.
    Pivot,
}

/// A point of the meridian: `(rho, z)`, its unit tangent `(rho', z')` and its derivative
/// `(rho'', z'')` by arc length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point<T> {
    /// Radius and height, m.
    pub pos: [T; 2],
    /// Unit tangent.
    pub tangent: [T; 2],
    /// Curvature vector, 1/m.
    pub bend: [T; 2],
}

impl<T: Real> Meridian<T> {
    /// Arc length where the fillet's arc ends and the cone starts, m: the path's curvature
    /// jumps there from `1 / (F - a)` to 0.
    pub fn arc_length(&self) -> T {
        self.arc_radius_m * self.alpha_rad
    }

    /// The piece that arc length `s` is on (the fillet below its end, the cone up to the
    /// lip's edge, the pivot beyond it).
    pub fn piece_at(&self, s: T) -> Piece {
        if s < self.arc_length() {
            Piece::Fillet
        } else if s <= self.top_s {
            Piece::Cone
        } else {
            Piece::Pivot
        }
    }

    /// This meridian following only the piece that `s` is on, continued past its ends: a
    /// segment's right-hand side, smooth up to the event where the granule leaves the piece,
    /// so that the integrator's interpolant locates it (the stages of a step that crosses it
    /// are on the same piece as its start).
    pub fn on_piece(&self, s: T) -> Self {
        Self {
            piece: self.piece_at(s),
            ..*self
        }
    }

    /// The meridian at arc length `s` (below 0 the bottom continued, so that an integrator's
    /// stage just past the edge stays defined; on one piece, that piece continued).
    pub fn at(&self, s: T) -> Point<T> {
        let rc = self.arc_radius_m;
        let (sa, ca) = (self.alpha_rad.sin(), self.alpha_rad.cos());
        let len = self.arc_length();
        let arc = |s: T| {
            let th = s / rc;
            let (st, ct) = (th.sin(), th.cos());
            Point {
                pos: [self.rho_b_m + rc * st, self.z0_m + rc * (T::ONE - ct)],
                tangent: [ct, st],
                bend: [-st / rc, ct / rc],
            }
        };
        let cone = |s: T| Point {
            pos: [
                self.rho_b_m + rc * sa + (s - len) * ca,
                self.z0_m + rc * (T::ONE - ca) + (s - len) * sa,
            ],
            tangent: [ca, sa],
            bend: [T::ZERO, T::ZERO],
        };
        // Over the edge: the centre turns about it (convex), the tangent's angle falling from
        // alpha at 1/pivot per metre.
        let pivot = |s: T| {
            let pv = self.pivot_m;
            let th = self.alpha_rad - (s - self.top_s) / pv;
            let (st, ct) = (th.sin(), th.cos());
            let top = cone(self.top_s).pos;
            let edge = [top[0] + pv * sa, top[1] - pv * ca];
            Point {
                pos: [edge[0] - pv * st, edge[1] + pv * ct],
                tangent: [ct, st],
                bend: [st / pv, -ct / pv],
            }
        };
        match self.piece {
            Piece::Fillet => return arc(s),
            Piece::Cone => return cone(s),
            Piece::Pivot => return pivot(s),
            Piece::Whole => {}
        }
        if s <= T::ZERO {
            return Point {
                pos: [self.rho_b_m + s, self.z0_m],
                tangent: [T::ONE, T::ZERO],
                bend: [T::ZERO, T::ZERO],
            };
        }
        match self.piece_at(s) {
            Piece::Fillet => arc(s),
            Piece::Cone => cone(s),
            _ => pivot(s),
        }
    }

    /// Whether arc length `s` is on the pivot over the lip's edge.
    pub fn over_edge(&self, s: T) -> bool {
        s > self.top_s
    }
}

/// How the contact acts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact<T> {
    /// No slip; rolling resistance.
    Roll,
    /// Slipping; the friction opposes the slip, or this direction (a unit tangent vector)
    /// while the slip is below the rest threshold or has turned against it.
    Slide([T; 3]),
}

/// Everything the wall's equations give at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallForces<T> {
    /// The state's time derivative.
    pub derivative: WallState<T>,
    /// Normal force per unit mass, m/s^2.
    pub normal_m_s2: T,
    /// The friction rolling would need without resistance, per unit mass, m/s^2.
    pub needed_m_s2: [T; 3],
    /// The centre's acceleration along the surface rolling without resistance, m/s^2: at rest
    /// `k2 D` of the bottom's equations (the resistance holds it while `|D| <= mu_r N/m`,
    /// `super::wall_rest`).
    pub drive_m_s2: [T; 3],
    /// The contact point's slip velocity, m/s.
    pub slip_m_s: [T; 3],
    /// The centre's radius from the bowl's axis, m.
    pub rho_m: T,
    /// The centre's velocity relative to the bowl, m/s.
    pub velocity_m_s: [T; 3],
}

fn dot<T: Real>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn tangential<T: Real>(v: &[T; 3], n: &[T; 3]) -> [T; 3] {
    let k = dot(v, n);
    [v[0] - k * n[0], v[1] - k * n[1], v[2] - k * n[2]]
}

/// The right-hand side on the wall.
pub fn wall_forces<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    t: T,
    y: &WallState<T>,
    contact: Contact<T>,
) -> WallForces<T> {
    wall_forces_slaved(sc, m, t, y, contact, (T::ZERO, [T::ZERO; 3]))
}

/// [`wall_forces`] whose slide's friction, while the slip is at most `slaved_m_s` and grows,
/// opposes the slip's free acceleration (`rolling::slide::friction_direction`, as on the
/// bottom), and whose roll's resistance, once the velocity is at rest or has turned against
/// `last` (its unit direction at the last accepted step; zero: none), opposes `last`, as the
/// bottom's (`rolling::equations::forces_along`): the velocity passes smoothly through zero
/// and the rest is an event located on the step (`super::wall_rest`).
pub(crate) fn wall_forces_slaved<T: Real>(
    sc: &RollingScene<T>,
    m: &Meridian<T>,
    t: T,
    y: &WallState<T>,
    contact: Contact<T>,
    (slaved_m_s, last): (T, [T; 3]),
) -> WallForces<T> {
    let [s, ex0, ey0, sd, pd, sx, sy, sz] = *y;
    // The azimuth's unit vector, renormalised against the integrator's drift.
    let en = (ex0 * ex0 + ey0 * ey0).sqrt().max(T::EPSILON);
    let (ex, ey) = (ex0 / en, ey0 / en);
    let p = m.at(s);
    let [rho, z] = p.pos;
    let [rp, zp] = p.tangent;
    let [rpp, zpp] = p.bend;
    let e_phi = [-ey, ex, T::ZERO];
    let tan = [rp * ex, rp * ey, zp];
    let n = [-zp * ex, -zp * ey, rp];
    let q = [rho * ex, rho * ey, z];
    let u = [
        sd * tan[0] + rho * pd * e_phi[0],
        sd * tan[1] + rho * pd * e_phi[1],
        sd * tan[2],
    ];
    // dn/dt = (-z'' e_rho + rho'' e3) sdot - z' phidot e_phi.
    let ndot = [
        -zpp * sd * ex - zp * pd * e_phi[0],
        -zpp * sd * ey - zp * pd * e_phi[1],
        rpp * sd,
    ];
    let f = frame(sc, t);
    let o = f.omega;
    let oq = cross(&o, &q);
    let ooq = cross(&o, &oq);
    let aq = cross(&f.alpha, &q);
    let ou = cross(&o, &u);
    let b: [T; 3] =
        core::array::from_fn(|i| f.gravity[i] - f.carrier[i] - aq[i] - ooq[i] - T::TWO * ou[i]);
    let normal = -dot(&u, &ndot) - dot(&b, &n);
    let sig = [sx, sy, sz];
    let os = cross(&o, &sig);
    let a = sc.particle_radius_m;
    let c: [T; 3] = core::array::from_fn(|i| -a * f.alpha[i] - os[i]);
    let cn = cross(&c, &n);
    let snd = cross(&sig, &ndot);
    let q_t = tangential(&[cn[0] + snd[0], cn[1] + snd[1], cn[2] + snd[2]], &n);
    let b_t = tangential(&b, &n);
    let k2 = sc.k2;
    let one_m = T::ONE - k2;
    let needed: [T; 3] = core::array::from_fn(|i| one_m * (q_t[i] - b_t[i]));
    let sn = cross(&sig, &n);
    let slip: [T; 3] = core::array::from_fn(|i| u[i] - sn[i]);
    let n_pos = normal.max(T::ZERO);
    let speed = dot(&u, &u).sqrt();
    let drive: [T; 3] = core::array::from_fn(|i| needed[i] + b_t[i]);
    // The friction, and the resistance's part of the torque (rolling only).
    let (fm, resist) = match contact {
        Contact::Roll => {
            let r = sc.rolling_resistance * n_pos;
            let at_rest = speed <= T::from_f64(AT_REST_M_S);
            let an = dot(&drive, &drive).sqrt();
            let along = last != [T::ZERO; 3];
            let dir = if along && at_rest && an > k2 * r {
                // A roll from rest starts along the drive.
                [drive[0] / an, drive[1] / an, drive[2] / an]
            } else if along && (at_rest || dot(&u, &last) <= T::ZERO) {
                // One that the resistance stops goes through rest along its last direction.
                last
            } else if !at_rest {
                [u[0] / speed, u[1] / speed, u[2] / speed]
            } else if an <= k2 * r || an == T::ZERO {
                // At rest: the resistance opposes where it would start to move (and holds
                // it while it can: then nothing moves).
                [T::ZERO; 3]
            } else {
                [drive[0] / an, drive[1] / an, drive[2] / an]
            };
            let held = speed <= T::from_f64(AT_REST_M_S) && dir == [T::ZERO; 3];
            if held {
                // Held at rest: the contact gives exactly what keeps it there.
                (core::array::from_fn(|i| -b_t[i]), [T::ZERO; 3])
            } else {
                let fm: [T; 3] = core::array::from_fn(|i| needed[i] - k2 * r * dir[i]);
                (fm, core::array::from_fn(|i| r * dir[i]))
            }
        }
        Contact::Slide(d) => {
            let k = sc.sliding_friction * n_pos;
            // The free slip's acceleration is `-needed / (1 - k2)` (as on the bottom).
            let free: [T; 3] = core::array::from_fn(|i| -needed[i] / one_m);
            let dir = friction_direction(k2, slip, free, k, d, slaved_m_s);
            ([-k * dir[0], -k * dir[1], -k * dir[2]], [T::ZERO; 3])
        }
    };
    let acc: [T; 3] = core::array::from_fn(|i| b[i] + normal * n[i] + fm[i]);
    let torque_force: [T; 3] = core::array::from_fn(|i| fm[i] + resist[i]);
    let nf = cross(&n, &torque_force);
    let ratio = k2 / one_m;
    let dsig: [T; 3] = core::array::from_fn(|i| -ratio * nf[i] + c[i]);
    // Back to the coordinates: s'' = du/dt . T + rho rho' phidot^2, phi'' = (du/dt . e_phi -
    // 2 rho' sdot phidot) / rho.
    let sdd = dot(&acc, &tan) + rho * rp * pd * pd;
    let pdd = (dot(&acc, &e_phi) - T::TWO * rp * sd * pd) / rho;
    WallForces {
        derivative: [sd, -pd * ey, pd * ex, sdd, pdd, dsig[0], dsig[1], dsig[2]],
        normal_m_s2: normal,
        needed_m_s2: needed,
        drive_m_s2: drive,
        slip_m_s: slip,
        rho_m: rho,
        velocity_m_s: u,
    }
}

/// The contact point's slip `u - s x n` of a wall state, m/s (as [`wall_forces`] gives it,
/// without the forces): not linear in the state, since `u` and `n` turn with the position.
pub fn slip_of<T: Real>(m: &Meridian<T>, y: &WallState<T>) -> [T; 3] {
    let en = (y[1] * y[1] + y[2] * y[2]).sqrt().max(T::EPSILON);
    let (ex, ey) = (y[1] / en, y[2] / en);
    let p = m.at(y[0]);
    let rho = p.pos[0];
    let [rp, zp] = p.tangent;
    let (sd, pd) = (y[3], y[4]);
    let u = [
        sd * rp * ex - rho * pd * ey,
        sd * rp * ey + rho * pd * ex,
        sd * zp,
    ];
    let n = [-zp * ex, -zp * ey, rp];
    let sn = cross(&[y[5], y[6], y[7]], &n);
    core::array::from_fn(|i| u[i] - sn[i])
}

/// A state on the bottom `[x, y, ux, uy, sx, sy, sz]` at the fillet's start radius as a wall
/// state (`s = 0`).
pub fn onto_wall<T: Real>(m: &Meridian<T>, y: &[T; 7]) -> WallState<T> {
    let rho = (y[0] * y[0] + y[1] * y[1]).sqrt().max(T::EPSILON);
    let (ex, ey) = (y[0] / rho, y[1] / rho);
    let radial = y[2] * ex + y[3] * ey;
    let around = -y[2] * ey + y[3] * ex;
    [
        T::ZERO,
        ex,
        ey,
        radial,
        around / m.rho_b_m,
        y[4],
        y[5],
        y[6],
    ]
}

/// A wall state back at the fillet's start (`s = 0`) as a state on the bottom.
pub fn onto_bottom<T: Real>(m: &Meridian<T>, y: &WallState<T>) -> [T; 7] {
    let en = (y[1] * y[1] + y[2] * y[2]).sqrt().max(T::EPSILON);
    let (ex, ey) = (y[1] / en, y[2] / en);
    let rho = m.rho_b_m;
    let (sd, pd) = (y[3], y[4]);
    [
        rho * ex,
        rho * ey,
        sd * ex - rho * pd * ey,
        sd * ey + rho * pd * ex,
        y[5],
        y[6],
        y[7],
    ]
}

/// A wall state as the centre `q`, its velocity `u` relative to the bowl and the spin `s`
/// (the flight's terms).
pub fn to_space<T: Real>(m: &Meridian<T>, y: &WallState<T>) -> [[T; 3]; 3] {
    let en = (y[1] * y[1] + y[2] * y[2]).sqrt().max(T::EPSILON);
    let (ex, ey) = (y[1] / en, y[2] / en);
    let p = m.at(y[0]);
    let [rho, z] = p.pos;
    let [rp, zp] = p.tangent;
    let (sd, pd) = (y[3], y[4]);
    [
        [rho * ex, rho * ey, z],
        [
            sd * rp * ex - rho * pd * ey,
            sd * rp * ey + rho * pd * ex,
            sd * zp,
        ],
        [y[5], y[6], y[7]],
    ]
}

/// A centre `q` on the wall at arc length `s`, moving along it at `u` (relative to the bowl)
/// with the spin `sig`, as a wall state: the velocity's part along the normal is dropped.
pub fn from_space<T: Real>(
    m: &Meridian<T>,
    s: T,
    q: &[T; 3],
    u: &[T; 3],
    sig: &[T; 3],
) -> WallState<T> {
    let en = (q[0] * q[0] + q[1] * q[1]).sqrt().max(T::EPSILON);
    let (ex, ey) = (q[0] / en, q[1] / en);
    let p = m.at(s);
    let [rp, zp] = p.tangent;
    let rho = p.pos[0].max(T::EPSILON);
    let sd = u[0] * rp * ex + u[1] * rp * ey + u[2] * zp;
    let pd = (-u[0] * ey + u[1] * ex) / rho;
    [s, ex, ey, sd, pd, sig[0], sig[1], sig[2]]
}
