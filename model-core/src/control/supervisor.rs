//! Operating states and faults.
//!
//! ```text
//!   Idle --start--> ChangingSpeed --(both references reached)--> Running
//!    ^  \                |  ^                                  |
//!    |   \--commission-->|  '------(new setpoint: ramping)-----'
//!    |                   v
//!    '--(both at rest)-- Stopping <--stop-- (ChangingSpeed | Running)
//!   any state --fault--> Fault --clear_fault--> Idle
//! ```
//! On a fault both duties go to zero in the same tick it is detected, and the bridge *coasts*
//! (zero duty means both half-bridges off, not shorted): a 150 to 300 mm bowl carrying a load
//! is not braked hard. A fault latches until [`crate::control::Controller::clear_fault`].

mod current_watch;
pub use current_watch::{
    BACK_EMF_SPEED_SHARE, BACK_EMF_STEADY_SHARE, CURRENT_BAND_A, CURRENT_BAND_NOISE,
    CURRENT_LEARN_MIN_DUTY, CURRENT_OFFSET_LIMIT_A, CURRENT_OFFSET_SAMPLES,
    CURRENT_READING_LIMIT_A, CurrentTrip, CurrentWatch, OVERCURRENT_MARGIN, START_WINDOW,
    TURNING_BACK_EMF_SHARE, UNCOMMANDED_SHARE,
};

/// Operating state. The numeric value (`as u8`) is what telemetry carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum State {
    /// Motors off (zero duty); setpoints and parameters may be changed.
    Idle = 0,
    /// The identification routine drives one axis at a time open loop.
    Commissioning = 1,
    /// Closed loop, at least one reference still ramping or not yet reached.
    ChangingSpeed = 2,
    /// Closed loop, both references reached and steady.
    Running = 3,
    /// Closed loop, ramping both references down to zero after a stop command.
    Stopping = 4,
    /// A fault latched: both duties zero until cleared.
    Fault = 5,
}

/// The band, as a share of the reference, within which a reference counts as reached (plus
/// [`REACHED_FLOOR_RAD_S`]): [`State::ChangingSpeed`] becomes [`State::Running`] inside it.
pub const REACHED_SHARE: f32 = 0.05;
/// The band's floor, rad/s: a reference near zero is reached within this much.
pub const REACHED_FLOOR_RAD_S: f32 = 0.05;
/// How many times the band a running axis may stray before the state goes back to
/// [`State::ChangingSpeed`]. One band both ways made a speed that wanders about the band's edge
/// (an axis settled within 5 % whose tooth map is still a few percent off at low speed,
/// docs/control.md "The wheels learned in commissioning") flip between running and changing speed at every tick.
pub const LEAVE_RUNNING_BANDS: f32 = 2.0;

/// The closed loop's state after a tick that is not stopping: [`State::Running`] once both
/// ramps have ended at their targets and both measured speeds are within the reached band of
/// them, and while they stay within [`LEAVE_RUNNING_BANDS`] bands; [`State::ChangingSpeed`]
/// otherwise (a new target restarts the ramp, so a change of speed always shows).
pub fn closed_loop_state(
    was: State,
    ramped_rad_s: [f32; 2],
    target_rad_s: [f32; 2],
    measured_rad_s: [f32; 2],
) -> State {
    let bands = if was == State::Running {
        LEAVE_RUNNING_BANDS
    } else {
        1.0
    };
    let reached = (0..2).all(|i| {
        let band = bands * (REACHED_SHARE * ramped_rad_s[i].abs() + REACHED_FLOOR_RAD_S);
        ramped_rad_s[i] == target_rad_s[i] && (measured_rad_s[i] - ramped_rad_s[i]).abs() <= band
    });
    if reached {
        State::Running
    } else {
        State::ChangingSpeed
    }
}

