//! The bowl's rotation as a perturbation of the incline (rolling, and sliding below), to second
//! order in the speeds (docs/model.md §12, "The four rotation rows"): the incline's path is
//! known in closed form
//! (`x0 = p0 + A t^2/2 d`, `A = k2 g (sin th - mu_r cos th)`, `d` downhill at release), and the
//! rotation's terms of §9's equations (the gyroscopic `(1 + k2) Oz J u`, the downhill
//! direction turning at `w2`, the spin `sig`, the Euler and centripetal terms, the normal
//! force's change and the resistance's turning direction) are polynomials in `t` along it, so
//! the first- and second-order corrections to the path and to the exit time are closed forms.
//!
//! Bowl frame of §9 at `t = 0`: `d = -e1`, `e2`; `s = sin th`, `Oz = w1 cos th + w2`,
//! `Nn = g cos th`, `G = g sin th`, `lambda = k2 mu_r Nn / A`. To first order (`psi = w2 t`):
//! the drive gains `G w2 t e2`, the gyroscopic term `(1 + k2) Oz A t e2`, and the resistance
//! turns with the velocity: `v1' + lambda v1 / t = B t`, `B = k2 G w2 + (1 + k2) Oz A`, so
//! `v1 = B t^2 / (2 + lambda)`, `y1 = B t^3 / (3 (2 + lambda))`; the spin `sig1 = w1 s A t^2/2`.
//! To second order, across the path `b2' + lambda b2 / t = k2 |Omega|^2 p0y`, so
//! `y2 = k2 |Omega|^2 p0y t^2 / (2 (1 + lambda))`; along it `a2' = q0 + q2 t^2` with the terms
//! listed in [`release_second_order_s`]. The exit time from `|x(T)| = R` to second order:
//! `T1 = -g1 / f0'`, `T2 = -(f0'' T1^2 / 2 + g1' T1 + g2) / f0'` with `f0 = |x0|^2`,
//! `g1 = 2 p0y y1`, `g2 = 2 P X2 + 2 p0y y2 + y1^2`, `P = x0 . d`.
//!
//! The mean over the twelve azimuths has no first-order part (the mirror, §12), so the rolling
//! incline's mean moves by `mean T2` to second order. Where the incline slides the same holds
//! along the sliding incline's path, with the slip's own turning (`Orders::sliding`); the rod
//! offset is left out (`L = 0`). The chooser
//! (`whole::second_order_bound`) runs [`mean_second_order_from`] where its a-priori rotation
//! estimate refuses the incline.

use crate::Real;
use crate::particle::rolling::{AZIMUTHS_DEG, RollingScene};

use super::incline::{Tilt, incline_release_s, mean_from_sum, slides_in};

/// `(cos beta, sin beta)` of [`AZIMUTHS_DEG`] (every 30 deg), exact to the last bit of `f64`
/// (`libm`'s `sin`/`cos` cost about 20 ns each: 24 of them would be most of the chooser's
/// budget for the second order, docs/model.md §12).
const AZIMUTH_COS_SIN: [(f64, f64); 12] = {
    const H: f64 = 0.866_025_403_784_438_6; // sqrt(3)/2
    [
        (1.0, 0.0),
        (H, 0.5),
        (0.5, H),
        (0.0, 1.0),
        (-0.5, H),
        (-H, 0.5),
        (-1.0, 0.0),
        (-H, -0.5),
        (-0.5, -H),
        (0.0, -1.0),
        (0.5, -H),
        (H, -0.5),
    ]
};

/// The scene's part of the orders (independent of the release), computed once per scene.
pub(crate) struct Orders<T> {
    drive: T,
    /// `1 / drive`.
    inv_drive: T,
    ri: T,
    /// `y1' = v1_k t^2` (rolling: the slip-free velocity across; sliding: the granule's).
    v1_k: T,
    /// `y1 = y1_k t^3`.
    y1_k: T,
    /// `y2 = y2_k p0y t^2`.
    y2_k: T,
    /// `q0 = q0_c - q0_x p0d` (`p0x = -p0d`).
    q0_x: T,
    q0_c: T,
    /// `q2 / 12`: `x2 = q0 t^2/2 + q2 t^4/12`.
    q2_12: T,
}

