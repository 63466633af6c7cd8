//! The controller while commissioning runs: the tick that feeds the axis under test's edges to
//! the identification (commission.rs), and what its end leaves (the identified models, or the
//! fault a failed identification latches).

use super::Controller;
use crate::control::commission::{IdentifyError, Phase};
use crate::control::supervisor::{Fault, State, WATCH_PITCHES};

impl Controller {
    /// The tick while commissioning: the estimators also feed the identification routine.
    #[inline(never)]
    pub(super) fn tick_commissioning(&mut self, now_ticks: u32, edges: [&[u32]; 2]) -> [f32; 2] {
        let dt = self.dt_s;
        let mut seen = [false; 2];
        let (comm_axis, wheels) = match &self.commissioning {
            Some(c) => (c.progress().0, c.wheels_steady()),
            None => (2, false),
        };
        for i in 0..2 {
            let a = &mut self.axes[i];
            let rad_per_pulse = a.est.rad_per_pulse();
            let mut comm = if i == comm_axis {
                self.commissioning.as_mut()
            } else {
                None
            };
            let seen_i = &mut seen[i];
            a.est.learn_teeth(wheels);
            let speed = a.est.tick(now_ticks, edges[i], false, |at, pulses| {
                *seen_i = true;
                if let Some(c) = comm.as_deref_mut() {
                    c.on_edge(at, pulses, rad_per_pulse);
                }
            });
            a.measured = a.direction * speed;
            if speed > self.cfg.axes[i].overspeed_rad_s {
                self.latch(Fault::Overspeed(i as u8));
            }
        }
        if self.state == State::Commissioning {
            self.commission_step(dt, &seen);
        }
        self.after_tick(dt)
    }

    #[inline(never)]
    fn commission_step(&mut self, dt: f32, seen: &[bool; 2]) {
        let Some(c) = self.commissioning.as_mut() else {
            self.state = State::Idle;
            return;
        };
        let axis = c.progress().0;
        // The load pattern of each step, with the wheel's, for load_pattern::adopt.
        let a = &mut self.axes[axis];
        a.load.commission_tick(&a.est, a.duty, c.steady_step());
        let clock = self.axes[axis].est.clock_ticks();
        match c.step(
            dt,
            clock,
            self.axes[0].est.is_stopped() && self.axes[1].est.is_stopped(),
            self.axes[0].est.teeth().learned() && self.axes[1].est.teeth().learned(),
        ) {
            Err(e) => {
                self.identify_error = Some(e);
                self.commissioning = None;
                // No edge at any duty: a dead sensor or a blocked shaft, the same fault as
                // in closed loop; anything else leaves the configuration unidentified.
                self.latch(if e == IdentifyError::NoBreakaway {
                    Fault::SensorLostOrStall(axis as u8)
                } else {
                    Fault::InvalidConfiguration
                });
            }
            Ok(duties) => {
                self.axes[0].duty = duties[0];
                self.axes[1].duty = duties[1];
                if c.progress().1 == Phase::Done {
                    let results = c.results();
                    self.commissioning = None;
                    self.identified = results;
                    let mut cfg = self.cfg;
                    for (i, r) in results.iter().enumerate() {
                        if let Some(r) = r {
                            cfg.axes[i].model = r.model;
                        }
                    }
                    match cfg.validate() {
                        Ok(()) => {
                            self.rebuild_keep_state(cfg);
                            self.state = State::Idle;
                        }
                        Err(e) => {
                            self.config_error = Some(e);
                            self.latch(Fault::InvalidConfiguration);
                        }
                    }
                    return;
                }
                // Blocked shaft or dead sensor during identification: the expected period is
                // unknown, so allow 3 periods at the lowest speed.
                for (i, &seen_i) in seen.iter().enumerate() {
                    let a = &mut self.axes[i];
                    if a.watch.step(
                        dt,
                        a.duty.abs(),
                        self.cfg.stall_duty,
                        seen_i,
                        self.cfg.sensor_timeout_floor_s,
                        self.cfg.axes[i].min_speed_rad_s,
                        a.est.rad_per_pulse(),
                        WATCH_PITCHES,
                    ) {
                        self.identify_error = Some(IdentifyError::TooFewEdges);
                        self.latch(Fault::SensorLostOrStall(i as u8));
                        return;
                    }
                }
            }
        }
    }
}