/// A latched fault. [`Fault::code`] is the number telemetry carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fault {
    /// Duty above the stall threshold and no pulse for `max(floor, 3 expected pulse periods)`
    /// (expected from the plant model's speed) on this axis (0 = precession, 1 = spin): the sensor is dead or the shaft is blocked.
    /// Without a current measurement the two cannot be told apart.
    SensorLostOrStall(u8),
    /// Measured speed above the axis's over-speed limit.
    Overspeed(u8),
    /// No command or heartbeat from the host for longer than the configured timeout.
    HostSilent,
    /// The configuration is invalid, or commissioning identified an implausible model or timed out.
    InvalidConfiguration,
    /// The sensor-lost watch fired on this axis and the current shows the back-EMF of a turning
    /// shaft: the sensor (or its wiring) is dead. Only with current sense.
    SensorLost(u8),
    /// The sensor-lost watch fired on this axis and the current shows no back-EMF (near
    /// `V d / R`): the shaft is blocked. Only with current sense.
    Stall(u8),
    /// The current on this axis above [`OVERCURRENT_MARGIN`] times the stall current at the
    /// duty limit (a shorted winding, a bridge shorted across the supply). Only with current sense.
    OverCurrent(u8),
    /// The current on this axis above what the commanded duty drives at the measured speed
    /// (see [`UNCOMMANDED_SHARE`]), or any current at zero duty: a bridge driving harder than it
    /// is told (stuck on, shorted), or a shaft stopped dead under drive. Only with current sense.
    CurrentAboveModel(u8),
    /// The board's hardware stop tripped: the break input (an over-current comparator or the
    /// bridge driver's fault output) switched the PWM off without the CPU. The bridge cannot be
    /// trusted after it, so the board also cuts the motor supply ([`Fault::cuts_supply`]).
    HardwareStop,
}

impl Fault {
    /// Telemetry code: 0 means no fault; 1/2 sensor lost or stall on precession/spin,
    /// 3/4 over-speed on precession/spin, 5 host silent, 6 invalid configuration, 7/8 sensor
    /// lost, 9/10 stall, 11/12 over-current, 13/14 current above the model (precession/spin),
    /// 15 hardware stop.
    pub fn code(self) -> u8 {
        match self {
            Fault::SensorLostOrStall(a) => 1 + a.min(1),
            Fault::Overspeed(a) => 3 + a.min(1),
            Fault::HostSilent => 5,
            Fault::InvalidConfiguration => 6,
            Fault::SensorLost(a) => 7 + a.min(1),
            Fault::Stall(a) => 9 + a.min(1),
            Fault::OverCurrent(a) => 11 + a.min(1),
            Fault::CurrentAboveModel(a) => 13 + a.min(1),
            Fault::HardwareStop => 15,
        }
    }

    /// What caught the fault: the sensor's edges, the motor current, or the host link's
    /// watchdog (and the configuration check for an invalid configuration).
    pub fn detected_by(self) -> DetectedBy {
        match self {
            Fault::SensorLostOrStall(_)
            | Fault::Overspeed(_)
            | Fault::SensorLost(_)
            | Fault::Stall(_) => DetectedBy::Edges,
            Fault::OverCurrent(_) | Fault::CurrentAboveModel(_) => DetectedBy::Current,
            Fault::HardwareStop => DetectedBy::BreakInput,
            Fault::HostSilent => DetectedBy::Watchdog,
            Fault::InvalidConfiguration => DetectedBy::Configuration,
        }
    }

    /// Whether a board with a supply-cut switch opens it for this fault: the faults a bridge
    /// told to stop may not stop (its own hardware stop tripped). The others are stopped by the
    /// bridge itself (duty zero, TIM1's main output off).
    pub fn cuts_supply(self) -> bool {
        matches!(self, Fault::HardwareStop)
    }
}

/// What caught a fault (see [`Fault::detected_by`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DetectedBy {
    /// The sensor's edges: none where the model expects them, or too soon.
    Edges,
    /// The motor current (current sense).
    Current,
    /// The host link's watchdog (no command or heartbeat).
    Watchdog,
    /// The board's break input (TIM1_BKIN): the hardware stopped the bridge without the CPU
    /// and the board latched [`Fault::HardwareStop`].
    BreakInput,
    /// The configuration or commissioning check.
    Configuration,
}

