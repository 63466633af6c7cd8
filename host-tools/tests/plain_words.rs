//! The words people read: the rig's states, faults and reset causes (`model_core::wire::words`)
//! and the controller's refusals (`virtual_rig::controller_words`) are plain words, never Rust names; the
//! `key=value` tokens are one lower-case word each, distinct within their kind.

use model_core::control::{ConfigError, Rejection, State as ControllerState};
use model_core::wire::{DeviceState, FaultCode, ResetCause};
use virtual_rig::controller_words::{config, rejection};

/// Every fault code the wire defines (read from the codes, so a new one is checked too).
fn faults() -> Vec<FaultCode> {
    (0..=255).filter_map(FaultCode::from_code).collect()
}

/// No word is a Rust name (no CamelCase run of two capitals).
#[test]
fn plain_words_only() {
    // A Rust name: a word that starts with a capital and has a lower-upper run inside
    // (`ChangingSpeed`); units such as `kHz` are not.
    let camel = |s: &str| {
        s.split(|c: char| !c.is_ascii_alphanumeric()).any(|w| {
            w.starts_with(|c: char| c.is_ascii_uppercase())
                && w.as_bytes()
                    .windows(2)
                    .any(|p| p[0].is_ascii_lowercase() && p[1].is_ascii_uppercase())
        })
    };
    assert!(camel("state ChangingSpeed") && !camel("10 kHz"));
    for f in faults() {
        assert!(!camel(f.words()), "{f:?}");
    }
    // Every state, as the controller has it and as the wire carries it: one table of words.
    for s in [
        ControllerState::Idle,
        ControllerState::Commissioning,
        ControllerState::ChangingSpeed,
        ControllerState::Running,
        ControllerState::Stopping,
        ControllerState::Fault,
    ] {
        let d = DeviceState::from(s);
        assert!(!camel(d.words()) && !camel(d.token()), "{s:?}");
    }
    // The key=value tokens: one lower-case word each, distinct within their kind.
    let token = |t: &str| !t.is_empty() && t.chars().all(|c| c.is_ascii_lowercase() || c == '-');
    let faults: Vec<&str> = faults().into_iter().map(FaultCode::token).collect();
    let states: Vec<&str> = [
        DeviceState::Idle,
        DeviceState::Commissioning,
        DeviceState::ChangingSpeed,
        DeviceState::Running,
        DeviceState::Stopping,
        DeviceState::Faulted,
    ]
    .into_iter()
    .map(DeviceState::token)
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
    .map(ResetCause::token)
    .collect();
    for kind in [faults, states, causes] {
        assert!(kind.iter().all(|t| token(t)), "{kind:?}");
        let mut unique = kind.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), kind.len(), "{kind:?}");
    }
    assert!(!camel(ResetCause::IndependentWatchdog.words()));
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
