//! The controller's refusals and states in plain words: a configuration it refused (from a rig
//! file or the rig's parameters), a command it refused, its state. Used where the controller runs
//! on the PC (the virtual rig, the lab's reports and experiments).

use model_core::control::{ConfigError, Rejection};
use model_core::wire::DeviceState;

const AXES: [&str; 2] = ["precession", "spin"];

fn axis(i: u8) -> &'static str {
    AXES[usize::from(i.min(1))]
}

/// Why the controller's configuration (from a rig file or the rig's parameters) was refused.
pub fn config(e: ConfigError) -> String {
    match e {
        ConfigError::TickRate => "the control tick rate must lie in 100 Hz ..= 10 kHz".into(),
        ConfigError::Timer => {
            "the capture timer must run at 10 kHz or more (10 counts per control tick at least)              and be 16 or 32 bits wide (timer_hz, timer_bits)"
                .into()
        }
        ConfigError::SupplyVoltage => "the supply voltage must lie in 1 ..= 60 V (supply_v)".into(),
        ConfigError::PulsesPerRev(a) => format!(
            "the {} axis's pulses per revolution must lie in 1 ..= 1000 (pulses_per_rev)",
            axis(a)
        ),
        ConfigError::SpeedLimits(a) => format!(
            "the {} axis's speed limits must satisfy 0 < minimum < maximum < overspeed",
            axis(a)
        ),
        ConfigError::MotorModel(a) => format!(
            "the {} axis's motor model is implausible (volts per rad/s in (0, 100], friction              duty in [0, 0.9], time constant in (0, 10] s): commission it again",
            axis(a)
        ),
        ConfigError::LoopParameter(a) => format!(
            "a loop setting of the {} axis is out of range (bandwidth, per-pulse bandwidth,              acceleration limit, duty limit)",
            axis(a)
        ),
        ConfigError::Supervisor => {
            "a supervisor threshold is out of range (stall duty, sensor timeout, link timeout)".into()
        }
        ConfigError::Geometry => {
            "the spin/precession ratio or the angle between the axes is invalid".into()
        }
        ConfigError::Commissioning => {
            "a commissioning setting is out of range (duties, step time, timeout)".into()
        }
    }
}

/// Why the controller refused a command.
pub fn rejection(e: Rejection) -> String {
    match e {
        Rejection::NotFinite => "a value was not a finite number".into(),
        Rejection::AboveMaxSpeed(a) => format!("the {} speed is above its limit", axis(a)),
        Rejection::BelowMinSpeed(a) => format!(
            "the {} speed is below the lowest its sensor can measure (use 0 or more)",
            axis(a)
        ),
        Rejection::InvalidResidenceTime => "the residence time must lie in 1 us ..= 1e6 s".into(),
        Rejection::Inverse(_) => "no bowl speed gives that residence time".into(),
        Rejection::SplitFailed => "the bowl speed cannot be split into motor speeds".into(),
        Rejection::WrongState(s) => format!("not allowed while {}", DeviceState::from(s).words()),
        Rejection::Faulted(_) => "the rig is faulted: clear the fault first".into(),
        Rejection::NotFaulted => "there is no fault to clear".into(),
        Rejection::InvalidConfig(c) => config(c),
        Rejection::InvalidTuning => "the loop tuning is out of range".into(),
    }
}
