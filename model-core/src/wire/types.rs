//! The plain data that travels over the wire: telemetry, commands, answers.
//!
//! Every number is a scaled integer with its unit in its name (`_mrad_s` = milliradians per
//! second, `_ms` = milliseconds, `_bp` = basis points, 1/10 000). Each enum has a fixed numeric or
//! token form, listed in `docs/protocol.md`. The settable parameters are one table of their
//! own: [`super::params`], the commands too: [`super::commands`]; the frames that carry
//! them: [`super::frame`].

/// Pulse-count, sequence-number and request-id fields wrap modulo 2^16.
pub type Wrapping16 = u16;

/// What the rig is doing (the numbers are the controller's `State as u8`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DeviceState {
    /// Motors off, waiting for a command.
    Idle = 0,
    /// The identification routine drives one axis at a time, open loop.
    Commissioning = 1,
    /// Closed loop, ramping towards the setpoints.
    ChangingSpeed = 2,
    /// Closed loop, at the setpoints.
    Running = 3,
    /// Ramping down after STOP.
    Stopping = 4,
    /// A fault stopped the motors; CLEAR returns to Idle.
    Faulted = 5,
}

/// Why the rig stopped itself (0 = no fault; the numbers are the controller's fault codes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FaultCode {
    /// No fault.
    None = 0,
    /// Precession: duty above the stall threshold and no pulse (sensor dead or shaft blocked).
    SensorLostOrStallPrecession = 1,
    /// Spin: duty above the stall threshold and no pulse (sensor dead or shaft blocked).
    SensorLostOrStallSpin = 2,
    /// The precession motor exceeded its over-speed limit.
    OverspeedPrecession = 3,
    /// The spin motor exceeded its over-speed limit.
    OverspeedSpin = 4,
    /// No command or heartbeat (PING) from the PC within the host timeout.
    HostSilent = 5,
    /// The configuration is invalid, or commissioning failed.
    InvalidConfiguration = 6,
    /// Precession: no pulse, and the current shows a turning shaft (sensor dead).
    SensorLostPrecession = 7,
    /// Spin: no pulse, and the current shows a turning shaft (sensor dead).
    SensorLostSpin = 8,
    /// Precession: no pulse, and the current shows no back-EMF (shaft blocked).
    StallPrecession = 9,
    /// Spin: no pulse, and the current shows no back-EMF (shaft blocked).
    StallSpin = 10,
    /// Precession: current above the over-current limit.
    OverCurrentPrecession = 11,
    /// Spin: current above the over-current limit.
    OverCurrentSpin = 12,
    /// Precession: more current than the duty drives at the measured speed (a bridge stuck on
    /// or shorted).
    CurrentAboveModelPrecession = 13,
    /// Spin: more current than the duty drives at the measured speed (a bridge stuck on or
    /// shorted).
    CurrentAboveModelSpin = 14,
    /// The board's hardware stop (break input: over-current comparator or driver fault) cut the
    /// PWM; the motor supply is cut too where the board has the switch.
    HardwareStop = 15,
}

/// What caused the last reset of the microcontroller (STM32 RCC_CSR flags).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResetCause {
    /// Power-on or brown-out reset.
    PowerOn = 0,
    /// The NRST pin (reset button, debugger).
    Pin = 1,
    /// A software reset request.
    Software = 2,
    /// The independent watchdog.
    IndependentWatchdog = 3,
    /// The window watchdog.
    WindowWatchdog = 4,
    /// A low-power management reset.
    LowPower = 5,
    /// No flag set, or a simulated rig.
    Unknown = 6,
}

/// Which residence-time model a target refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResidenceModel {
    /// Rolling sphere without the Coriolis term (paper Eq. 5-7). Token `FLAT`.
    Flat,
    /// With the Coriolis friction term (paper Eq. 9-11, coefficients corrected). Token `CORI`.
    Coriolis,
    /// The residence-time table the PC computed with the model chosen for the rig's bowl, tilt
    /// and granule and stored in the `RT_*` parameters (docs/model.md §11). Token `TABLE`.
    Table,
}