impl<T: Real> Orders<T> {
    /// The incline's orders where its mode is known (`slides`, as
    /// [`InclineMode::Slides`](super::rotation_bound::InclineMode) has it; the chooser holds
    /// it): [`Orders::new`] without deciding it again.
    pub(crate) fn of_mode(scene: &RollingScene<T>, tilt: Tilt<T>, slides: bool) -> Option<Self> {
        if slides {
            Self::sliding(scene, tilt.sin, tilt.cos)
        } else {
            Self::rolling(scene, tilt.sin, tilt.cos)
        }
    }

    /// `mean T2 / mean T0` from the incline's own times (finite, and positive wherever the
    /// orders exist: a release inside the rim) and their sum `t0`, as the chooser holds them
    /// ([`tilted_second_order`] checks and computes them again).
    pub(crate) fn relative(&self, times: &[T; 12], t0: T) -> Option<T> {
        relative_second_order(self, times, t0)
    }

    /// The incline's orders in its mode at the scene (rolling, or sliding where rolling needs
    /// more friction than `mu_s`, as [`incline_release_s`] has it). `None` when the incline
    /// does not drive the granule or the release is not inside the rim. `(s, c)`: the tilt's
    /// sine and cosine.
    fn new(scene: &RollingScene<T>, s: T, c: T) -> Option<Self> {
        if slides_in(scene, s, c) {
            Self::sliding(scene, s, c)
        } else {
            Self::rolling(scene, s, c)
        }
    }

    /// The rolling incline's orders (the module's text).
    fn rolling(scene: &RollingScene<T>, s: T, c: T) -> Option<Self> {
        let g = scene.g_m_s2;
        let (k2, mu_r, a) = (scene.k2, scene.rolling_resistance, scene.particle_radius_m);
        let (w1, w2) = (scene.precession_rad_s, scene.spin_rad_s);
        let (big_g, nn) = (g * s, g * c);
        let drive = k2 * (big_g - mu_r * nn);
        if drive.is_nan() || drive <= T::ZERO {
            return None;
        }
        let (ri, rim) = (scene.ri_m, scene.rim_radius_m);
        // Also catches a NaN radius.
        if ri.is_nan() || rim.is_nan() || ri.abs() >= rim {
            return None;
        }
        let oz = w1 * c + w2;
        let omega2 = w1 * w1 * s * s + oz * oz;
        let inv_drive = T::ONE / drive;
        let lambda = k2 * mu_r * nn * inv_drive;
        let half = T::HALF;
        // First order across the path.
        let b = k2 * big_g * w2 + (T::ONE + k2) * oz * drive;
        // One division for both: 1 / ((2 + lambda) (1 + lambda)).
        let r = T::ONE / ((T::TWO + lambda) * (T::ONE + lambda));
        let v1_k = b * (T::ONE + lambda) * r;
        let y1_k = v1_k * T::from_f64(1.0 / 3.0);
        // Second order across the path: y2 = k2 |Omega|^2 p0y t^2 / (2 (1 + lambda)).
        let y2_k = k2 * omega2 * (T::TWO + lambda) * r * half;
        // Second order along d: a2' = q0 + q2 t^2, from (x = p0x - A t^2/2 the e1 coordinate):
        //   -k2 [G w2^2 t^2/2 + Oz^2 x - w1 s Oz a + w1 w2 s a]          (gravity turning, -C, -E)
        //   -(1 - k2) [w1^2 s^2 A t^2/2 + a w1 w2 s]                       (spin sig1 Ox, Euler)
        //   -k2 mu_r [(w1 w2 s + Oz w1 s) x - w1^2 s^2 a + 2 w1 s v1
        //             - 2 w1 s w2 A t^2 - Nn v1^2 / (2 A^2 t^2)]           (normal force, direction)
        //   -(1 + k2) Oz v1                                                (gyroscopic on v1)
        let n_x = w1 * w2 * s + oz * w1 * s; // N2's coefficient of x
        let q0_x = -k2 * oz * oz - k2 * mu_r * n_x;
        let q0_c = -k2 * (-w1 * s * oz * a + w1 * w2 * s * a) - (T::ONE - k2) * a * w1 * w2 * s
            + k2 * mu_r * w1 * w1 * s * s * a;
        let q2 = -k2 * (big_g * w2 * w2 * half - oz * oz * drive * half)
            - (T::ONE - k2) * w1 * w1 * s * s * drive * half
            - k2 * mu_r
                * (-n_x * drive * half + T::TWO * w1 * s * v1_k
                    - T::TWO * w1 * s * w2 * drive
                    - nn * v1_k * v1_k * half * inv_drive * inv_drive)
            - (T::ONE + k2) * oz * v1_k;
        Some(Orders {
            drive,
            inv_drive,
            ri,
            v1_k,
            y1_k,
            y2_k,
            q0_x,
            q0_c,
            q2_12: q2 * T::from_f64(1.0 / 12.0),
        })
    }

