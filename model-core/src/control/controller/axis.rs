//! One motor axis's runtime state inside the controller.

use crate::control::breakaway::BackEmfScale;
use crate::control::config::{AxisConfig, ControllerConfig};
use crate::control::estimator::PulseSpeedEstimator;
use crate::control::load_pattern::LoadPattern;
use crate::control::observer::{AngleObserver, ObserverConstants};
use crate::control::pi::{LoopConstants, SpeedLoop};
use crate::control::supervisor::{CurrentWatch, SensorWatch};

/// What the controller keeps per axis between ticks: the speed estimator, the loop and its
/// constants, the sensor watch, and the last outputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct AxisState {
    /// Speed from the edge timestamps.
    pub(super) est: PulseSpeedEstimator,
    /// The loop's constants for this axis's motor model and bandwidth.
    pub(super) k: LoopConstants,
    /// Feedforward + PI state.
    pub(super) speed_loop: SpeedLoop,
    /// Stall / lost-sensor detection.
    pub(super) watch: SensorWatch,
    /// Largest setpoint change per tick (the acceleration limit times the tick), rad/s.
    pub(super) max_step: f32,
    /// Duty applied, -1..=1.
    pub(super) duty: f32,
    /// Measured speed with the commanded sign, rad/s.
    pub(super) measured: f32,
    /// The commanded direction (+1 or -1): one sensor per shaft cannot tell.
    pub(super) direction: f32,
    /// The once-per-revolution load, learned and fed forward.
    pub(super) load: LoadPattern,
    /// The speed is steady this tick (the reference unchanged, the shaft near the model).
    pub(super) steady: bool,
    /// The current sense's offset, current per duty and back-EMF (none: never sampled).
    pub(super) current: CurrentWatch,
    /// The back-EMF per rad/s the current shows at speeds the edges measure (kept across
    /// starts; breakaway.rs).
    pub(super) emf: BackEmfScale,
    /// This tick's current reading as the duty that drives it into a held shaft, for the loop
    /// (see `LoopInput::torque_duty`); taken by the loop each tick.
    pub(super) torque_duty: Option<f32>,
    /// The shaft's angle, speed and unknown load, by the identified plant and the edges.
    pub(super) obs: AngleObserver,
    /// The observer's constants for this axis's motor model.
    pub(super) ok: ObserverConstants,
    /// What the last duty held beyond the identified model (the spin's reaction on the
    /// precession axis, the once-per-revolution load): not what drives the observer's plant.
    pub(super) extra_duty: f32,
    /// With the drive off: the time since the last edge when this was judged (negative: not
    /// judged, or the drive is on), and when the plant model puts the shaft at rest, both
    /// counted from the last edge, s; see [`AxisState::settle_coasted`].
    pub(super) coast_from_s: f32,
    pub(super) coast_rest_s: f32,
}

/// A coasting shaft reads at rest once the time since its last edge is this many times what
/// its plant model takes from that edge to rest (the time scales with the inertia, and the
/// material poured in since commissioning adds inertia the model does not know), ...
pub const COAST_MARGIN: f32 = 3.0;
/// ... plus this, s (a shaft the model stops at its last edge still gets a fifth of a second).
pub const COAST_MIN_S: f32 = 0.2;

impl AxisState {
    /// At rest, for axis configuration `a` of `cfg`, ticking every `dt_s`.
    pub(super) const fn new(cfg: &ControllerConfig, a: &AxisConfig, dt_s: f32) -> Self {
        Self {
            est: PulseSpeedEstimator::new(cfg, a),
            k: LoopConstants::new(a, dt_s, cfg.supply_v),
            speed_loop: SpeedLoop::REST,
            watch: SensorWatch::CLEAR,
            max_step: a.accel_limit_rad_s2 * dt_s,
            duty: 0.0,
            measured: 0.0,
            direction: 1.0,
            load: LoadPattern::new(a, cfg.supply_v),
            steady: false,
            current: CurrentWatch::NEW,
            emf: BackEmfScale::NONE,
            torque_duty: None,
            obs: AngleObserver::REST,
            ok: ObserverConstants::new(a, dt_s, cfg.supply_v),
            extra_duty: 0.0,
            coast_from_s: -1.0,
            coast_rest_s: 0.0,
        }
    }

    /// With the drive off (`drive_off`: the reference ramped to zero, or a fault; and the duty
    /// zero), reads the shaft at rest once [`COAST_MARGIN`] times the time its plant model
    /// takes from the last edge to rest has passed since that edge (plus [`COAST_MIN_S`]). The
    /// model's coast is judged once, from the faster of the measured and the observer's speed
    /// (`AngleObserver::coast_s`), and again after any later edge. The estimator alone waits
    /// for two pitches at the lowest speed without an edge (5.2 s at 12 teeth and 0.2 rad/s):
    /// a stopped rig read `stopping`, and its speed the bound `pitch / time since the last
    /// edge`, for 5 s after its shafts stood still (STOP from 2.4 rad/s; a fault's coast, and
    /// reversals, waited for it too). True when it read the shaft at rest.
    pub(super) fn settle_coasted(&mut self, drive_off: bool) -> bool {
        if !drive_off || self.duty != 0.0 || self.est.is_stopped() {
            self.coast_from_s = -1.0;
            return false;
        }
        let since = self.est.since_edge_s();
        // Not judged yet, or an edge since (the shaft still turned): judge from here.
        if self.coast_from_s < 0.0 || since < self.coast_from_s {
            let w = self.measured.abs().max(self.obs.speed_rad_s());
            self.coast_from_s = since;
            self.coast_rest_s = since + self.obs.coast_s(&self.ok, w);
        }
        if since < COAST_MARGIN * self.coast_rest_s + COAST_MIN_S {
            return false;
        }
        self.est.settle_at_rest();
        self.measured = 0.0;
        self.coast_from_s = -1.0;
        true
    }

    /// Loop and sensor watch back to rest (a fresh start).
    pub(super) const fn rest_loop(&mut self) {
        self.speed_loop = SpeedLoop::REST;
        self.watch = SensorWatch::CLEAR;
        self.load.forget();
        self.current.restart();
    }
}
