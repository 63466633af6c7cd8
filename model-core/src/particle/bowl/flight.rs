//! The granule in flight (issue 30, docs/model.md §10): once the normal force reaches zero it
//! leaves the surface and flies, ballistic in the inertial frame (gravity alone, no friction,
//! its spin kept), until it meets the bowl's surface again (bottom, fillet, wall or the lip's
//! edge) or its centre passes over the lip. The arc is in closed form,
//! `X(t) = X0 + V0 (t - t0) - g (t - t0)^2 / 2 e_Z`, and the bowl's pose at `t` is the rig's
//! two rotations about the precessing rod, so no step is taken: the landing and the exit are
//! roots in time of the gap to the surface and of the lip's margin along that arc, bracketed
//! on a fine scan and located by bisection to the last rounding.
//!
//! **Frames.** The bowl frame of `rolling::equations` (its `Omega`, `alpha`, `gB`, `A_O`) is
//! `R(t) = Rz(w1 t) Ry(-th) Rz(w2 t)` about the inertial frame (`Z` up), its origin (the
//! bottom's centre) at `O(t) = -L (cos w1 t, sin w1 t, 0)`: `R^T e_Z` is `-gB/g`,
//! `w1 R^T e_Z + w2 e3` is `Omega` and `R^T dO^2/dt^2` is `A_O` (a test integrates the
//! bowl-frame equations of a free particle and meets this arc to 1e-9).
//!
//! **Impact** (a landing, and a sharp flared corner): the normal velocity `v_n` is reversed and
//! scaled by the restitution `e`; the normal impulse `(1 + e) |v_n|` per unit mass bounds the
//! tangential one by Coulomb, `|J_t| <= mu_s (1 + e) |v_n|`. A tangential impulse changes the
//! contact point's slip by `J_t / (m (1 - k2))`, so the slip stops (the granule rolls on) when
//! `(1 - k2) |v_c| <= mu_s (1 + e) |v_n|`, else `J_t` opposes it at its bound; the spin takes
//! `ds = -(k2 / (1 - k2)) n x J_t` (as the sliding equations' torque). A rebound slower than a
//! rest speed stays on the surface (no endless bounce sequence).

use super::super::rolling::RollingScene;
use super::super::rolling::equations::cross;
use super::wall::Meridian;
use crate::Real;

/// Scan step along the arc, in units of the shortest of the scene's times (`sqrt(R/g)`,
/// `1/|Omega|`, `R/|V|`): a gap that dips below zero and back within less than this is
/// grazed, not met.
const SCAN: f64 = 2e-3;

/// Bisection steps: each halves the bracket, so 80 reach the last rounding of any horizon.
const BISECT: u32 = 80;

/// Below this rebound speed off a surface, in units of `sqrt(g R)`, the granule stays on it.
pub const REST_SPEED: f64 = 1e-3;

/// A flight: where and how fast the centre was at `t0`, in the inertial frame, and the
/// granule's absolute angular velocity times its radius (constant in flight), inertial.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flight<T> {
    /// Start, s.
    pub t0_s: T,
    /// Centre at the start, inertial, m.
    pub position_m: [T; 3],
    /// Its velocity, inertial, m/s.
    pub velocity_m_s: [T; 3],
    /// `a w` with `w` the absolute angular velocity, inertial, m/s.
    pub spin_m_s: [T; 3],
}

/// Where a flying granule meets the bowl.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Surface<T> {
    /// The flat bottom.
    Bottom,
    /// The fillet, the wall or the lip's edge, at this arc length of the centre's meridian, m.
    Wall(T),
}

/// The granule where a flight ends on the surface, in the bowl frame: centre `q`, its velocity
/// `u` relative to the bowl, spin `s = a w` relative to the bowl, the surface's unit normal
/// `n` towards the centre there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landing<T> {
    /// Time, s.
    pub t_s: T,
    /// Which surface.
    pub surface: Surface<T>,
    /// Centre, m.
    pub q_m: [T; 3],
    /// Velocity relative to the bowl, m/s.
    pub u_m_s: [T; 3],
    /// Spin relative to the bowl times `a`, m/s.
    pub s_m_s: [T; 3],
    /// Unit normal of the surface towards the centre.
    pub normal: [T; 3],
}