    /// The sliding incline's orders (docs/model.md §12, "The sliding incline's second
    /// order"; derived as the rolling ones, checked against the disc in `lab`'s
    /// `whole::rotation_orders`). The granule slides down `d = -e1` at `A = g (sin th - mu_s
    /// cos th)` from rest, its contact slipping at `U t` with `U = A - kappa mu_s Nn`
    /// (`kappa = k2 / (1 - k2)`: the friction torque spins the sphere up, `kappa` of the
    /// friction per unit mass at its surface); `U > 0` is the sliding condition itself. The
    /// slip's direction turns with the rotation: across the path its component `v` obeys
    /// `v' + lambda v / t = P(t)`, `lambda = (1 + kappa) mu_s Nn / U`, so each order is a
    /// polynomial in `t` again.
    /// - First order across: `v1 = B t^2 / (2 + lambda)` with
    ///   `B = G w2 + Oz (2 A - kappa mu_s Nn)`; the granule's `uy1 = Kuy t^2`,
    ///   `Kuy = (G w2 + 2 Oz A) / 2 - mu_s Nn B / (2 U (2 + lambda))`, `y1 = Kuy t^3 / 3`.
    /// - Second order across: `y2 = |Omega|^2 (1 - mu_s Nn / (U (1 + lambda))) p0y t^2 / 2`.
    /// - Second order along `e1`: `x2 = q0 t^2 / 2 + q4 t^4 / 24`,
    ///   `q0 = (Oz^2 + mu_s s w1 (c w1 + 2 w2)) p0x - a s w1^2 (c + mu_s s)` (the rolling
    ///   form's with `k2 = 1`), `q4 = -mu_s Nn (B / (2 + lambda))^2 / U^2 + 4 Kuy (Oz + mu_s s
    ///   w1) - g H`, `H = c s w1 (c w1 + 2 w2) + mu_s (s^2 w1 (c w1 + 6 w2) - c Oz^2)
    ///   - mu_s^2 c s w1 (c w1 + 6 w2)`.
    ///
    /// The exit time's orders are then the rolling incline's ([`Orders::terms`]).
    fn sliding(scene: &RollingScene<T>, s: T, c: T) -> Option<Self> {
        let g = scene.g_m_s2;
        let (k2, mu, a) = (scene.k2, scene.sliding_friction, scene.particle_radius_m);
        let (w1, w2) = (scene.precession_rad_s, scene.spin_rad_s);
        let (big_g, nn) = (g * s, g * c);
        let mu_n = mu * nn;
        let drive = big_g - mu_n;
        // A sphere's `k2` is below 1 (a point mass would have no spin to drive).
        let kappa = k2 / (T::ONE - k2);
        let slip = drive - kappa * mu_n;
        // Also catches NaNs: no drive, or no slip to turn (not sliding).
        if !(drive > T::ZERO && slip > T::ZERO && kappa.is_finite()) {
            return None;
        }
        let (ri, rim) = (scene.ri_m, scene.rim_radius_m);
        if ri.is_nan() || rim.is_nan() || ri.abs() >= rim {
            return None;
        }
        let (half, two) = (T::HALF, T::TWO);
        let oz = w1 * c + w2;
        let omega2 = w1 * w1 * s * s + oz * oz;
        let inv_slip = T::ONE / slip;
        let n_u = mu_n * inv_slip;
        let lambda = (T::ONE + kappa) * n_u;
        // First order across the path.
        let b = big_g * w2 + oz * (two * drive - kappa * mu_n);
        let v1 = b / (two + lambda);
        let k_uy = ((big_g * w2 + two * oz * drive) - n_u * v1) * half;
        // Second order across the path.
        let y2_k = omega2 * (T::ONE - n_u / (T::ONE + lambda)) * half;
        // Second order along e1 (see above); `q0_x`, `q0_c` and `q2_12` are along d = -e1.
        let c_w1 = c * w1;
        let h = c * s * w1 * (c_w1 + two * w2)
            + mu * (s * s * w1 * (c_w1 + T::from_f64(6.0) * w2) - c * oz * oz)
            - mu * mu * c * s * w1 * (c_w1 + T::from_f64(6.0) * w2);
        let q4 = -n_u * v1 * v1 * inv_slip + T::from_f64(4.0) * k_uy * (oz + mu * s * w1) - g * h;
        Some(Orders {
            drive,
            inv_drive: T::ONE / drive,
            ri,
            v1_k: k_uy,
            y1_k: k_uy * T::from_f64(1.0 / 3.0),
            y2_k,
            q0_x: -(oz * oz + mu * s * w1 * (c_w1 + two * w2)),
            q0_c: a * s * w1 * w1 * (c + mu * s),
            q2_12: -q4 * T::from_f64(1.0 / 24.0),
        })
    }

