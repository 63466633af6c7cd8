//! The controller's construction: a configuration checked and built into the state (in a
//! `const fn`, so firmware can hold it in a `static`), and a replaced configuration rebuilt
//! keeping what the rig has learned.

use super::{AxisState, Controller, HostWatch, decouple_duty_per_rad_s};
use crate::control::config::{ConfigError, ControllerConfig};
use crate::control::const_trig::{cos_const, sin_const};
use crate::control::planner::SetpointPlanner;
use crate::control::supervisor::{Fault, State};

impl Controller {
    /// A controller in [`State::Idle`] for a configuration that passes validation.
    ///
    /// A `const fn`: firmware can build its controller in a `static` from a configuration
    /// the compiler has checked.
    pub const fn new(cfg: ControllerConfig) -> Result<Self, ConfigError> {
        match cfg.validate() {
            Ok(()) => Ok(Self::build(cfg)),
            Err(e) => Err(e),
        }
    }

    /// Like [`Controller::new`], but an invalid configuration gives a controller running the
    /// nominal configuration with [`Fault::InvalidConfiguration`] latched; the fault cannot be
    /// cleared until [`Controller::set_parameters`] succeeds. For firmware that must boot.
    pub fn new_or_faulted(cfg: ControllerConfig) -> Self {
        match cfg.validate() {
            Ok(()) => Self::build(cfg),
            Err(e) => {
                let mut c = Self::build(ControllerConfig::nominal());
                c.config_error = Some(e);
                c.latch(Fault::InvalidConfiguration);
                c
            }
        }
    }

    const fn build(cfg: ControllerConfig) -> Self {
        let dt_s = 1.0 / cfg.tick_hz as f32;
        let a0 = cfg.axes[0];
        let a1 = cfg.axes[1];
        let mut c = Self {
            cfg,
            dt_s,
            axes: [
                AxisState::new(&cfg, &a0, dt_s),
                AxisState::new(&cfg, &a1, dt_s),
            ],
            planner: SetpointPlanner::REST,
            state: State::Idle,
            fault: None,
            config_error: None,
            host: HostWatch::new(cfg.host_timeout_s),
            commissioning: None,
            identified: [None; 2],
            identify_error: None,
            feedback: true,
            cos_axes: cos_const(cfg.axes_angle_rad),
            sin_axes: sin_const(cfg.axes_angle_rad),
            decouple_duty_per_rad_s: decouple_duty_per_rad_s(&cfg),
            reached: false,
            supply_cut: false,
        };
        // The precession's shaft turns about the vertical (teeth.rs).
        c.axes[0].est.about_the_vertical();
        c
    }

    /// Replaces the configuration, keeping the estimators' clocks.
    #[inline(never)]
    pub(super) fn rebuild_keep_state(&mut self, cfg: ControllerConfig) {
        let est = [self.axes[0].est, self.axes[1].est];
        let current = [self.axes[0].current, self.axes[1].current];
        let emf = [self.axes[0].emf, self.axes[1].emf];
        let load = [self.axes[0].load, self.axes[1].load];
        let identified = self.identified;
        let feedback = self.feedback;
        let supply_cut = self.supply_cut;
        *self = Self::build(cfg);
        self.supply_cut = supply_cut;
        for (a, (((e, c), l), m)) in self
            .axes
            .iter_mut()
            .zip(est.into_iter().zip(current).zip(load).zip(emf))
        {
            a.est = e;
            a.current = c;
            // The back-EMF learned in commissioning's steady runs (breakaway.rs).
            a.emf = m;
            a.load.adopt(&l);
        }
        self.identified = identified;
        self.feedback = feedback;
    }
}
