//! The rig's states, faults and reset causes in plain words, for everything a person reads
//! (monitor, send, commission, demo); the wire's tokens and codes stay in logs and JSON keys.

use model_core::control::{ConfigError, Rejection, State as ControllerState};
use model_core::wire::{DeviceState, FaultCode, ResetCause};

/// The device's state.
pub fn state(s: DeviceState) -> &'static str {
    match s {
        DeviceState::Idle => "idle",
        DeviceState::Commissioning => "commissioning",
        DeviceState::SpinningUp => "spinning up",
        DeviceState::Running => "running",
        DeviceState::Stopping => "stopping",
        DeviceState::Faulted => "faulted (motors off)",
    }
}

/// A fault, with what it means at the rig.
pub fn fault(f: FaultCode) -> &'static str {
    match f {
        FaultCode::None => "no fault",
        FaultCode::SensorLostOrStallPrecession => {
            "precession motor: no sensor pulses (sensor lost or motor stalled)"
        }
        FaultCode::SensorLostOrStallSpin => {
            "spin motor: no sensor pulses (sensor lost or motor stalled)"
        }
        FaultCode::OverspeedPrecession => "precession motor over its speed limit",
        FaultCode::OverspeedSpin => "spin motor over its speed limit",
        FaultCode::HostSilent => "the PC went silent (link loss)",
        FaultCode::InvalidConfiguration => "the stored configuration is invalid",
    }
}

/// Why the board last started.
pub fn reset_cause(r: ResetCause) -> &'static str {
    match r {
        ResetCause::PowerOn => "power-on",
        ResetCause::Pin => "reset pin",
        ResetCause::Software => "software reset",
        ResetCause::IndependentWatchdog => "watchdog (the control loop stalled)",
        ResetCause::WindowWatchdog => "window watchdog",
        ResetCause::LowPower => "low-power reset",
        ResetCause::Unknown => "unknown",
    }
}

/// The device's state as one lower-case word for `key=value` lines (`bowl send status`), which
/// scripts read: the same states as [`state`], without its explanations.
pub fn state_token(s: DeviceState) -> &'static str {
    match s {
        DeviceState::Idle => "idle",
        DeviceState::Commissioning => "commissioning",
        DeviceState::SpinningUp => "spinning-up",
        DeviceState::Running => "running",
        DeviceState::Stopping => "stopping",
        DeviceState::Faulted => "faulted",
    }
}

/// A fault as one lower-case word for `key=value` lines (see [`state_token`]).
pub fn fault_token(f: FaultCode) -> &'static str {
    match f {
        FaultCode::None => "none",
        FaultCode::SensorLostOrStallPrecession => "no-pulses-precession",
        FaultCode::SensorLostOrStallSpin => "no-pulses-spin",
        FaultCode::OverspeedPrecession => "overspeed-precession",
        FaultCode::OverspeedSpin => "overspeed-spin",
        FaultCode::HostSilent => "link-lost",
        FaultCode::InvalidConfiguration => "invalid-configuration",
    }
}

/// A reset cause as one lower-case word for `key=value` lines (see [`state_token`]).
pub fn reset_cause_token(r: ResetCause) -> &'static str {
    match r {
        ResetCause::PowerOn => "power-on",
        ResetCause::Pin => "pin",
        ResetCause::Software => "software",
        ResetCause::IndependentWatchdog => "watchdog",
        ResetCause::WindowWatchdog => "window-watchdog",
        ResetCause::LowPower => "low-power",
        ResetCause::Unknown => "unknown",
    }
}

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
        Rejection::WrongState(s) => format!("not allowed while {}", controller_state(s)),
        Rejection::Faulted(_) => "the rig is faulted: clear the fault first".into(),
        Rejection::NotFaulted => "there is no fault to clear".into(),
        Rejection::InvalidConfig(c) => config(c),
        Rejection::InvalidTuning => "the loop tuning is out of range".into(),
    }
}