/// How a flight ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FlightEnd<T> {
    /// It met the surface.
    Lands(Landing<T>),
    /// Its centre passed over the lip (over the rim, with no wall) at this time, with this
    /// speed relative to the bowl, m/s.
    Exits(T, T),
    /// Still flying at the horizon.
    Horizon,
}

type Mat<T> = [[T; 3]; 3];

fn mul<T: Real>(a: &Mat<T>, b: &Mat<T>) -> Mat<T> {
    core::array::from_fn(|i| {
        core::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
    })
}

fn apply<T: Real>(a: &Mat<T>, v: &[T; 3]) -> [T; 3] {
    core::array::from_fn(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

fn apply_t<T: Real>(a: &Mat<T>, v: &[T; 3]) -> [T; 3] {
    core::array::from_fn(|i| a[0][i] * v[0] + a[1][i] * v[1] + a[2][i] * v[2])
}

fn dot<T: Real>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn rz<T: Real>(angle: T) -> Mat<T> {
    let (s, c) = (angle.sin(), angle.cos());
    [
        [c, -s, T::ZERO],
        [s, c, T::ZERO],
        [T::ZERO, T::ZERO, T::ONE],
    ]
}

/// The bowl frame's orientation at `t`: its axes' inertial components in its columns.
pub fn rotation<T: Real>(sc: &RollingScene<T>, t: T) -> Mat<T> {
    let (s, c) = (sc.axes_angle_rad.sin(), sc.axes_angle_rad.cos());
    let tilt = [
        [c, T::ZERO, -s],
        [T::ZERO, T::ONE, T::ZERO],
        [s, T::ZERO, c],
    ];
    mul(
        &mul(&rz(sc.precession_rad_s * t), &tilt),
        &rz(sc.spin_rad_s * t),
    )
}

/// The bowl frame's angular velocity in its own components (`rolling::equations`' `Omega`).
fn omega<T: Real>(sc: &RollingScene<T>, t: T) -> [T; 3] {
    let psi = sc.spin_rad_s * t;
    let (st, ct) = (sc.axes_angle_rad.sin(), sc.axes_angle_rad.cos());
    let w1 = sc.precession_rad_s;
    [
        w1 * st * psi.cos(),
        -w1 * st * psi.sin(),
        w1 * ct + sc.spin_rad_s,
    ]
}

/// The bowl's origin and its velocity at `t`, inertial.
fn origin<T: Real>(sc: &RollingScene<T>, t: T) -> ([T; 3], [T; 3]) {
    let w1 = sc.precession_rad_s;
    let l = sc.rod_length_m;
    let (s, c) = ((w1 * t).sin(), (w1 * t).cos());
    (
        [-l * c, -l * s, T::ZERO],
        [l * w1 * s, -l * w1 * c, T::ZERO],
    )
}

/// A flight from a bowl-frame state at `t`: centre `q`, velocity `u` and spin `s` relative to
/// the bowl.
pub fn launch<T: Real>(sc: &RollingScene<T>, t: T, q: [T; 3], u: [T; 3], s: [T; 3]) -> Flight<T> {
    let r = rotation(sc, t);
    let (o, od) = origin(sc, t);
    let om = omega(sc, t);
    let oq = cross(&om, &q);
    let rq = apply(&r, &q);
    let v = apply(&r, &core::array::from_fn(|i| u[i] + oq[i]));
    let a = sc.particle_radius_m;
    let w = apply(&r, &core::array::from_fn(|i| s[i] + a * om[i]));
    Flight {
        t0_s: t,
        position_m: core::array::from_fn(|i| o[i] + rq[i]),
        velocity_m_s: core::array::from_fn(|i| od[i] + v[i]),
        spin_m_s: w,
    }
}

/// The flight's centre at `t` in the bowl frame: `(q, u, s)` as [`launch`] takes them.
pub fn state_at<T: Real>(sc: &RollingScene<T>, f: &Flight<T>, t: T) -> [[T; 3]; 3] {
    let tau = t - f.t0_s;
    let g = sc.g_m_s2;
    let mut x: [T; 3] = core::array::from_fn(|i| f.position_m[i] + f.velocity_m_s[i] * tau);
    x[2] -= T::HALF * g * tau * tau;
    let mut v = f.velocity_m_s;
    v[2] -= g * tau;
    let r = rotation(sc, t);
    let (o, od) = origin(sc, t);
    let q = apply_t(&r, &core::array::from_fn(|i| x[i] - o[i]));
    let om = omega(sc, t);
    let oq = cross(&om, &q);
    let vb = apply_t(&r, &core::array::from_fn(|i| v[i] - od[i]));
    let u = core::array::from_fn(|i| vb[i] - oq[i]);
    let wb = apply_t(&r, &f.spin_m_s);
    let a = sc.particle_radius_m;
    let s = core::array::from_fn(|i| wb[i] - a * om[i]);
    [q, u, s]
}

/// The centre's signed distance to the surface its centre may not cross (the bowl's surface
/// offset by the granule's radius), positive inside, with the piece it is nearest; `None`
/// for the meridian: a bare rim (the flat bottom out to `R`).
pub fn gap<T: Real>(sc: &RollingScene<T>, m: Option<&Meridian<T>>, q: &[T; 3]) -> (T, Surface<T>) {
    let rho = (q[0] * q[0] + q[1] * q[1]).sqrt();
    let z = q[2];
    let a = sc.particle_radius_m;
    let Some(m) = m else {
        return (z - a, Surface::Bottom);
    };
    // The region the centre may take is bounded by the bottom's line, the fillet's arc and
    // the offset cone up to the lip's edge, then the circle of radius `a` about the edge.
    // Each full line bounds the whole region below the edge, so the distance is the least of
    // the pieces' (an arc's only where the point faces it).
    let mut best = (z - m.z0_m, Surface::Bottom);
    let rc = m.arc_radius_m;
    let alpha = m.alpha_rad;
    let (sa, ca) = (alpha.sin(), alpha.cos());
    let centre = [m.rho_b_m, m.z0_m + rc];
    let d = [rho - centre[0], z - centre[1]];
    let dl = (d[0] * d[0] + d[1] * d[1]).sqrt();
    if d[0] >= T::ZERO && dl > T::ZERO {
        let th = (-d[1] / dl).max(-T::ONE).min(T::ONE).acos();
        if th <= alpha && rc - dl < best.0 {
            best = (rc - dl, Surface::Wall(rc * th));
        }
    }
    let arc_end = [m.rho_b_m + rc * sa, m.z0_m + rc * (T::ONE - ca)];
    let rel = [rho - arc_end[0], z - arc_end[1]];
    let s_c = rc * alpha + rel[0] * ca + rel[1] * sa;
    if s_c <= m.top_s {
        let dc = -rel[0] * sa + rel[1] * ca;
        if dc < best.0 {
            best = (dc, Surface::Wall(s_c.max(rc * alpha)));
        }
    } else {
        // Above the wall's top: the lip's edge, a circle of radius `pivot` about it.
        let pv = m.pivot_m;
        let top = m.at(m.top_s).pos;
        let edge = [top[0] + pv * sa, top[1] - pv * ca];
        let e = [rho - edge[0], z - edge[1]];
        let el = (e[0] * e[0] + e[1] * e[1]).sqrt();
        let de = el - pv;
        if de < best.0 {
            // The tangent's angle `th` on the pivot: (-sin th, cos th) = e / |e|.
            let ct = if el > T::ZERO { e[1] / el } else { T::ONE };
            let mut th = ct.max(-T::ONE).min(T::ONE).acos();
            if e[0] > T::ZERO {
                th = -th;
            }
            best = (de, Surface::Wall(m.top_s + (alpha - th).max(T::ZERO) * pv));
        }
    }
    best
}

/// How far the centre is past the lip's radius (the rim's, with no wall), m: it has left once
/// this is positive.
pub fn past_lip<T: Real>(sc: &RollingScene<T>, m: Option<&Meridian<T>>, q: &[T; 3]) -> T {
    let rho = (q[0] * q[0] + q[1] * q[1]).sqrt();
    rho - m.map_or(sc.rim_radius_m, |m| m.lip_m)
}

/// The unit normal towards the centre of the surface at `surface`, for a centre at `q`.
pub fn normal_at<T: Real>(m: Option<&Meridian<T>>, surface: Surface<T>, q: &[T; 3]) -> [T; 3] {
    match (surface, m) {
        (Surface::Wall(s), Some(m)) => {
            let rho = (q[0] * q[0] + q[1] * q[1]).sqrt().max(T::EPSILON);
            let (ex, ey) = (q[0] / rho, q[1] / rho);
            let [rp, zp] = m.at(s).tangent;
            [-zp * ex, -zp * ey, rp]
        }
        _ => [T::ZERO, T::ZERO, T::ONE],
    }
}

/// Follows the flight until it lands, its centre passes the lip, or `horizon_s`.
pub fn fly<T: Real>(
    sc: &RollingScene<T>,
    m: Option<&Meridian<T>>,
    f: &Flight<T>,
    horizon_s: T,
) -> FlightEnd<T> {
    let rim = sc.rim_radius_m;
    let speed = dot(&f.velocity_m_s, &f.velocity_m_s).sqrt();
    let om = omega(sc, f.t0_s);
    let spin = dot(&om, &om).sqrt() + sc.precession_rad_s.abs();
    // The shortest of the scene's times: the fall over the rim, a turn, a crossing.
    let times = [
        (rim / sc.g_m_s2.max(T::EPSILON)).sqrt(),
        T::ONE / spin.max(T::EPSILON),
        rim / speed.max(T::EPSILON),
    ];
    let h = T::from_f64(SCAN) * times[0].min(times[1]).min(times[2]);
    let events = |t: T| {
        let [q, _, _] = state_at(sc, f, t);
        (gap(sc, m, &q).0, past_lip(sc, m, &q))
    };
    // The gap starts at zero (a lift-off where `N` = 0, or a rebound): the landing event is
    // armed once the granule is clearly off the surface, so the start is not met again.
    let clear = T::from_f64(1e-12) * rim;
    let mut armed = false;
    let mut t_prev = f.t0_s;
    if events(f.t0_s).0 > clear {
        armed = true;
    }
    let max_scan = 10_000_000u32;
    for _ in 0..max_scan {
        if t_prev >= horizon_s {
            return FlightEnd::Horizon;
        }
        let t = (t_prev + h).min(horizon_s);
        let now = events(t);
        let exits = now.1 > T::ZERO;
        let lands = armed && now.0 <= T::ZERO;
        // A granule that sinks into the surface before it is clear of it never left it:
        // it lands where it started (the contact takes over again).
        let sank = !armed && now.0 < -T::from_f64(1e-9) * rim;
        if exits || lands || sank {
            let t_exit = exits.then(|| locate(t_prev, t, |t| events(t).1));
            let t_land = if lands {
                Some(locate(t_prev, t, |t| events(t).0))
            } else if sank {
                Some(sinks_at(t_prev, t, |t| events(t).0))
            } else {
                None
            };
            return match (t_exit, t_land) {
                (Some(te), tl) if tl.is_none_or(|tl| te <= tl) => {
                    let [_, u, _] = state_at(sc, f, te);
                    FlightEnd::Exits(te, dot(&u, &u).sqrt())
                }
                (_, Some(tl)) => FlightEnd::Lands(landing(sc, m, f, tl)),
                _ => FlightEnd::Horizon,
            };
        }
        if now.0 > clear {
            armed = true;
        }
        t_prev = t;
    }
    FlightEnd::Horizon
}

/// Where a flight that never cleared the surface (its gap `g` at most a rounding at `lo`,
/// below zero at `hi`) sinks into it: the last instant of its gap above zero, found by
/// bisection as if `lo` were above the surface. A lift-off that grazes the surface (at a lip's
/// edge, where the normal force jumps by `|u|^2 / a` and the pivot leaves it a hair below
/// zero) rises less than the scan's first step can see and meets the surface again within
/// it: landed at its start, it lifted off there again at once, without end (a 57 deg wall at
/// 16 deg tilt, 3.2 and -2.2 rad/s: 50 000 flights at 0.4438 s until the cap, docs/model.md
/// §10); landed where it comes back, the contact takes over there. A gap below zero at every
/// instant after `lo` gives `lo`, as before.
fn sinks_at<T: Real>(lo: T, hi: T, g: impl Fn(T) -> T) -> T {
    let (mut a, mut b) = (lo, hi);
    for _ in 0..BISECT {
        let mid = a + (b - a) * T::HALF;
        if mid <= a || mid >= b {
            break;
        }
        if g(mid) > T::ZERO {
            a = mid;
        } else {
            b = mid;
        }
    }
    if g(b) > T::ZERO { b } else { a }
}

/// Where `g` changes sign between `lo` and `hi` (bisection to the last rounding): the first
/// instant on `hi`'s side.
fn locate<T: Real>(lo: T, hi: T, g: impl Fn(T) -> T) -> T {
    let (mut a, mut b) = (lo, hi);
    let ga = g(a);
    for _ in 0..BISECT {
        let mid = a + (b - a) * T::HALF;
        if mid <= a || mid >= b {
            break;
        }
        let gm = g(mid);
        if (gm > T::ZERO) == (ga > T::ZERO) {
            a = mid;
        } else {
            b = mid;
        }
    }
    b
}

/// The granule where the flight meets the surface at `t`.
fn landing<T: Real>(
    sc: &RollingScene<T>,
    m: Option<&Meridian<T>>,
    f: &Flight<T>,
    t: T,
) -> Landing<T> {
    let [q, u, s] = state_at(sc, f, t);
    let surface = gap(sc, m, &q).1;
    Landing {
        t_s: t,
        surface,
        q_m: q,
        u_m_s: u,
        s_m_s: s,
        normal: normal_at(m, surface, &q),
    }
}

/// The impact on a surface of unit normal `n` (towards the centre): the velocity `u` and spin
/// `s` (relative to the bowl, `s = a w`) after it, and the normal speed it rebounds with
/// (`e |v_n|`, 0 if it was not moving into the surface).
pub fn impact<T: Real>(
    sc: &RollingScene<T>,
    restitution: T,
    u: [T; 3],
    s: [T; 3],
    n: [T; 3],
) -> ([T; 3], [T; 3], T) {
    let vn = dot(&u, &n);
    if vn >= T::ZERO {
        return (u, s, T::ZERO);
    }
    let jn = -(T::ONE + restitution) * vn;
    let sn = cross(&s, &n);
    let slip: [T; 3] = core::array::from_fn(|i| u[i] - sn[i]);
    let sl_n = dot(&slip, &n);
    let slip_t: [T; 3] = core::array::from_fn(|i| slip[i] - sl_n * n[i]);
    let sl = dot(&slip_t, &slip_t).sqrt();
    let k2 = sc.k2;
    let one_m = T::ONE - k2;
    let jt: [T; 3] = if one_m * sl <= sc.sliding_friction * jn {
        core::array::from_fn(|i| -one_m * slip_t[i])
    } else {
        let k = sc.sliding_friction * jn / sl;
        core::array::from_fn(|i| -k * slip_t[i])
    };
    let u2: [T; 3] = core::array::from_fn(|i| u[i] + jn * n[i] + jt[i]);
    let nj = cross(&n, &jt);
    let ratio = k2 / one_m;
    let s2: [T; 3] = core::array::from_fn(|i| s[i] - ratio * nj[i]);
    (u2, s2, -restitution * vn)
}