/// A predicted residence time as sent in telemetry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Residence {
    /// The particle reaches the rim after this many milliseconds (at most [`RESIDENCE_MAX_MS`]).
    Ms(u32),
    /// The particle never leaves: its start radius is inside the equilibrium radius. Wire: `-1`.
    NeverLeaves,
    /// No prediction (bowl at rest, model not configured, or longer than [`RESIDENCE_MAX_MS`]).
    /// Wire: `-2`.
    Unavailable,
}

/// The largest residence time telemetry can carry, ms (2.8 hours; 7 digits keep the frame short).
pub const RESIDENCE_MAX_MS: u32 = 9_999_999;

/// The largest PWM duty magnitude, basis points (10 000 = 100 %).
pub const DUTY_MAX_BP: i16 = 10_000;

/// One motor's line in a telemetry frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotorTelemetry {
    /// Speed setpoint, mrad/s at the output shaft.
    pub set_mrad_s: i16,
    /// Measured speed from the pulse estimator, mrad/s.
    pub measured_mrad_s: i16,
    /// PWM duty, basis points, -10 000..=10 000 (sign = direction).
    pub duty_bp: i16,
    /// Sensor pulses counted since reset, modulo 2^16.
    pub pulses: Wrapping16,
}

/// One telemetry frame (`$T1,...`): the periodic report of the rig.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Telemetry {
    /// Device time since reset, ms (wraps after 49.7 days).
    pub time_ms: u32,
    /// Telemetry sequence number, +1 per frame, modulo 2^16: gaps count the lost frames.
    pub seq: Wrapping16,
    /// Device state.
    pub state: DeviceState,
    /// Active fault (None unless `state` is Faulted).
    pub fault: FaultCode,
    /// Precession motor (omega1, the rod about the vertical).
    pub precession: MotorTelemetry,
    /// Spin motor (omega2, the bowl about its own axis).
    pub spin: MotorTelemetry,
    /// Combined bowl speed from the measured motor speeds (paper Eq. 2), mrad/s.
    pub bowl_mrad_s: u16,
    /// Predicted residence time without the Coriolis term at the measured speeds.
    pub residence_flat: Residence,
    /// Predicted residence time with the Coriolis term at the measured speeds.
    pub residence_coriolis: Residence,
}

/// The boot announcement (`$H1,...`), sent once after every reset.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Hello {
    /// Why the device reset.
    pub reset_cause: ResetCause,
    /// Resets since the counter was last cleared (kept in backup RAM on the MCU), modulo 2^16.
    pub reset_count: Wrapping16,
}

/// Which gate fired (`$E1` field 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum GateKind {
    /// The release trigger: a granule was dropped at the start radius.
    Release = 0,
    /// The exit light gate at the rim: a granule left the bowl.
    Exit = 1,
}

/// A gate event (`$E1,...`), sent by the device when a gate input fires, outside the telemetry
/// rate: the residence time is the difference of an exit and the release before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GateEvent {
    /// Which gate.
    pub kind: GateKind,
    /// Device time of the captured edge, microseconds since reset (the proximity sensors' time
    /// base), modulo 2^32.
    pub time_us: u32,
    /// The reset counter of the boot that measured it ([`Hello::reset_count`]): events of
    /// different boots have unrelated times.
    pub boot: Wrapping16,
}

/// The answer to STATUS (`$S1,...`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Status {
    /// Device state.
    pub state: DeviceState,
    /// Active fault.
    pub fault: FaultCode,
    /// Why the device last reset.
    pub reset_cause: ResetCause,
    /// Reset counter, modulo 2^16.
    pub reset_count: Wrapping16,
    /// Device time since reset, ms.
    pub uptime_ms: u32,
    /// Telemetry rate, frames per second (0 = off).
    pub telemetry_hz: u8,
    /// Board conditions the PC should know about, one bit each ([`status_flags`]); 0 = none.
    pub flags: u8,
}

/// The bits of [`Status::flags`] (a rig without such conditions, e.g. the virtual one, sends 0).
pub mod status_flags {
    /// This boot started from the default parameters and motor models: the parameter flash
    /// held no valid record (empty, corrupt, another layout) or its values were refused.
    pub const PARAMS_DEFAULTS: u8 = 1 << 0;
    /// The last parameter save failed (flash keeps the record before it).
    pub const PARAMS_SAVE_FAILED: u8 = 1 << 1;
    /// The board runs on its internal RC oscillator: the crystal did not start.
    pub const CLOCK_FALLBACK: u8 = 1 << 2;
}

