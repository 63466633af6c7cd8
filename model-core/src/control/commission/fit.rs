//! What commissioning makes of its steps (the module's "What is estimated" in [`super`]): the
//! steps' lines once the shaft has settled, the motor model from them, and the reaction.

use super::{
    Commissioning, Identified, IdentifyError, LineFit, MotorModel, Phase, REACTION_RAMP_S,
    SETTLE_MAX_S, SETTLE_TAUS,
};

impl Commissioning {
    /// The spin's ramp starts at `t_s` (the precession's clock); the fit starts once the ramp
    /// is done and both axes have settled (five time constants of each, at least the step
    /// time).
    pub(super) fn start_reaction(&mut self, t_s: f32) {
        let tau = |i: usize| {
            self.results[i]
                .map(|r| r.model.time_constant_s)
                .unwrap_or(0.0)
        };
        let settle_s = 5.0 * (tau(0) + tau(1));
        self.step_at_s = t_s;
        self.reaction_fit_from_s = t_s + REACTION_RAMP_S + settle_s.max(self.cfg.step_time_s);
        self.reaction_fit = LineFit::default();
        self.reaction_done_s = None;
        self.phase = Phase::Reaction;
    }

    /// `g = -dtheta1 / (K1 dw2)` (module docs) into the precession's model; left at 0 (the
    /// geometry's estimate) when a fit fails or the result is not plausible.
    pub(super) fn measure_reaction(&mut self) {
        let (Some(before), Some(after), Some(spin), Some(prec)) = (
            self.high_fit.solve_span(),
            self.reaction_fit.solve_span(),
            self.results[1],
            self.results[0].as_mut(),
        ) else {
            return;
        };
        // Where the spin accelerated: the middle of its ramp (should the precession's speed
        // differ slightly before and after, the lines' gap is taken there).
        let t = self.step_at_s + 0.5 * REACTION_RAMP_S;
        let lost_rad = (after.0 + after.1 * t) - (before.0 + before.1 * t);
        let gain = self.supply_v / prec.model.volts_per_rad_s;
        let g = -lost_rad / (gain * spin.high_speed_rad_s);
        if g.is_finite() && g.abs() <= 1.0 {
            // Exactly 0 means "not measured".
            prec.model.reaction_duty_s2_per_rad = if g == 0.0 { f32::MIN_POSITIVE } else { g };
        }
    }

    /// Whether a complete fit stands: it started at least [`SETTLE_TAUS`] time constants
    /// `tau_s` after its step at `step_s` (or [`SETTLE_MAX_S`]). If not, the step holds on and
    /// its fit starts again from there (a revolution or so more).
    pub(super) fn settled(&mut self, step_s: f32, tau_s: f32) -> bool {
        let from_s = step_s + (SETTLE_TAUS * tau_s).min(SETTLE_MAX_S);
        // A time constant that is no number stands as well.
        if from_s.is_nan() || from_s <= self.fit_from_s {
            return true;
        }
        self.fit_from_s = from_s;
        self.steady_pulses = 0;
        if self.phase == Phase::Low {
            self.low_fit = LineFit::default();
        } else {
            self.high_fit = LineFit::default();
        }
        false
    }

    /// The two steps' steady speeds `w_L`, `w_H` and the time constant from their lines (module
    /// docs), `None` without both lines.
    pub(super) fn step_lines(&self) -> Option<(f32, f32, f32)> {
        let (b_l, w_l) = self.low_fit.solve_span()?;
        let (b_h, w_h) = self.high_fit.solve_span()?;
        let t_s = self.step_at_s;
        Some((
            w_l,
            w_h,
            ((b_l + w_l * t_s) - (b_h + w_h * t_s)) / (w_h - w_l),
        ))
    }

    pub(super) fn identify(&self) -> Result<Identified, IdentifyError> {
        let (w_l, w_h, mut tau) = self.step_lines().ok_or(IdentifyError::TooFewEdges)?;
        let increased = w_l > 0.0 && w_h > w_l * 1.05;
        if !increased {
            return Err(IdentifyError::NoSpeedIncrease);
        }
        let v = self.supply_v;
        let (d_l, d_h) = (self.low_duty, self.high_duty);
        let a = v * (d_h - d_l) / (w_h - w_l);
        let mut friction_duty = d_l - a * w_l / v;
        // A slightly negative offset is fit noise around zero friction.
        if friction_duty < 0.0 && friction_duty > -0.02 {
            friction_duty = 0.0;
        }
        // Below a millisecond the estimate is noise; the loop design only needs its order.
        if tau < 1e-3 && tau > -0.02 {
            tau = 1e-3;
        }
        let model = MotorModel {
            volts_per_rad_s: a,
            friction_duty,
            time_constant_s: tau,
            breakaway_duty: self.breakaway_duty,
            reaction_duty_s2_per_rad: 0.0,
        };
        model
            .validate(self.axis as u8)
            .map_err(|_| IdentifyError::Implausible)?;
        Ok(Identified {
            model,
            low_speed_rad_s: w_l,
            high_speed_rad_s: w_h,
        })
    }
}
