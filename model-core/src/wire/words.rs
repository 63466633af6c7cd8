//! The rig's states, faults and reset causes in words: one table per concept, beside the types
//! (a method of each), so the monitor, `bowl send`, the demo, the lab and the tests all say the
//! same thing. Two forms each: `token`, one lower-case word for `key=value` lines, CSV columns
//! and scenario files, which scripts read; `words`, plain words for a person.
//!
//! The firmware never calls these, so the linker leaves the strings out of its image (checked
//! with `tests/lib/elf-size.py`). The controller's own refusals are the virtual rig's
//! (`virtual_rig::controller_words`).

use super::types::{DeviceState, FaultCode, ResetCause};

impl DeviceState {
    /// The state as one lower-case word for `key=value` lines, CSV columns and scenario files
    /// (`bowl send status`, `bowl replay --csv`), which scripts read.
    pub const fn token(self) -> &'static str {
        match self {
            DeviceState::Idle => "idle",
            DeviceState::Commissioning => "commissioning",
            DeviceState::ChangingSpeed => "changing-speed",
            DeviceState::Running => "running",
            DeviceState::Stopping => "stopping",
            DeviceState::Faulted => "faulted",
        }
    }

    /// The state in plain words for a person (the monitor, the virtual rig's refusals): the
    /// same states as [`DeviceState::token`], the fault's consequence said.
    pub const fn words(self) -> &'static str {
        match self {
            DeviceState::Idle => "idle",
            DeviceState::Commissioning => "commissioning",
            DeviceState::ChangingSpeed => "changing speed",
            DeviceState::Running => "running",
            DeviceState::Stopping => "stopping",
            DeviceState::Faulted => "faulted (motors off)",
        }
    }
}

impl FaultCode {
    /// The fault as one lower-case word for `key=value` lines and the telemetry CSV's `fault`
    /// column (see [`DeviceState::token`]).
    pub const fn token(self) -> &'static str {
        match self {
            FaultCode::None => "none",
            FaultCode::SensorLostOrStallPrecession => "no-pulses-precession",
            FaultCode::SensorLostOrStallSpin => "no-pulses-spin",
            FaultCode::OverspeedPrecession => "overspeed-precession",
            FaultCode::OverspeedSpin => "overspeed-spin",
            FaultCode::HostSilent => "link-lost",
            FaultCode::InvalidConfiguration => "invalid-configuration",
            FaultCode::SensorLostPrecession => "sensor-lost-precession",
            FaultCode::SensorLostSpin => "sensor-lost-spin",
            FaultCode::StallPrecession => "stall-precession",
            FaultCode::StallSpin => "stall-spin",
            FaultCode::OverCurrentPrecession => "over-current-precession",
            FaultCode::OverCurrentSpin => "over-current-spin",
            FaultCode::CurrentAboveModelPrecession => "current-above-model-precession",
            FaultCode::CurrentAboveModelSpin => "current-above-model-spin",
            FaultCode::HardwareStop => "hardware-stop",
        }
    }

    /// The fault a CSV's `fault` cell names ([`FaultCode::token`]'s word), if any.
    pub fn from_token(word: &str) -> Option<FaultCode> {
        FaultCode::ALL.iter().copied().find(|f| f.token() == word)
    }

    /// The fault in plain words for a person, with what it means at the rig.
    pub const fn words(self) -> &'static str {
        match self {
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
            FaultCode::SensorLostPrecession => {
                "precession motor: no sensor pulses while the current shows it turning (sensor lost)"
            }
            FaultCode::SensorLostSpin => {
                "spin motor: no sensor pulses while the current shows it turning (sensor lost)"
            }
            FaultCode::StallPrecession => {
                "precession motor: no sensor pulses and no back-EMF in the current (shaft stalled)"
            }
            FaultCode::StallSpin => {
                "spin motor: no sensor pulses and no back-EMF in the current (shaft stalled)"
            }
            FaultCode::OverCurrentPrecession => "precession motor: current over its limit",
            FaultCode::OverCurrentSpin => "spin motor: current over its limit",
            FaultCode::CurrentAboveModelPrecession => {
                "precession motor: more current than the duty drives at its speed (bridge stuck on or shorted, or shaft stopped dead)"
            }
            FaultCode::CurrentAboveModelSpin => {
                "spin motor: more current than the duty drives at its speed (bridge stuck on or shorted, or shaft stopped dead)"
            }
            FaultCode::HardwareStop => {
                "hardware stop: over-current or a bridge driver fault switched the motors off (motor supply cut)"
            }
        }
    }
}

impl ResetCause {
    /// Why the board last started, as one lower-case word for `key=value` lines (see
    /// [`DeviceState::token`]).
    pub const fn token(self) -> &'static str {
        match self {
            ResetCause::PowerOn => "power-on",
            ResetCause::Pin => "pin",
            ResetCause::Software => "software",
            ResetCause::IndependentWatchdog => "watchdog",
            ResetCause::WindowWatchdog => "window-watchdog",
            ResetCause::LowPower => "low-power",
            ResetCause::Unknown => "unknown",
        }
    }

    /// Why the board last started, in plain words for a person.
    pub const fn words(self) -> &'static str {
        match self {
            ResetCause::PowerOn => "power-on",
            ResetCause::Pin => "reset pin",
            ResetCause::Software => "software reset",
            ResetCause::IndependentWatchdog => "watchdog (the control loop stalled)",
            ResetCause::WindowWatchdog => "window watchdog",
            ResetCause::LowPower => "low-power reset",
            ResetCause::Unknown => "unknown",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ALL` is every fault the wire codes name, and each token reads back as its own fault.
    #[test]
    fn fault_tokens_read_back() {
        let by_code = (0..=255).filter_map(FaultCode::from_code);
        assert!(FaultCode::ALL.iter().copied().eq(by_code));
        for &f in FaultCode::ALL {
            assert_eq!(FaultCode::from_token(f.token()), Some(f), "{f:?}");
        }
        for word in ["", "None", "no fault", "link lost", "stall-spin "] {
            assert_eq!(FaultCode::from_token(word), None, "{word:?}");
        }
    }
}
