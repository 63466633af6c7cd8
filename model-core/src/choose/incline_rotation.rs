//! The bowl's rotation as a perturbation of the rolling incline, to second order in the speeds
//! (docs/model.md §12, "The four rotation rows"): the incline's path is known in closed form
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
//! incline's mean moves by `mean T2` to second order. Rolling only: a sliding incline's slip
//! has its own dynamics (not here), and the rod offset is left out (`L = 0`).

use crate::Real;
use crate::particle::rolling::{AZIMUTHS_DEG, RollingScene, incline_residence_s};

/// The rolling incline's release at `beta_rad`: `(T0, T1, T2)`, its exit time at rest and the
/// rotation's first- and second-order corrections (s); `None` when the incline does not drive
/// the granule or the release is not inside the rim.
pub fn release_second_order_s<T: Real>(scene: &RollingScene<T>, beta_rad: T) -> Option<(T, T, T)> {
    let (s, c) = (scene.axes_angle_rad.sin(), scene.axes_angle_rad.cos());
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
    // Release: p0 = ri (-cos beta, -sin beta); along d = -e1 its coordinate is ri cos beta.
    let p0d = ri * beta_rad.cos();
    let p0y = -ri * beta_rad.sin();
    let p0x = -p0d;
    // The incline's own exit time (its path to the rim and drive are the ones above).
    let t0 = incline_residence_s(scene, beta_rad)?;
    if t0 <= T::ZERO {
        return None;
    }
    let oz = w1 * c + w2;
    let omega2 = w1 * w1 * s * s + oz * oz;
    let lambda = k2 * mu_r * nn / drive;
    let half = T::HALF;
    // First order across the path.
    let b = k2 * big_g * w2 + (T::ONE + k2) * oz * drive;
    let v1_k = b / (T::TWO + lambda); // v1 = v1_k t^2
    let y1_k = v1_k / T::from_f64(3.0); // y1 = y1_k t^3
    // Second order across the path: y2 = y2_k t^2.
    let y2_k = k2 * omega2 * p0y / (T::TWO * (T::ONE + lambda));
    // Second order along d: a2' = q0 + q2 t^2, from (x = p0x - A t^2/2 the e1 coordinate):
    //   -k2 [G w2^2 t^2/2 + Oz^2 x - w1 s Oz a + w1 w2 s a]          (gravity turning, -C, -E)
    //   -(1 - k2) [w1^2 s^2 A t^2/2 + a w1 w2 s]                       (spin sig1 Ox, Euler)
    //   -k2 mu_r [(w1 w2 s + Oz w1 s) x - w1^2 s^2 a + 2 w1 s v1
    //             - 2 w1 s w2 A t^2 - Nn v1^2 / (2 A^2 t^2)]           (normal force, direction)
    //   -(1 + k2) Oz v1                                                (gyroscopic on v1)
    let n_x = w1 * w2 * s + oz * w1 * s; // N2's coefficient of x
    let q0 = -k2 * (oz * oz * p0x - w1 * s * oz * a + w1 * w2 * s * a)
        - (T::ONE - k2) * a * w1 * w2 * s
        - k2 * mu_r * (n_x * p0x - w1 * w1 * s * s * a);
    let q2 = -k2 * (big_g * w2 * w2 * half - oz * oz * drive * half)
        - (T::ONE - k2) * w1 * w1 * s * s * drive * half
        - k2 * mu_r
            * (-n_x * drive * half + T::TWO * w1 * s * v1_k
                - T::TWO * w1 * s * w2 * drive
                - nn * v1_k * v1_k / (T::TWO * drive * drive))
        - (T::ONE + k2) * oz * v1_k;
    // Exit time.
    let t = t0;
    let big_p = p0d + drive * t * t * half;
    let f1 = T::TWO * big_p * drive * t;
    let f2 = T::TWO * drive * drive * t * t + T::TWO * drive * big_p;
    let y1 = y1_k * t * t * t;
    let v1 = v1_k * t * t;
    let x2 = q0 * t * t * half + q2 * t * t * t * t / T::from_f64(12.0);
    let y2 = y2_k * t * t;
    let g1 = T::TWO * p0y * y1;
    let g1d = T::TWO * p0y * v1;
    let g2 = T::TWO * big_p * x2 + T::TWO * p0y * y2 + y1 * y1;
    if f1 <= T::ZERO {
        return None;
    }
    let t1 = -g1 / f1;
    let t2 = -(f2 * t1 * t1 * half + g1d * t1 + g2) / f1;
    (t1.is_finite() && t2.is_finite()).then_some((t0, t1, t2))
}

/// The rolling incline's mean over [`AZIMUTHS_DEG`] and the rotation's second-order change of
/// it, relative: `(mean T0, mean T2 / mean T0)`.
pub fn mean_second_order<T: Real>(scene: &RollingScene<T>) -> Option<(T, T)> {
    let (mut t0, mut t2) = (T::ZERO, T::ZERO);
    for deg in AZIMUTHS_DEG {
        let (a, _, c) = release_second_order_s(scene, T::from_f64(deg.to_radians()))?;
        t0 += a;
        t2 += c;
    }
    let n = T::from_f64(AZIMUTHS_DEG.len() as f64);
    let (mean, rel) = (t0 / n, t2 / t0);
    (mean.is_finite() && rel.is_finite()).then_some((mean, rel))
}

#[cfg(test)]
#[path = "incline_rotation_tests.rs"]
mod tests;
