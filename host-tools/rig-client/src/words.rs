//! The rig's states, faults and reset causes in plain words, for everything a person reads
//! (monitor, send, commission, demo); the wire's tokens and codes stay in logs and JSON keys.
//! The controller's own refusals are the virtual rig's (`virtual_rig::controller_words`).

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
    }
}