    /// The release at `(cos beta, sin beta)` whose incline time is `t` (`T0`): `(T1, T2)`,
    /// unchecked (the callers check that what comes out is finite). No square root (the
    /// incline's time gives the path: at the exit `x0 . d = p0d + A t^2/2`) and one division:
    /// the chooser runs this on seven releases (the mirror pairs share `T2`).
    #[inline(always)]
    fn terms(&self, cb: T, sb: T, t: T) -> (T, T) {
        let (drive, ri, half, two) = (self.drive, self.ri, T::HALF, T::TWO);
        // Release: p0 = ri (-cos beta, -sin beta); along d = -e1 its coordinate is ri cos beta.
        let p0d = ri * cb;
        let p0y = -ri * sb;
        let tt = t * t;
        // P = x0 . d at the exit; f0' = 2 P A t, f0'' = 2 A (A t^2 + P).
        let big_p = p0d + drive * tt * half;
        // 1 / f0' = inv / (2 A). (One inverse of the seven products instead, measured: no
        // faster.)
        let inv = T::ONE / (big_p * t);
        let f2 = two * drive * (drive * tt + big_p);
        let y1 = self.y1_k * tt * t;
        let v1 = self.v1_k * tt;
        let q0 = self.q0_c - self.q0_x * p0d;
        let x2 = tt * (q0 * half + self.q2_12 * tt);
        let y2 = self.y2_k * p0y * tt;
        let g1d = two * p0y * v1;
        let g2 = two * (big_p * x2 + p0y * y2) + y1 * y1;
        // T1 = -g1 / f0' with g1 = 2 p0y y1.
        let t1 = -p0y * y1 * inv * self.inv_drive;
        let t2 = -(f2 * t1 * t1 * half + g1d * t1 + g2) * inv * half * self.inv_drive;
        (t1, t2)
    }
}

