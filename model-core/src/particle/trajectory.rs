//! The particle's path before it leaves: `r(t)` and `r'(t)` (paper Eq. 6, 7, 10, 11) from the
//! same closed forms as the residence time ([`super::Shape`]), for plots and checks of the
//! integrators against the closed forms.

use super::scene::nonneg_finite;
use super::{Model, Scene, SceneError, Shape};
use crate::Real;

fn checked_time<T: Real>(t_s: T) -> Result<(), SceneError> {
    if nonneg_finite(t_s) {
        Ok(())
    } else {
        Err(SceneError::InvalidTime)
    }
}

/// Shared set-up of `r(t)` and `r'(t)`: `None` when the particle does not move (`ri <= a`).
fn moving<T: Real>(scene: &Scene<T>, model: Model) -> Result<Option<(Shape<T>, T)>, SceneError> {
    scene.validate()?;
    let a = scene.equilibrium_radius_m();
    if scene.ri_m <= a {
        return Ok(None);
    }
    Ok(Some((Shape::new(scene, model)?, a)))
}

/// `r(t)`, m: paper Eq. 6 (flat) or Eq. 10 (Coriolis, corrected `A`, `B`), written as
/// `ri + (ri - a) F(l1 t)` so that it is accurate at small `t`.
///
/// This is the trajectory of the ODE for every `t >= 0`; the particle physically leaves at the
/// rim at `T` ([`residence`](super::residence)). When static friction holds it (`ri <= a`) it stays at `ri`.
pub fn position_m<T: Real>(scene: &Scene<T>, model: Model, t_s: T) -> Result<T, SceneError> {
    checked_time(t_s)?;
    let Some((shape, a)) = moving(scene, model)? else {
        return Ok(scene.ri_m);
    };
    let u = shape.c1 * scene.omega_rad_s * t_s;
    let (f, _, _) = shape.eval(u);
    let r = scene.ri_m + (scene.ri_m - a) * f;
    if r.is_finite() {
        Ok(r)
    } else {
        Err(SceneError::OutOfRange)
    }
}

/// `r'(t)`, m/s: paper Eq. 7 (flat) or Eq. 11 (Coriolis):
/// `(ri - a) (k omega / (2 s)) (e^{l1 t} - e^{l2 t})`; 0 when the particle does not move.
pub fn radial_velocity_m_s<T: Real>(
    scene: &Scene<T>,
    model: Model,
    t_s: T,
) -> Result<T, SceneError> {
    checked_time(t_s)?;
    let Some((shape, a)) = moving(scene, model)? else {
        return Ok(T::ZERO);
    };
    let l1 = shape.c1 * scene.omega_rad_s;
    let (_, fp, _) = shape.eval(l1 * t_s);
    let v = (scene.ri_m - a) * l1 * fp;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(SceneError::OutOfRange)
    }
}
