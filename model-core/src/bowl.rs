//! Bowl kinematics: the combined angular speed of the bowl from its two motors (paper Eq. 2),
//! and the split of a combined target speed back into spin and precession setpoints.
//!
//! # Angle convention (correction to the paper)
//! Paper Eq. 2 reads `omega = sqrt((w1 sin th)^2 + (w1 cos th + w2)^2)`, which equals
//! `sqrt(w1^2 + w2^2 + 2 w1 w2 cos th)`: the norm of the sum of two angular-velocity vectors whose
//! axes are `th` apart. The paper calls `th` the rod's angle to the *horizontal*; with that
//! definition the angle between the axes would be `90 deg - th`. We implement the formula as
//! printed and name its parameter for what it is, [`BowlGeometry::axes_angle_rad`], the angle
//! between the spin axis and the precession (vertical) axis. The default, 60 degrees, reproduces
//! the paper's numbers. A rig whose bowl spins about a rod tilted 60 degrees from the horizontal has
//! 30 degrees between the axes (11.5 % faster combined speed at equal motor speeds): set the angle
//! from the rig's geometry.

use crate::Real;

/// Errors of the kinematics functions. Each says which input was wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BowlError {
    /// A speed was NaN or infinite.
    NonFiniteSpeed,
    /// The combined target speed was negative.
    NegativeTargetSpeed,
    /// The spin/precession ratio was NaN, infinite or negative.
    InvalidRatio,
    /// The angle between the axes was NaN, infinite, or outside [0, pi).
    /// At pi the two axes are opposed and equal speeds cancel: no split exists.
    InvalidAxesAngle,
}

/// The rig's geometry as far as Eq. 2 needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlGeometry<T> {
    /// Angle between the spin axis and the precession axis, radians (see the module docs).
    pub axes_angle_rad: T,
}

impl<T: Real> Default for BowlGeometry<T> {
    /// 60 degrees between the axes: the paper's Eq. 2 with its th = 60 deg.
    fn default() -> Self {
        Self {
            axes_angle_rad: T::from_f64(core::f64::consts::FRAC_PI_3),
        }
    }
}

/// Motor speeds of the two axes, rad/s at the output shaft.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorSpeeds<T> {
    /// Precession: the rod about the vertical, omega1.
    pub precession_rad_s: T,
    /// Spin: the bowl about its own axis, omega2.
    pub spin_rad_s: T,
}

impl<T: Real> BowlGeometry<T> {
    /// Checks the angle and returns the geometry.
    pub fn new(axes_angle_rad: T) -> Result<Self, BowlError> {
        let pi = T::from_f64(core::f64::consts::PI);
        if !axes_angle_rad.is_finite() || axes_angle_rad < T::ZERO || axes_angle_rad >= pi {
            return Err(BowlError::InvalidAxesAngle);
        }
        Ok(Self { axes_angle_rad })
    }

    /// Paper Eq. 2: combined bowl speed `omega = sqrt(w1^2 + w2^2 + 2 w1 w2 cos(angle))`.
    ///
    /// Evaluated as `sqrt((w1 sin a)^2 + (w1 cos a + w2)^2)`, the paper's printed form: a sum of
    /// squares, so it never takes the square root of a negative rounding residue.
    pub fn combined_speed_rad_s(&self, speeds: MotorSpeeds<T>) -> Result<T, BowlError> {
        let a = self.axes_angle_rad;
        combined_speed_from_trig(a.cos(), a.sin(), speeds)
    }

    /// The inverse of Eq. 2 at a fixed ratio `spin = ratio * precession`: see [`split_from_trig`].
    pub fn split(
        &self,
        omega_rad_s: T,
        spin_per_precession: T,
    ) -> Result<MotorSpeeds<T>, BowlError> {
        let a = self.axes_angle_rad;
        split_from_trig(a.cos(), a.sin(), omega_rad_s, spin_per_precession)
    }
}

/// Paper Eq. 2 (see [`BowlGeometry::combined_speed_rad_s`]) with the cosine and sine of the
/// angle between the axes already known: the controller computes them once per configuration,
/// so the MCU evaluates no sine or cosine at run time.
pub fn combined_speed_from_trig<T: Real>(
    cos_axes: T,
    sin_axes: T,
    speeds: MotorSpeeds<T>,
) -> Result<T, BowlError> {
    let (w1, w2) = (speeds.precession_rad_s, speeds.spin_rad_s);
    if !w1.is_finite() || !w2.is_finite() {
        return Err(BowlError::NonFiniteSpeed);
    }
    let along = w1 * cos_axes + w2;
    let across = w1 * sin_axes;
    let omega = (along * along + across * across).sqrt();
    if omega.is_finite() {
        Ok(omega)
    } else {
        Err(BowlError::NonFiniteSpeed)
    }
}