impl DetectedBy {
    /// The report's word for it.
    pub fn word(self) -> &'static str {
        match self {
            DetectedBy::Edges => "edges",
            DetectedBy::Current => "current",
            DetectedBy::Watchdog => "watchdog",
            DetectedBy::BreakInput => "break input",
            DetectedBy::Configuration => "configuration",
        }
    }
}

/// Telemetry code of an optional fault (0 = none).
pub fn fault_code(f: Option<Fault>) -> u8 {
    f.map_or(0, Fault::code)
}

/// Pitches the plant model turns without an edge before the watch faults: below three, so a
/// fault comes within three expected pulse periods from the last edge; above two, so one
/// tooth's offset (a tenth of a pitch at most) or one missing pulse never faults a healthy shaft.
/// 2.8 rather than 2.6: a stiff shaft carrying material the model does not know breaks away
/// only when the push has found that load, and its first edge can come most of a pitch later
/// (docs/control.md, "Faults").
pub const WATCH_PITCHES: f32 = 2.8;

/// [`WATCH_PITCHES`] for a sensor that has dropped pulses lately (a worn target, a marginal
/// gap: [`super::estimator::PulseSpeedEstimator::dropping`]): two in a row leave an interval of
/// three pitches, and a tooth's offset or the shaft's own ripple lengthen it by up to the 0.3 the
/// missing-pulse inference allows. A dead sensor then faults within 3.3 expected pulse periods
/// of the last edge instead of 2.8 (docs/control.md, "Dropped pulses"); at 10 % of pulses dropped,
/// two in a row came every 17 s at 3 rad/s and faulted a healthy rig at 2.8.
pub const DROPPING_WATCH_PITCHES: f32 = 3.3;

/// An edge interval faster than this many times the plant model's speed (plus the margin) is a
/// runaway: tooth offsets (up to 10 % on one interval), a 10 % overshoot and the breakaway of a
/// stiff shaft at the lowest speed stay inside.
pub const RUNAWAY_RATIO: f32 = 1.2;
/// See [`RUNAWAY_RATIO`], rad/s.
pub const RUNAWAY_MARGIN_RAD_S: f32 = 0.3;

/// Whether an edge interval's speed `edge_rad_s` is a runaway: faster than [`RUNAWAY_RATIO`]
/// times (plus [`RUNAWAY_MARGIN_RAD_S`]) what the shaft may run at, the larger of the plant
/// model's speed `model_rad_s` (the reference through the identified lag) and `driven_rad_s`,
/// what the duty the loop applied drives the identified plant to
/// ([`super::observer::AngleObserver::driven_rad_s`]). The second is the observer's
/// expectation of a shaft the loop itself pushed: a heavy-friction shaft that crawled below its
/// lowest speed after a step down and was pushed off its crawl leaps well past the reference
/// (seed 7 p37 at 4 -> 0.2 rad/s: 0.62 rad/s under a 0.25 push, against 0.54 allowed by the
/// model alone), while a bridge stuck on drives the shaft past what the loop's (then
/// falling) duty drives.
pub fn edge_runaway(edge_rad_s: f32, model_rad_s: f32, driven_rad_s: f32) -> bool {
    edge_rad_s > RUNAWAY_RATIO * model_rad_s.abs().max(driven_rad_s) + RUNAWAY_MARGIN_RAD_S
}
/// Near the top speed, where full duty (a bridge stuck on) drives the shaft to less than
/// [`RUNAWAY_RATIO`] allows, the last two edge intervals together faster than this many times
/// the model's speed (plus the margin), at a steady reference, are a runaway too: tooth offsets
/// shorten two neighbouring intervals by at most 5 %. Only there: at lower speeds a start from
/// rest overshoots more than this long after its reference is steady.
pub const PAIR_RUNAWAY_RATIO: f32 = 1.1;
/// The pair rule is armed when the single-interval threshold exceeds this share of the model's
/// full-duty speed (material poured in since commissioning lowers the true one).
pub const PAIR_RUNAWAY_ARMED_SHARE: f32 = 0.8;
/// See [`PAIR_RUNAWAY_RATIO`], rad/s.
pub const PAIR_RUNAWAY_MARGIN_RAD_S: f32 = 0.1;
/// Near the top speed, the mean speed over the last whole revolution faster than this many
/// times the model's speed (plus the margin) is a runaway too: tooth offsets and a
/// once-per-revolution load cancel over a revolution, and a settled loop holds its mean on the
/// model, so a few per mille is evidence. On the seven 60-plant families (family-60, seeds 3 to
/// 8) at 0.2, 0.5, 1 and 3 rad/s no healthy shaft's revolution ran above 1.0025 x model +
/// 0.0025 rad/s once settled (7 of 420 did above 1 x model); twice that is the rule. A bridge
/// stuck on that full duty takes 9 % above its reference adds 0.7 % per interval.
pub const REVOLUTION_RUNAWAY_RATIO: f32 = 1.005;
/// See [`REVOLUTION_RUNAWAY_RATIO`], rad/s.
pub const REVOLUTION_RUNAWAY_MARGIN_RAD_S: f32 = 0.005;
/// The revolution rule also needs the duty this far below what the identified model needs:
/// a shaft that sped up because material left the bowl ran as fast for a revolution, but its
/// loop holds it on more duty than the model (the load's share still coming down), while a
/// bridge stuck on drives the loop's duty below the model.
pub const REVOLUTION_RUNAWAY_DUTY: f32 = 0.01;
/// Seconds of steady reference after which a loop has settled (the 2 % settling target): a
/// revolution judged by [`REVOLUTION_RUNAWAY_RATIO`] must begin after it.
pub const SETTLED_AFTER_S: f32 = 3.0;

