//! The equations of motion of a sphere rolling without slip on the flat bottom of the tilted,
//! precessing bowl, in the bowl's frame (docs/model.md §9). Why not the paper's Eq. 5: a rolling
//! sphere's contact couples its radial and azimuthal motion (the gyroscopic term `(1 + k2) Oz`),
//! resistance acts against the actual velocity, and on the tilted rig gravity has an in-plane
//! part that is the largest force.
//!
//! Frame: origin at the centre of the bottom, `e1`, `e2` in its plane, `n = e3` the bowl's axis,
//! which precesses about the vertical at `w1` at the angle `th`; the bowl spins about `n` at
//! `w2`, `psi = w2 t`. State `[x, y, ux, uy, sig]`: the contact point, the centre's velocity
//! relative to the bowl, and `sig = a s` with `s` the sphere's spin about `n` relative to the bowl.
//!
//! ```text
//! Omega = (w1 sin th cos psi, -w1 sin th sin psi, w1 cos th + w2)
//! alpha = w1 w2 sin th (-sin psi, -cos psi, 0)
//! gB    = -g (sin th cos psi, -sin th sin psi, cos th)
//! A_O   = w1^2 L (cos th cos psi, -cos th sin psi, -sin th)
//! p = (x, y, a);  C = Omega (Omega . p) - |Omega|^2 p;  E = alpha x p
//! N/m = g cos th + A_Oz + E_z + C_z + 2 (Ox uy - Oy ux)
//! D   = (gB - A_O - E - C)_xy + ((1 - k2)/k2) [sig (Ox, Oy) - a (alpha_y, -alpha_x)]
//! du/dt   = k2 [D - mu_r (N/m) u/|u|] - (1 + k2) Oz (-uy, ux)
//! dsig/dt = -(Ox ux + Oy uy)
//! f_t/m = (A_O + E + C + 2 Omega x u + du/dt - gB)_xy   (the friction that keeps it rolling)
//! ```

use super::RollingScene;
use crate::Real;

/// Below this speed relative to the bowl, m/s, the granule counts as at rest: the resistance's
/// direction `u/|u|` is undefined there and the start from rest is stiff (eigenvalue about
/// `-k2 mu_r (N/m)/|u|`), so the direction is held on `D/|D|` instead. `T` moves by less than
/// 1e-10 s against a threshold 100 times smaller.
pub const AT_REST_M_S: f64 = 1e-7;

/// The state: `[x, y, ux, uy, sig]`, m and m/s.
pub type State<T> = [T; 5];

/// Everything the equations give at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Forces<T> {
    /// The state's time derivative.
    pub derivative: State<T>,
    /// Normal force per unit mass, m/s^2 (the granule lifts off where it is <= 0).
    pub normal_m_s2: T,
    /// In-plane friction force per unit mass needed to roll, `|f_t|/m`, m/s^2.
    pub friction_m_s2: T,
    /// That friction as a vector in the bottom's plane, `f_t/m`, m/s^2 (a granule that starts
    /// to slide slips against it).
    pub friction_xy_m_s2: [T; 2],
    /// At rest and held by the resistance: `|D| <= mu_r N/m`.
    pub held: bool,
}

/// Vectors of the bowl frame at time `t` (shared with the sliding granule's equations).
pub(crate) struct Frame<T> {
    /// The frame's angular velocity `Omega`, rad/s.
    pub(crate) omega: [T; 3],
    /// Its angular acceleration `alpha`, rad/s^2.
    pub(crate) alpha: [T; 3],
    /// Gravity `gB`, m/s^2.
    pub(crate) gravity: [T; 3],
    /// The bowl centre's acceleration `A_O`, m/s^2.
    pub(crate) carrier: [T; 3],
}