/// The incline's release at `beta_rad` (rolling or sliding, [`incline_release_s`]): `(T0, T1, T2)`, its exit time at rest and the
/// rotation's first- and second-order corrections (s); `None` when the incline does not drive
/// the granule or the release is not inside the rim.
pub fn release_second_order_s<T: Real>(scene: &RollingScene<T>, beta_rad: T) -> Option<(T, T, T)> {
    let th = scene.axes_angle_rad;
    let orders = Orders::new(scene, th.sin(), th.cos())?;
    let t = incline_release_s(scene, beta_rad)?;
    let (t1, t2) = orders.terms(beta_rad.cos(), beta_rad.sin(), t);
    (t > T::ZERO && t1.is_finite() && t2.is_finite()).then_some((t, t1, t2))
}

/// The incline's mean over [`AZIMUTHS_DEG`] (rolling or sliding) and the rotation's second-order change of
/// it, relative: `(mean T0, mean T2 / mean T0)`.
pub fn mean_second_order<T: Real>(scene: &RollingScene<T>) -> Option<(T, T)> {
    let mut times = [T::ZERO; 12];
    for (t, deg) in times.iter_mut().zip(AZIMUTHS_DEG) {
        *t = incline_release_s(scene, T::from_f64(deg.to_radians()))?;
    }
    mean_second_order_from(scene, &times)
}

/// [`mean_second_order`] from the rolling incline's own times at [`AZIMUTHS_DEG`] (the
/// chooser has them from the incline it has just computed): the scene's part once, then
/// seven releases, no trigonometry (the azimuths' from a table), no square root, one division
/// each. `T2` is even in `sin beta` (`T1` is odd, and enters squared or times the odd `g1'`),
/// and the azimuths at `beta` and `-beta` have the same path and time, so the pairs 30/330 to
/// 150/210 deg count twice. (Built to cost at most a fifth of the incline, docs/model.md §12.)
pub fn mean_second_order_from<T: Real>(scene: &RollingScene<T>, times: &[T; 12]) -> Option<(T, T)> {
    let th = scene.axes_angle_rad;
    tilted_second_order(scene, th.sin(), th.cos(), times)
}

/// [`mean_second_order_from`] with the tilt's sine `s` and cosine `c` already computed.
pub(crate) fn tilted_second_order<T: Real>(
    scene: &RollingScene<T>,
    s: T,
    c: T,
    times: &[T; 12],
) -> Option<(T, T)> {
    let orders = Orders::new(scene, s, c)?;
    let t0 = checked_sum(times)?;
    let mean = mean_from_sum(t0);
    let rel = relative_second_order(&orders, times, t0)?;
    mean.is_finite().then_some(rel).map(|rel| (mean, rel))
}

/// The sum of `times`, `None` unless every one is finite and positive (branch-free: checked
/// together).
pub(crate) fn checked_sum<T: Real>(times: &[T; 12]) -> Option<T> {
    let mut t0 = T::ZERO;
    let mut ok = true;
    for &t in times {
        ok &= t.is_finite() & (t > T::ZERO);
        t0 += t;
    }
    ok.then_some(t0)
}

/// `mean T2 / mean T0` over the seven releases that stand for the twelve (`t0` the times' sum).
fn relative_second_order<T: Real>(orders: &Orders<T>, times: &[T; 12], t0: T) -> Option<T> {
    // Azimuths 0 to 180 deg; 30 to 150 stand for their mirrors 330 to 210 too.
    const WEIGHT: [f64; 7] = [1.0, 2.0, 2.0, 2.0, 2.0, 2.0, 1.0];
    // Eight releases computed side by side (the eighth thrown away) so the compiler can pair
    // them in vector registers (one at a time took 49 ns of the chooser's time, side by side
    // 42 ns); summed in order after, as one at a time did.
    let mut c = [T::ZERO; 8];
    for (i, c) in c.iter_mut().enumerate() {
        let (cb, sb) = AZIMUTH_COS_SIN[i];
        *c = orders.terms(T::from_f64(cb), T::from_f64(sb), times[i]).1;
    }
    let mut t2 = T::ZERO;
    for (w, c) in WEIGHT.iter().zip(c) {
        t2 += T::from_f64(*w) * c;
    }
    let rel = t2 / t0;
    rel.is_finite().then_some(rel)
}

#[cfg(test)]
#[path = "incline_rotation_tests.rs"]
mod tests;