/// The inverse of Eq. 2 at a fixed ratio `spin = ratio * precession`: the motor speeds that
/// give the combined speed `omega_rad_s`, with the cosine and sine of the axes angle known.
///
/// From Eq. 2, `omega^2 = w1^2 (1 + ratio^2 + 2 ratio cos a)`, so
/// `w1 = omega / sqrt(1 + ratio^2 + 2 ratio cos a)` and `w2 = ratio * w1`. With `ratio >= 0`
/// and `a < pi` the root is positive.
pub fn split_from_trig<T: Real>(
    cos_axes: T,
    sin_axes: T,
    omega_rad_s: T,
    spin_per_precession: T,
) -> Result<MotorSpeeds<T>, BowlError> {
    if !omega_rad_s.is_finite() {
        return Err(BowlError::NonFiniteSpeed);
    }
    if omega_rad_s < T::ZERO {
        return Err(BowlError::NegativeTargetSpeed);
    }
    let rho = spin_per_precession;
    if !rho.is_finite() || rho < T::ZERO {
        return Err(BowlError::InvalidRatio);
    }
    // Same sum-of-squares form as Eq. 2 with w1 = 1: (cos a + rho)^2 + sin^2 a.
    let along = cos_axes + rho;
    let across = sin_axes;
    let gain = (along * along + across * across).sqrt();
    if gain.is_nan() || gain <= T::ZERO || !gain.is_finite() {
        return Err(BowlError::InvalidRatio);
    }
    let w1 = omega_rad_s / gain;
    let w2 = rho * w1;
    if !w1.is_finite() || !w2.is_finite() {
        return Err(BowlError::NonFiniteSpeed);
    }
    Ok(MotorSpeeds {
        precession_rad_s: w1,
        spin_rad_s: w2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_speeds_at_60_degrees_give_sqrt3() {
        // cos 60 = 1/2: omega^2 = 1 + 1 + 1 = 3 for unit speeds.
        let g = BowlGeometry::<f64>::default();
        let w = g
            .combined_speed_rad_s(MotorSpeeds {
                precession_rad_s: 1.0,
                spin_rad_s: 1.0,
            })
            .unwrap();
        assert!((w - 3f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn thirty_degrees_is_11_5_percent_above_sixty_at_equal_speeds() {
        let s = MotorSpeeds {
            precession_rad_s: 2.0,
            spin_rad_s: 2.0,
        };
        let w60 = BowlGeometry::<f64>::default()
            .combined_speed_rad_s(s)
            .unwrap();
        let w30 = BowlGeometry::new(core::f64::consts::FRAC_PI_6)
            .unwrap()
            .combined_speed_rad_s(s)
            .unwrap();
        let ratio = w30 / w60;
        assert!((ratio - 1.115).abs() < 1e-3, "{ratio}");
    }

    #[test]
    fn split_inverts_combined_speed() {
        let g = BowlGeometry::<f64>::default();
        for &rho in &[0.0, 0.25, 1.0, 3.0, 100.0] {
            for &omega in &[0.0, 0.5, 1.8, 3.6] {
                let s = g.split(omega, rho).unwrap();
                let back = g.combined_speed_rad_s(s).unwrap();
                assert!(
                    (back - omega).abs() <= 1e-14 * (1.0 + omega),
                    "rho {rho} omega {omega}"
                );
                assert!((s.spin_rad_s - rho * s.precession_rad_s).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn bad_inputs_are_errors() {
        let g = BowlGeometry::<f64>::default();
        assert_eq!(g.split(-1.0, 1.0), Err(BowlError::NegativeTargetSpeed));
        assert_eq!(g.split(1.0, -1.0), Err(BowlError::InvalidRatio));
        assert_eq!(g.split(f64::NAN, 1.0), Err(BowlError::NonFiniteSpeed));
        assert_eq!(
            BowlGeometry::new(core::f64::consts::PI),
            Err(BowlError::InvalidAxesAngle)
        );
        let inf = MotorSpeeds {
            precession_rad_s: f64::INFINITY,
            spin_rad_s: 0.0,
        };
        assert_eq!(g.combined_speed_rad_s(inf), Err(BowlError::NonFiniteSpeed));
        let huge = MotorSpeeds {
            precession_rad_s: 1e300,
            spin_rad_s: 1e300,
        };
        assert_eq!(g.combined_speed_rad_s(huge), Err(BowlError::NonFiniteSpeed));
    }
}