/// The controller's state in plain words.
pub fn controller_state(s: ControllerState) -> &'static str {
    match s {
        ControllerState::Idle => "idle",
        ControllerState::Commissioning => "commissioning",
        ControllerState::SpinningUp => "spinning up",
        ControllerState::Running => "running",
        ControllerState::Stopping => "stopping",
        ControllerState::Fault => "faulted",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FAULTS: [FaultCode; 7] = [
        FaultCode::None,
        FaultCode::SensorLostOrStallPrecession,
        FaultCode::SensorLostOrStallSpin,
        FaultCode::OverspeedPrecession,
        FaultCode::OverspeedSpin,
        FaultCode::HostSilent,
        FaultCode::InvalidConfiguration,
    ];

    /// No word is a Rust name (no CamelCase run of two capitals).
    #[test]
    fn plain_words_only() {
        // A Rust name: a word that starts with a capital and has a lower-upper run inside
        // (`SpinningUp`); units such as `kHz` are not.
        let camel = |s: &str| {
            s.split(|c: char| !c.is_ascii_alphanumeric()).any(|w| {
                w.starts_with(|c: char| c.is_ascii_uppercase())
                    && w.as_bytes()
                        .windows(2)
                        .any(|p| p[0].is_ascii_lowercase() && p[1].is_ascii_uppercase())
            })
        };
        assert!(camel("state SpinningUp") && !camel("10 kHz"));
        for f in FAULTS {
            assert!(!camel(fault(f)), "{f:?}");
        }
        assert!(!camel(state(DeviceState::SpinningUp)));
        // The key=value tokens: one lower-case word each, distinct within their kind.
        let token =
            |t: &str| !t.is_empty() && t.chars().all(|c| c.is_ascii_lowercase() || c == '-');
        let faults: Vec<&str> = FAULTS.into_iter().map(fault_token).collect();
        let states: Vec<&str> = [
            DeviceState::Idle,
            DeviceState::Commissioning,
            DeviceState::SpinningUp,
            DeviceState::Running,
            DeviceState::Stopping,
            DeviceState::Faulted,
        ]
        .into_iter()
        .map(state_token)
        .collect();
        let causes: Vec<&str> = [
            ResetCause::PowerOn,
            ResetCause::Pin,
            ResetCause::Software,
            ResetCause::IndependentWatchdog,
            ResetCause::WindowWatchdog,
            ResetCause::LowPower,
            ResetCause::Unknown,
        ]
        .into_iter()
        .map(reset_cause_token)
        .collect();
        for kind in [faults, states, causes] {
            assert!(kind.iter().all(|t| token(t)), "{kind:?}");
            let mut unique = kind.clone();
            unique.sort_unstable();
            unique.dedup();
            assert_eq!(unique.len(), kind.len(), "{kind:?}");
        }
        assert!(!camel(reset_cause(ResetCause::IndependentWatchdog)));
        use model_core::control::InverseFailure;
        let configs = [
            ConfigError::TickRate,
            ConfigError::Timer,
            ConfigError::SupplyVoltage,
            ConfigError::PulsesPerRev(1),
            ConfigError::SpeedLimits(0),
            ConfigError::MotorModel(1),
            ConfigError::LoopParameter(0),
            ConfigError::Supervisor,
            ConfigError::Geometry,
            ConfigError::Commissioning,
        ];
        for c in configs {
            let text = config(c);
            assert!(!camel(&text) && !text.contains("Error"), "{c:?}: {text}");
        }
        for r in [
            Rejection::NotFinite,
            Rejection::AboveMaxSpeed(1),
            Rejection::BelowMinSpeed(0),
            Rejection::InvalidResidenceTime,
            Rejection::Inverse(InverseFailure::Unreachable),
            Rejection::SplitFailed,
            Rejection::WrongState(ControllerState::Commissioning),
            Rejection::Faulted(model_core::control::Fault::HostSilent),
            Rejection::NotFaulted,
            Rejection::InvalidConfig(ConfigError::Timer),
            Rejection::InvalidTuning,
        ] {
            assert!(!camel(&rejection(r)), "{r:?}");
        }
        assert!(rejection(Rejection::AboveMaxSpeed(1)).contains("spin"));
        assert!(config(ConfigError::PulsesPerRev(0)).contains("precession"));
    }
}
