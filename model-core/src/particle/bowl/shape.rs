//! The shape's geometry against a scene: the bare rim, the centre's meridian on the fillet and
//! the wall, whether the corner is sharp, and the checks of [`BowlShape`]'s values.

use super::wall::{Meridian, Piece};
use super::{BowlError, BowlShape};
use crate::Real;
use crate::particle::rolling::RollingScene;

/// The radius, in units of the rim's, of the fillet a sharp corner is given for a granule that
/// stays in it, and the least radius of the centre's arc on a fillet barely larger than the
/// granule (a tighter arc makes the granule resting in it stiff).
const SHARP_FILLET: f64 = 1e-2;

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
        // which stands in for touching the bottom and the wall at once; a fillet barely larger
        // than the granule gets the same least arc (a smooth turn, no impact).
        let rc = (self.fillet_radius_m - a).max(rim * T::from_f64(SHARP_FILLET));
        let fillet = rc + a;
        let alpha = self.wall_angle_rad;
        let (sa, ca) = (alpha.sin(), alpha.cos());
        // tan(alpha/2) = sin alpha / (1 + cos alpha).
        let half_tan = sa / (T::ONE + ca);
        let rho_b = rim - fillet * half_tan;
        let lip = rim + self.wall_height_m * ca / sa;
        // The centre when the contact is at the edge, and how far along the cone that is from
        // the fillet's end (0 where the stand-in fillet of a sharp corner rises above a wall
        // lower than it: then the pivot starts there; a real fillet that does is refused).
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
            piece: Piece::Whole,
        })
    }

    /// How high the fillet's arc rises up the wall before it meets it, m: `F (1 - cos alpha)`.
    pub fn fillet_rise_m(&self) -> T {
        self.fillet_radius_m * (T::ONE - self.wall_angle_rad.cos())
    }

    /// Refuses a fillet that rises above its wall, or one with no wall (a bare rim): a fillet
    /// rounds the corner into the wall and ends on it, so neither is a bowl. The wall's model
    /// took the arc whole, so the granule climbed it past the lip (a 50 mm fillet on a 10 mm
    /// wall at 60 deg: 25 mm up) and the time came out for a taller bowl than the one given.
    pub fn check_fillet(&self) -> Result<(), BowlError> {
        // A millionth over is rounding: a fillet of `h / (1 - cos alpha)` exactly is held.
        if self.fillet_radius_m > T::ZERO
            && self.fillet_rise_m() > self.wall_height_m * T::from_f64(1.0 + 1e-6)
        {
            return Err(BowlError::FilletAboveWall);
        }
        Ok(())
    }

    /// Whether the corner is sharper than the granule (`F <= a`): then reaching it is an
    /// impact. A fillet any larger turns the granule's path smoothly, however tight (the
    /// centre's arc `F - a`, at least the stand-in's `R / 100`): it used to be an impact up to
    /// `F - a = R / 100`, so a 4 mm fillet with a 3.2 mm granule in an 82 mm bowl bounced off
    /// the wall and left 22 % later than the smooth turn MuJoCo and a 4.5 mm fillet give
    /// (docs/model.md §10, the held-out sweep's scene 8).
    pub fn sharp_corner(&self, sc: &RollingScene<T>) -> bool {
        self.fillet_radius_m <= sc.particle_radius_m
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
        self.check_fillet()?;
        if let Some(m) = self.meridian(sc)
            && (m.rho_b_m <= sc.ri_m || m.rho_b_m.is_nan())
        {
            return Err(BowlError::FilletReachesRelease);
        }
        Ok(())
    }
}
