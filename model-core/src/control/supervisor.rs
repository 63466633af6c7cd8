//! Operating states and faults.
//!
//! ```text
//!   Idle --start--> SpinningUp --(both references reached)--> Running
//!    ^  \                |  ^                                  |
//!    |   \--commission-->|  '------(new setpoint: ramping)-----'
//!    |                   v
//!    '--(both at rest)-- Stopping <--stop-- (SpinningUp | Running)
//!   any state --fault--> Fault --clear_fault--> Idle
//! ```
//! On a fault both duties go to zero in the same tick it is detected, and the bridge *coasts*
//! (zero duty means both half-bridges off, not shorted): a 150 to 300 mm bowl carrying a load
//! is not braked hard. A fault latches until [`crate::control::Controller::clear_fault`].

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
    SpinningUp = 2,
    /// Closed loop, both references reached and steady.
    Running = 3,
    /// Closed loop, ramping both references down to zero after a stop command.
    Stopping = 4,
    /// A fault latched: both duties zero until cleared.
    Fault = 5,
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
    /// The board's hardware stop tripped: the break input (an over-current comparator or the
    /// bridge driver's fault output) switched the PWM off without the CPU. The bridge cannot be
    /// trusted after it, so the board also cuts the motor supply ([`Fault::cuts_supply`]).
    HardwareStop,
}

impl Fault {
    /// Telemetry code: 0 means no fault; 1/2 sensor lost or stall on precession/spin,
    /// 3/4 over-speed on precession/spin, 5 host silent, 6 invalid configuration, 7 hardware
    /// stop.
    pub fn code(self) -> u8 {
        match self {
            Fault::SensorLostOrStall(a) => 1 + a.min(1),
            Fault::Overspeed(a) => 3 + a.min(1),
            Fault::HostSilent => 5,
            Fault::InvalidConfiguration => 6,
            Fault::HardwareStop => 7,
        }
    }

    /// Whether a board with a supply-cut switch opens it for this fault: the faults a bridge
    /// told to stop may not stop (its own hardware stop tripped). The others are stopped by the
    /// bridge itself (duty zero, TIM1's main output off).
    pub fn cuts_supply(self) -> bool {
        matches!(self, Fault::HardwareStop)
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

/// An edge interval faster than this many times the plant model's speed (plus the margin) is a
/// runaway: tooth offsets (up to 10 % on one interval), a 10 % overshoot and the breakaway of a
/// stiff shaft at the lowest speed stay inside.
pub const RUNAWAY_RATIO: f32 = 1.2;
/// See [`RUNAWAY_RATIO`], rad/s.
pub const RUNAWAY_MARGIN_RAD_S: f32 = 0.3;
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
    /// both `floor_s` has passed and the shaft should have turned three pitches: at a steady
    /// speed that is `max(floor_s, 3 pulse periods)`.
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
    ) -> bool {
        if edge_seen || duty_abs <= stall_duty {
            *self = Self::CLEAR;
            return false;
        }
        self.blind_s += dt_s;
        self.expected_rad += expected_rad_s.abs() * dt_s;
        self.blind_s > floor_s && self.expected_rad > WATCH_PITCHES * rad_per_pulse
    }

    /// Clears the watch.
    pub fn reset(&mut self) {
        *self = Self::CLEAR;
    }
}
