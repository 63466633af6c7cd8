//! `bowl predict --target host|mcu`: where the chosen plan will run. The chooser is generic over
//! the number type: f64 plans are priced in host nanoseconds, f32 plans in Cortex-M4F
//! instructions (the measured cost table), and f32 sets the tolerance's floor (64 epsilon of
//! f32, about 7.6e-6). For the MCU the scene, the need and a trace are narrowed to f32, the
//! chooser runs in f32, and its choice is widened back for printing; the residence time
//! `bowl predict` prints is still computed on the host in f64.

use model_core::choose::{
    Choice, ChooseError, Knowledge, Need, Plan, SampledOmega, Target, TraceError,
    choose_constant_for, choose_trace, choose_varying_for,
};
use model_core::ode::{Method, SpinUp};
use model_core::particle::Scene;

/// Where the chosen plan runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum RunsOn {
    /// The PC, f64, priced in nanoseconds.
    #[default]
    Host,
    /// The Cortex-M4F, f32, priced in executed instructions.
    Mcu,
}

impl RunsOn {
    /// The cost table's target.
    pub fn target(self) -> Target {
        match self {
            RunsOn::Host => Target::Host,
            RunsOn::Mcu => Target::Mcu,
        }
    }
}

fn narrow_need(n: &Need<f64>) -> Need<f32> {
    match *n {
        Need::Tolerance(t) => Need::Tolerance(t as f32),
        Need::Uncertainty(k) => Need::Uncertainty(Knowledge {
            mu_rel: k.mu_rel as f32,
            radius_m: k.radius_m as f32,
            omega_rel: k.omega_rel as f32,
        }),
    }
}

fn widen_method(m: Method<f32>) -> Method<f64> {
    match m {
        Method::Euler { step_s } => Method::Euler {
            step_s: f64::from(step_s),
        },
        Method::SemiImplicitEuler { step_s } => Method::SemiImplicitEuler {
            step_s: f64::from(step_s),
        },
        Method::Rk4 { step_s } => Method::Rk4 {
            step_s: f64::from(step_s),
        },
        Method::Dp54 { rtol, atol } => Method::Dp54 {
            rtol: f64::from(rtol),
            atol: f64::from(atol),
        },
    }
}

fn widen(c: Choice<f32>) -> Choice<f64> {
    Choice {
        model: c.model,
        plan: match c.plan {
            Plan::ClosedForm => Plan::ClosedForm,
            Plan::ClosedFormAtMeanSpeed { omega_rad_s } => Plan::ClosedFormAtMeanSpeed {
                omega_rad_s: f64::from(omega_rad_s),
            },
            Plan::Integrate(m) => Plan::Integrate(widen_method(m)),
        },
        tolerance_rel: f64::from(c.tolerance_rel),
        spread_rel: c.spread_rel.map(f64::from),
        coriolis_effect_rel: f64::from(c.coriolis_effect_rel),
        estimated_error_rel: f64::from(c.estimated_error_rel),
        rhs_evaluations: c.rhs_evaluations,
        predicted_cost: c.predicted_cost,
        time_estimate_s: f64::from(c.time_estimate_s),
        choosing_evaluations: c.choosing_evaluations,
        answer_s: c.answer_s.map(f64::from),
        source: c.source,
    }
}

/// The chooser at a constant speed, for `runs_on`.
pub fn constant(
    scene: &Scene<f64>,
    need: &Need<f64>,
    runs_on: RunsOn,
) -> Result<Choice<f64>, ChooseError> {
    match runs_on {
        RunsOn::Host => choose_constant_for(scene, need),
        RunsOn::Mcu => choose_constant_for(&scene.to_f32(), &narrow_need(need)).map(widen),
    }
}

/// The chooser for a first-order spin-up, for `runs_on`.
pub fn spin_up(
    scene: &Scene<f64>,
    need: &Need<f64>,
    speed: &SpinUp<f64>,
    runs_on: RunsOn,
) -> Result<Choice<f64>, ChooseError> {
    match runs_on {
        RunsOn::Host => choose_varying_for(scene, need, speed),
        RunsOn::Mcu => {
            let narrow = SpinUp {
                start_rad_s: speed.start_rad_s as f32,
                final_rad_s: speed.final_rad_s as f32,
                time_constant_s: speed.time_constant_s as f32,
            };
            choose_varying_for(&scene.to_f32(), &narrow_need(need), &narrow).map(widen)
        }
    }
}

/// Why a trace could not be used: the sample's problem, or the chooser's.
pub enum TraceChoiceError {
    /// The trace narrowed to f32 is not a valid trace (times that f32 cannot tell apart).
    Trace(TraceError),
    /// The chooser failed.
    Choose(ChooseError),
}

/// The chooser over a trace (`times_s`, `omega_rad_s`; `host` is the f64 trace already
/// checked), for `runs_on`.
pub fn trace(
    scene: &Scene<f64>,
    need: &Need<f64>,
    host: &SampledOmega<'_, f64>,
    times_s: &[f64],
    omega_rad_s: &[f64],
    runs_on: RunsOn,
) -> Result<Choice<f64>, TraceChoiceError> {
    match runs_on {
        RunsOn::Host => choose_trace(scene, need, host).map_err(TraceChoiceError::Choose),
        RunsOn::Mcu => {
            let times: Vec<f32> = times_s.iter().map(|&t| t as f32).collect();
            let omegas: Vec<f32> = omega_rad_s.iter().map(|&w| w as f32).collect();
            let narrow = SampledOmega::new(&times, &omegas).map_err(TraceChoiceError::Trace)?;
            choose_trace(&scene.to_f32(), &narrow_need(need), &narrow)
                .map(widen)
                .map_err(TraceChoiceError::Choose)
        }
    }
}