pub(crate) fn frame<T: Real>(s: &RollingScene<T>, t: T) -> Frame<T> {
    let psi = s.spin_rad_s * t;
    let (sp, cp) = (psi.sin(), psi.cos());
    let (st, ct) = (s.axes_angle_rad.sin(), s.axes_angle_rad.cos());
    let w1 = s.precession_rad_s;
    let w1l = w1 * w1 * s.rod_length_m;
    let g = s.g_m_s2;
    let aw = w1 * s.spin_rad_s * st;
    Frame {
        omega: [w1 * st * cp, -w1 * st * sp, w1 * ct + s.spin_rad_s],
        alpha: [-aw * sp, -aw * cp, T::ZERO],
        gravity: [-g * st * cp, g * st * sp, -g * ct],
        carrier: [w1l * ct * cp, -w1l * ct * sp, -w1l * st],
    }
}

/// The dot product of two vectors of any length (the rest's and the slip's directions, the
/// wall's normal).
pub(crate) fn dot<T: Real, const N: usize>(a: &[T; N], b: &[T; N]) -> T {
    a.iter().zip(b).fold(T::ZERO, |acc, (x, y)| acc + *x * *y)
}

pub(crate) fn cross<T: Real>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// What the frame does to a granule at the contact point `(x, y)` moving at `(ux, uy)` relative
/// to the bowl, whether it rolls or slides (the sliding equations share it): the frame at `t`,
/// `C = Omega (Omega . p) - |Omega|^2 p` and `E = alpha x p` at the centre `p = (x, y, a)`, and
/// the normal force per unit mass `N/m = g cos th + A_Oz + E_z + C_z + 2 (Ox uy - Oy ux)`, which
/// does not depend on the spin, so rolling and sliding have the same (docs/model.md §9).
pub(crate) fn at_contact<T: Real>(
    s: &RollingScene<T>,
    t: T,
    xy: [T; 2],
    u: [T; 2],
) -> (Frame<T>, [T; 3], [T; 3], T) {
    let f = frame(s, t);
    let o = f.omega;
    let p = [xy[0], xy[1], s.particle_radius_m];
    let o_dot_p = o[0] * p[0] + o[1] * p[1] + o[2] * p[2];
    let o2 = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
    let c = [
        o[0] * o_dot_p - o2 * p[0],
        o[1] * o_dot_p - o2 * p[1],
        o[2] * o_dot_p - o2 * p[2],
    ];
    let e = cross(&f.alpha, &p);
    let g_cos = -f.gravity[2];
    let normal = g_cos + f.carrier[2] + e[2] + c[2] + T::TWO * (o[0] * u[1] - o[1] * u[0]);
    (f, c, e, normal)
}

/// `D`, the in-plane drive of the rolling equations (m/s^2), and the rolling resistance's
/// largest force `mu_r N/m` at `(t, y)`, with the frame and `N/m` they came from.
fn drive<T: Real>(
    s: &RollingScene<T>,
    t: T,
    y: &State<T>,
) -> ([T; 2], T, Frame<T>, [T; 3], [T; 3], T) {
    let [x, yy, ux, uy, sig] = *y;
    let (f, c, e, normal) = at_contact(s, t, [x, yy], [ux, uy]);
    let o = f.omega;
    let a = s.particle_radius_m;
    let spin_coupling = (T::ONE - s.k2) / s.k2;
    let d = [
        f.gravity[0] - f.carrier[0] - e[0] - c[0] + spin_coupling * (sig * o[0] - a * f.alpha[1]),
        f.gravity[1] - f.carrier[1] - e[1] - c[1] + spin_coupling * (sig * o[1] + a * f.alpha[0]),
    ];
    let resistance = s.rolling_resistance * normal.max(T::ZERO);
    (d, resistance, f, c, e, normal)
}

/// How far the drive exceeds what the rolling resistance can hold of a granule at rest at
/// `(t, y)` (its velocity taken as zero), `|D| - mu_r N/m`, m/s^2: it stays at rest while this
/// is at most zero (the held segment of a run, `super::rest`).
pub(crate) fn rest_margin_m_s2<T: Real>(s: &RollingScene<T>, t: T, y: &State<T>) -> T {
    let (d, resistance, ..) = drive(s, t, &[y[0], y[1], T::ZERO, T::ZERO, y[4]]);
    (d[0] * d[0] + d[1] * d[1]).sqrt() - resistance
}