/// A fault the simulated or emulated rig can be told to produce (real hardware rejects it with
/// [`Reason::Unsupported`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Injection {
    /// Remove every injected fault. Token `NONE`.
    None,
    /// The precession sensor stops giving pulses. Token `SENSOR1`.
    SensorLostPrecession,
    /// The spin sensor stops giving pulses. Token `SENSOR2`.
    SensorLostSpin,
    /// The precession motor is blocked. Token `STALL1`.
    StallPrecession,
    /// The spin motor is blocked. Token `STALL2`.
    StallSpin,
}

/// One axis's motor model and speed-loop gains as the rig uses them (a `M` answer), scaled
/// integers like every wire field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisModel {
    /// Whether the model was identified by COMMISSION, on this boot or on the one that stored
    /// it (the flag is persisted with the model); otherwise it is the nominal one.
    pub identified: bool,
    /// Effective back-EMF constant, microvolts per rad/s (0..=[`MODEL_FIELD_MAX`]).
    pub back_emf_uv_per_rad_s: u32,
    /// Duty that balances Coulomb friction, parts per million of full duty.
    pub friction_ppm: u32,
    /// Mechanical time constant, microseconds.
    pub time_constant_us: u32,
    /// Proportional gain at the loop's bandwidth ceiling (`control::pi::bandwidth_ceiling_rad_s`),
    /// duty ppm per rad/s of speed error.
    pub kp_ppm_per_rad_s: u32,
    /// Integral gain at the same bandwidth, duty ppm per rad of accumulated speed error.
    pub ki_ppm_per_rad: u32,
}

/// The largest value of an [`AxisModel`] field (the encoder refuses larger ones).
pub const MODEL_FIELD_MAX: u32 = 2_000_000_000;

/// Why a command was rejected. A rejected command changed nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Reason {
    /// The frame's CRC was right but its fields did not parse. Token `MALFORMED`.
    Malformed,
    /// The command word is not known. Token `UNKNOWN`.
    UnknownCommand,
    /// The parameter name is not known. Token `PARAM`.
    UnknownParam,
    /// A value was outside its range (never clamped). Token `RANGE`.
    Range,
    /// Not allowed in the current state (for instance START while faulted). Token `STATE`.
    State,
    /// The target cannot be reached (for instance a residence time the bowl cannot produce
    /// within the speed limit, a particle that never leaves, a residence-time table that speed
    /// barely moves, or no table stored for `RTIME TABLE`). Token `INFEASIBLE`.
    Infeasible,
    /// This device does not do that (fault injection on real hardware). Token `UNSUPPORTED`.
    Unsupported,
    /// The frame's protocol version is not spoken here. Token `VERSION`.
    Version,
    /// The device could not build its answer (a value it holds is outside the wire range:
    /// a bug). Token `INTERNAL`.
    Internal,
    /// A line typed at a plain console ([`super::console`]) that the rig could not read as
    /// words: it held a byte no command has (an arrow or function key, a Ctrl key, a letter
    /// beyond ASCII such as `µ`, a frame's `,` or `*`) or was longer than
    /// [`super::console::CONSOLE_LINE_MAX`]. Only typed lines get it: the PC's frames never
    /// do, so an older PC meets it only in a console. Token `UNREADABLE`.
    Unreadable,
}

impl Reason {
    /// Every reason.
    pub const ALL: [Reason; 10] = [
        Reason::Malformed,
        Reason::UnknownCommand,
        Reason::UnknownParam,
        Reason::Range,
        Reason::State,
        Reason::Infeasible,
        Reason::Unsupported,
        Reason::Version,
        Reason::Internal,
        Reason::Unreadable,
    ];

    /// The wire token.
    pub fn token(self) -> &'static str {
        match self {
            Reason::Malformed => "MALFORMED",
            Reason::UnknownCommand => "UNKNOWN",
            Reason::UnknownParam => "PARAM",
            Reason::Range => "RANGE",
            Reason::State => "STATE",
            Reason::Infeasible => "INFEASIBLE",
            Reason::Unsupported => "UNSUPPORTED",
            Reason::Version => "VERSION",
            Reason::Internal => "INTERNAL",
            Reason::Unreadable => "UNREADABLE",
        }
    }
    /// The reason a wire token names (a REJECT frame's field, a report's `reason`), if any: the
    /// same table as [`Reason::token`].
    pub fn from_token(token: &[u8]) -> Option<Reason> {
        Reason::ALL
            .iter()
            .copied()
            .find(|r| r.token().as_bytes() == token)
    }
}