/// A shaft that holds its reference on this much less duty than the identified model needs is
/// driven by something else (a bridge stuck on whose full duty takes it only a little above
/// the reference, below what [`PAIR_RUNAWAY_RATIO`] can tell from tooth offsets): the loop
/// lowers its duty against the excess speed and the check sees the duty fall below the model.
/// On the seven 60-plant families (family-60, seeds 3 to 8) at 0.2, 0.5, 1 and 3 rad/s a
/// healthy shaft never ran below the model by 0.02 once its references were reached;
/// 0.05 of the supply is 0.6 V on the nominal rig.
pub const DRIVEN_BELOW_MODEL_DUTY: f32 = 0.05;
/// Seconds of steady reference before [`PAIR_RUNAWAY_RATIO`] applies (the model has settled and
/// the two intervals do not lag a ramp).
pub const PAIR_RUNAWAY_STEADY_S: f32 = 1.0;

/// The sensor-lost watch of one axis: time spent driving above the stall duty without an edge,
/// and how far the shaft should have turned meanwhile.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SensorWatch {
    blind_s: f32,
    expected_rad: f32,
}

impl SensorWatch {
    /// A cleared watch.
    pub const CLEAR: Self = Self {
        blind_s: 0.0,
        expected_rad: 0.0,
    };

    /// Advances the watch; true when the axis must fault.
    ///
    /// `expected_rad_s` is the speed the shaft should have now (the plant model's speed while
    /// running, so an accelerating shaft is not blamed for the reference's lead), `rad_per_pulse`
    /// the pitch. The fault comes when, with the duty above the stall threshold and no edge,
    /// both `floor_s` has passed and the shaft should have turned `watch_pitches` pitches
    /// ([`WATCH_PITCHES`], or [`DROPPING_WATCH_PITCHES`] for a sensor that drops pulses): at a
    /// steady speed that is `max(floor_s, 3 pulse periods)`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        dt_s: f32,
        duty_abs: f32,
        stall_duty: f32,
        edge_seen: bool,
        floor_s: f32,
        expected_rad_s: f32,
        rad_per_pulse: f32,
        watch_pitches: f32,
    ) -> bool {
        if edge_seen || duty_abs <= stall_duty {
            *self = Self::CLEAR;
            return false;
        }
        self.blind_s += dt_s;
        self.expected_rad += expected_rad_s.abs() * dt_s;
        self.blind_s > floor_s && self.expected_rad > watch_pitches * rad_per_pulse
    }

    /// Clears the watch.
    pub fn reset(&mut self) {
        *self = Self::CLEAR;
    }
}
