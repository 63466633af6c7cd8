//! Releases on the simulated rig: the one plant with the controller
//! (`virtual_rig::SimulatedBackend`), and a granule that follows the rig file's
//! `[particle]` truth under the plant's true bowl speed (paper Eq. 2 from the two true shaft
//! speeds). What the experiment records is what a real rig records: the gate times (with the
//! gate's jitter) and the controller's *measured* speeds.

use anyhow::{Result, anyhow};
use model_core::control::State;
use model_core::sim::PlantParams;
use model_core::sim::granule::ParticleParams;
use model_core::wire::GateKind;

use virtual_rig::SimulatedBackend;

/// Speed trace sampling period, ms.
const TRACE_PERIOD_MS: u32 = 10;
/// A speed counts as settled within this fraction of its target (or 0.02 rad/s)...
const SETTLED_BAND: f64 = 0.02;
/// ...held for this long, ms.
const SETTLED_HOLD_MS: u32 = 1000;
/// Give up waiting for the speeds after this long, ms.
const SETTLE_TIMEOUT_MS: u32 = 30_000;
/// Give up on a granule after this long in the bowl, ms.
const RESIDENCE_TIMEOUT_MS: u32 = 60_000;

/// How a release ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Release {
    /// The exit gate fired: residence time (s, with gate jitter, microsecond resolution) and the
    /// measured speed trace (s since release, rad/s).
    Left(f64, Vec<(f64, f64)>),
    /// Still in the bowl at the time limit (trace attached).
    NeverLeft(Vec<(f64, f64)>),
    /// The speeds did not settle in time.
    NotSettled,
    /// The controller faulted (its fault named).
    MotorFault(String),
}

/// The experiment's rig on a `SimulatedBackend` driven directly (no protocol device between):
/// the simulated counterpart of [`super::port::PortRig`].
pub struct BackendRig {
    backend: SimulatedBackend,
    now_ms: u32,
}

impl BackendRig {
    /// The plant, commissioned, with the given granule truth.
    pub fn new(plant: PlantParams, particle: ParticleParams, seed: u32) -> Result<Self> {
        let mut backend = SimulatedBackend::with_plant(plant, particle, seed)?;
        // The experiment drives the controller directly, with no link to lose: the rig's
        // link-loss watchdog (LINK_TIMEOUT_MS) is off here.
        model_core::wire::device::Backend::set_param(
            backend.bound_mut(),
            model_core::wire::ParamId::LinkTimeoutMs,
            0,
        )
        .map_err(|r| anyhow!("cannot turn the link watchdog off: {}", r.token()))?;
        Ok(Self { backend, now_ms: 0 })
    }

    /// The granule truth.
    pub fn particle(&self) -> ParticleParams {
        *self.backend.bound().injector().particle()
    }

    /// Motor speeds for a combined bowl speed by the controller's split rule.
    fn split_speeds(&self, bowl_rad_s: f64) -> Result<[f64; 2]> {
        let cfg = self.backend.bound().controller().config();
        let s = model_core::control::planner::split_combined(
            bowl_rad_s as f32,
            cfg.axes_angle_rad.cos(),
            cfg.axes_angle_rad.sin(),
            cfg.spin_per_precession,
        )
        .ok_or_else(|| anyhow!("bowl speed {bowl_rad_s} rad/s cannot be split"))?;
        Ok(s.map(crate::number::from_f32))
    }

    /// The fastest combined bowl speed whose split keeps both motors within their limits.
    pub fn max_bowl_rad_s(&self) -> Result<f64> {
        let per_unit = self.split_speeds(1.0)?;
        let cfg = self.backend.bound().controller().config();
        Ok((0..2)
            .map(|i| f64::from(cfg.axes[i].max_speed_rad_s) / per_unit[i].abs().max(1e-9))
            .fold(f64::INFINITY, f64::min))
    }

    fn tick_ms(&mut self) {
        self.now_ms = self.now_ms.wrapping_add(1);
        self.backend.advance_to_ms(self.now_ms);
    }

    /// A fault the controller latched, in the words a rig over its serial line gives for it:
    /// its state and fault as the rig's telemetry carries them (the binding's conversions).
    fn fault(&self) -> Option<String> {
        let c = self.backend.bound().controller();
        super::reported_fault(c.state().into(), c.fault().into())
    }

    fn clear_fault(&mut self) {
        let _ = self.backend.bound_mut().controller_mut().clear_fault();
    }

