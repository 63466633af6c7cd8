//! The integrator methods of `bowl predict` (filled in with model-core's `ode` module).

use anyhow::{Result, bail};
use model_core::particle::{Model, Scene};

use super::{MethodChoice, Prediction};

/// Integrates one scene with a numerical method.
pub fn predict(
    _scene: &Scene<f64>,
    _model: Model,
    method: MethodChoice,
    _step_s: Option<f64>,
    _tol: f64,
) -> Result<Prediction> {
    bail!("--method {method:?} is not available yet")
}
