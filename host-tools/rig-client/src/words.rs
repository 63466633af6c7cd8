//! The rig's faults and reset causes in plain words, for everything a person reads (monitor,
//! send, commission, demo), and as `key=value` tokens; the states' words are the state's own
//! (`DeviceState::words`, `DeviceState::token`, beside the state in `model_core::wire`).
//! The controller's own refusals are the virtual rig's (`virtual_rig::controller_words`).

use model_core::wire::{FaultCode, ResetCause};

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

/// A fault as one lower-case word for `key=value` lines (see `DeviceState::token`).
pub fn fault_token(f: FaultCode) -> &'static str {
    match f {
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

/// Every fault the wire knows, in code order.
pub fn all_faults() -> impl Iterator<Item = FaultCode> {
    (0..=i64::from(u8::MAX)).filter_map(FaultCode::from_code)
}

/// The fault a CSV's `fault` cell names ([`fault_token`]'s word), if any.
pub fn fault_from_token(word: &str) -> Option<FaultCode> {
    all_faults().find(|&f| fault_token(f) == word)
}

/// A reset cause as one lower-case word for `key=value` lines (see `DeviceState::token`).
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