macro_rules! code_enum {
    ($ty:ident { $($variant:ident),* $(,)? }) => {
        impl $ty {
            /// The numeric wire code.
            pub fn code(self) -> u8 {
                self as u8
            }
            /// The value with this wire code.
            pub fn from_code(code: i64) -> Option<Self> {
                $(if code == $ty::$variant as i64 { return Some($ty::$variant); })*
                None
            }
            /// Every value, in code order (the same list as [`Self::from_code`] reads).
            pub const ALL: &'static [Self] = &[$($ty::$variant),*];
        }
    };
}

code_enum!(DeviceState {
    Idle,
    Commissioning,
    ChangingSpeed,
    Running,
    Stopping,
    Faulted,
});
code_enum!(FaultCode {
    None,
    SensorLostOrStallPrecession,
    SensorLostOrStallSpin,
    OverspeedPrecession,
    OverspeedSpin,
    HostSilent,
    InvalidConfiguration,
    SensorLostPrecession,
    SensorLostSpin,
    StallPrecession,
    StallSpin,
    OverCurrentPrecession,
    OverCurrentSpin,
    CurrentAboveModelPrecession,
    CurrentAboveModelSpin,
    HardwareStop,
});
code_enum!(GateKind { Release, Exit });
code_enum!(ResetCause {
    PowerOn,
    Pin,
    Software,
    IndependentWatchdog,
    WindowWatchdog,
    LowPower,
    Unknown,
});

impl ResidenceModel {
    /// Every model, in the order of [`ResidenceModel::TOKENS`].
    pub const ALL: [ResidenceModel; 3] = [
        ResidenceModel::Flat,
        ResidenceModel::Coriolis,
        ResidenceModel::Table,
    ];

    /// The wire tokens, in the order of [`ResidenceModel::ALL`].
    pub const TOKENS: [&'static str; 3] = ["FLAT", "CORI", "TABLE"];

    /// The wire token.
    pub fn token(self) -> &'static str {
        Self::TOKENS[self as usize]
    }
}

impl Injection {
    /// Every injection.
    pub const ALL: [Injection; 5] = [
        Injection::None,
        Injection::SensorLostPrecession,
        Injection::SensorLostSpin,
        Injection::StallPrecession,
        Injection::StallSpin,
    ];

    /// The wire tokens, in the order of [`Injection::ALL`].
    pub const TOKENS: [&'static str; 5] = ["NONE", "SENSOR1", "SENSOR2", "STALL1", "STALL2"];

    /// The wire token.
    pub fn token(self) -> &'static str {
        Self::TOKENS[self as usize]
    }
}

impl Residence {
    /// The wire integer: ms, or -1 (never leaves), or -2 (unavailable).
    pub fn to_wire(self) -> i64 {
        match self {
            Residence::Ms(ms) => i64::from(ms),
            Residence::NeverLeaves => -1,
            Residence::Unavailable => -2,
        }
    }

    /// Parses the wire integer; `None` outside -2..=RESIDENCE_MAX_MS.
    pub fn from_wire(v: i64) -> Option<Self> {
        match v {
            -1 => Some(Residence::NeverLeaves),
            -2 => Some(Residence::Unavailable),
            0..=9_999_999 => u32::try_from(v).ok().map(Residence::Ms),
            _ => None,
        }
    }

    /// Converts a predicted time in seconds (`None` = never leaves). NaN, negative or longer
    /// than [`RESIDENCE_MAX_MS`] becomes [`Residence::Unavailable`], rounding to the nearest ms.
    pub fn from_seconds(time_s: Option<f32>) -> Self {
        match time_s {
            None => Residence::NeverLeaves,
            Some(t) if t >= 0.0 && t * 1000.0 <= RESIDENCE_MAX_MS as f32 => {
                // In range and not NaN: the cast cannot saturate.
                Residence::Ms(((t * 1000.0 + 0.5) as u32).min(RESIDENCE_MAX_MS))
            }
            Some(_) => Residence::Unavailable,
        }
    }
}