/// The direction a roll's resistance opposes at the start of a roll from `(t, y)` (`super::rest`):
/// the velocity's, or at rest `D/|D|` (where the granule starts), zero if there is no drive.
pub(crate) fn start_direction<T: Real>(s: &RollingScene<T>, t: T, y: &State<T>) -> [T; 2] {
    let speed = (y[2] * y[2] + y[3] * y[3]).sqrt();
    if speed > T::from_f64(AT_REST_M_S) {
        return [y[2] / speed, y[3] / speed];
    }
    let (d, ..) = drive(s, t, y);
    let d_norm = (d[0] * d[0] + d[1] * d[1]).sqrt();
    if d_norm > T::ZERO {
        [d[0] / d_norm, d[1] / d_norm]
    } else {
        [T::ZERO, T::ZERO]
    }
}

/// The right-hand side and the contact forces at `(t, y)`.
pub fn forces<T: Real>(s: &RollingScene<T>, t: T, y: &State<T>) -> Forces<T> {
    forces_with(s, t, y, None)
}

/// [`forces`] of a roll whose velocity had the unit direction `last` at its last accepted step
/// (`super::rest`): the resistance opposes the velocity while it goes along `last`, and `last`
/// itself once the velocity is at rest or has turned against it, so the right-hand side stays
/// smooth through the step in which the velocity reaches zero and the integrator's interpolant
/// locates that instant (as a slide's friction, `super::slide::slide_forces`).
pub(crate) fn forces_along<T: Real>(
    s: &RollingScene<T>,
    t: T,
    y: &State<T>,
    last: [T; 2],
) -> Forces<T> {
    forces_with(s, t, y, Some(last))
}

fn forces_with<T: Real>(
    s: &RollingScene<T>,
    t: T,
    y: &State<T>,
    last: Option<[T; 2]>,
) -> Forces<T> {
    let [_, _, ux, uy, _] = *y;
    let (d, resistance, f, c, e, normal) = drive(s, t, y);
    let o = f.omega;
    let k2 = s.k2;
    let speed = (ux * ux + uy * uy).sqrt();
    let gyro = (T::ONE + k2) * o[2];
    let d_norm = (d[0] * d[0] + d[1] * d[1]).sqrt();
    let at_rest = speed <= T::from_f64(AT_REST_M_S);
    let (dir, held) = match last {
        // A roll that starts from rest starts along D.
        Some(_) if at_rest && d_norm > resistance => ([d[0] / d_norm, d[1] / d_norm], false),
        // One that the resistance stops goes through rest along its last direction.
        Some(l) if at_rest || ux * l[0] + uy * l[1] <= T::ZERO => (l, false),
        _ if !at_rest => ([ux / speed, uy / speed], false),
        // Held: the resistance balances D; it cannot exceed it.
        _ if d_norm <= resistance || d_norm == T::ZERO => ([T::ZERO, T::ZERO], true),
        _ => ([d[0] / d_norm, d[1] / d_norm], false),
    };
    let (dux, duy) = if held && speed <= T::from_f64(AT_REST_M_S) {
        (T::ZERO, T::ZERO)
    } else {
        (
            k2 * (d[0] - resistance * dir[0]) + gyro * uy,
            k2 * (d[1] - resistance * dir[1]) - gyro * ux,
        )
    };
    let dsig = -(o[0] * ux + o[1] * uy);
    let ou = cross(&o, &[ux, uy, T::ZERO]);
    let ft = [
        f.carrier[0] + e[0] + c[0] + T::TWO * ou[0] + dux - f.gravity[0],
        f.carrier[1] + e[1] + c[1] + T::TWO * ou[1] + duy - f.gravity[1],
    ];
    Forces {
        derivative: [ux, uy, dux, duy, dsig],
        normal_m_s2: normal,
        friction_m_s2: (ft[0] * ft[0] + ft[1] * ft[1]).sqrt(),
        friction_xy_m_s2: ft,
        held,
    }
}
