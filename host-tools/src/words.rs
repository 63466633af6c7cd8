//! The rig's states, faults and reset causes in plain words, for everything a person reads
//! (monitor, send, commission, demo); the wire's tokens and codes stay in logs and JSON keys.

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

#[cfg(test)]
mod tests {
    use super::*;

    /// No word is a Rust name (no CamelCase run of two capitals).
    #[test]
    fn plain_words_only() {
        let camel = |s: &str| {
            s.as_bytes()
                .windows(2)
                .any(|w| w[0].is_ascii_lowercase() && w[1].is_ascii_uppercase())
        };
        for f in [
            FaultCode::None,
            FaultCode::SensorLostOrStallPrecession,
            FaultCode::SensorLostOrStallSpin,
            FaultCode::OverspeedPrecession,
            FaultCode::OverspeedSpin,
            FaultCode::HostSilent,
            FaultCode::InvalidConfiguration,
        ] {
            assert!(!camel(fault(f)), "{f:?}");
        }
        assert!(!camel(state(DeviceState::SpinningUp)));
        assert!(!camel(reset_cause(ResetCause::IndependentWatchdog)));
    }
}