    fn settle_speeds(&mut self, targets: [f64; 2], settle_s: f64) -> Result<(), Release> {
        let ctrl = self.backend.bound_mut().controller_mut();
        if let Err(e) = ctrl.set_motor_speeds(targets[0] as f32, targets[1] as f32) {
            return Err(Release::MotorFault(format!(
                "speeds {:.3}, {:.3} rad/s refused by the controller: {}",
                targets[0],
                targets[1],
                virtual_rig::controller_words::rejection(e)
            )));
        }
        if ctrl.state() == State::Idle {
            let _ = ctrl.start();
        }
        let mut held = 0;
        let mut waited = 0;
        while held < SETTLED_HOLD_MS {
            self.tick_ms();
            waited += 1;
            if let Some(f) = self.fault() {
                self.clear_fault();
                return Err(Release::MotorFault(f));
            }
            let st = self.backend.bound().controller().status();
            let ok = (0..2).all(|i| {
                let m = f64::from(st.axes[i].measured_rad_s);
                (m - targets[i]).abs() <= (SETTLED_BAND * targets[i].abs()).max(0.02)
            });
            held = if ok { held + 1 } else { 0 };
            if waited > SETTLE_TIMEOUT_MS {
                return Err(Release::NotSettled);
            }
        }
        for _ in 0..(settle_s * 1000.0) as u32 {
            self.tick_ms();
        }
        Ok(())
    }

    /// Drops one granule (RELEASE, as on the wire) and follows it to the exit gate; the
    /// residence time is the exit gate's time minus the release gate's, as a real rig's
    /// events give it.
    fn drop_granule(&mut self) -> Release {
        use model_core::wire::device::Backend as _;
        if let Err(r) = self.backend.bound_mut().release() {
            return Release::MotorFault(format!("RELEASE refused: {}", r.token()));
        }
        let mut released_us = None;
        let mut trace = Vec::new();
        for ms in 0..RESIDENCE_TIMEOUT_MS {
            if ms % TRACE_PERIOD_MS == 0 {
                let w = f64::from(
                    self.backend
                        .bound()
                        .controller()
                        .status()
                        .combined_measured_rad_s,
                );
                trace.push((f64::from(ms) * 1e-3, w));
            }
            self.tick_ms();
            if let Some(f) = self.fault() {
                self.clear_fault();
                self.backend.world_mut().clear_bowl();
                return Release::MotorFault(f);
            }
            while let Some(e) = self.backend.bound_mut().next_gate_event() {
                match (e.kind, released_us) {
                    (GateKind::Release, _) => released_us = Some(e.time_us),
                    (GateKind::Exit, Some(at)) => {
                        // Divided, not multiplied by 1e-6: 1066302 us is written 1.066302 s,
                        // not 1.0663019999999999.
                        return Release::Left(f64::from(e.time_us.wrapping_sub(at)) / 1e6, trace);
                    }
                    (GateKind::Exit, None) => {}
                }
            }
        }
        self.backend.world_mut().clear_bowl();
        Release::NeverLeft(trace)
    }

    /// Injects a fault into the simulated rig (as INJECT does on the wire).
    #[cfg(test)]
    pub fn inject(&mut self, what: model_core::wire::Injection) -> Result<()> {
        use model_core::wire::device::Backend as _;
        self.backend
            .bound_mut()
            .inject(what)
            .map_err(|r| anyhow!("injection refused: {}", r.token()))
    }
}

impl super::ReleaseRig for BackendRig {
    fn geometry(&self) -> (f64, f64, f64) {
        let p = self.particle();
        (p.release_radius_m, p.rim_radius_m, p.k2)
    }

    fn split(&self, bowl_rad_s: f64) -> Result<[f64; 2]> {
        self.split_speeds(bowl_rad_s)
    }

    /// The rig's AXES_MDEG parameter, as a rig over its serial line gives it: the simulated
    /// rig sets it to the tilt its granules feel (`SimulatedBackend::with_plant`).
    fn axes_angle_rad(&self) -> f64 {
        use model_core::wire::device::Backend as _;
        let mdeg = self
            .backend
            .bound()
            .param(model_core::wire::ParamId::AxesMdeg);
        super::axes_angle_rad(f64::from(mdeg))
    }

    /// The simulated rig draws each bowl-model granule's azimuth and knows it.
    fn last_release_azimuth_deg(&self) -> Option<f64> {
        self.backend
            .bound()
            .injector()
            .last_bowl_release()
            .map(|r| r.azimuth_rad.to_degrees())
    }

    fn settle(&mut self, targets: [f64; 2], settle_s: f64) -> Result<(), Release> {
        self.settle_speeds(targets, settle_s)
    }

    fn release(&mut self) -> Release {
        self.drop_granule()
    }

    /// Stops the motors (ramping down).
    fn stop(&mut self) {
        let _ = self.backend.bound_mut().controller_mut().stop();
    }

    fn max_speeds_rad_s(&self) -> Option<[f64; 2]> {
        let cfg = self.backend.bound().controller().config();
        Some([0, 1].map(|i| f64::from(cfg.axes[i].max_speed_rad_s)))
    }
}
