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
            "the capture timer must run at 10 kHz or more (10 counts per control tick at least) \
             and be 16 or 32 bits wide (timer_hz, timer_bits)"
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
            "the {} axis's motor model is implausible (volts per rad/s in (0, 100], friction \
             duty in [0, 0.9], time constant in (0, 10] s): commission it again",
            axis(a)
        ),
        ConfigError::LoopParameter(a) => format!(
            "a loop setting of the {} axis is out of range (bandwidth, per-pulse bandwidth, \
             acceleration limit, duty limit)",
            axis(a)
        ),
        ConfigError::Supervisor => {
            "a supervisor threshold is out of range (stall duty, sensor timeout, link timeout)"
                .into()
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

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::control::{Fault, InverseFailure, State};

    /// Every refused configuration, each axis's where it names one (a new kind fails to compile
    /// in the match until it is listed).
    fn every_config_error() -> Vec<ConfigError> {
        let all: Vec<ConfigError> = [0, 1]
            .into_iter()
            .flat_map(|a| {
                [
                    ConfigError::PulsesPerRev(a),
                    ConfigError::SpeedLimits(a),
                    ConfigError::MotorModel(a),
                    ConfigError::LoopParameter(a),
                ]
            })
            .chain([
                ConfigError::TickRate,
                ConfigError::Timer,
                ConfigError::SupplyVoltage,
                ConfigError::Supervisor,
                ConfigError::Geometry,
                ConfigError::Commissioning,
            ])
            .collect();
        for e in &all {
            match e {
                ConfigError::TickRate
                | ConfigError::Timer
                | ConfigError::SupplyVoltage
                | ConfigError::PulsesPerRev(_)
                | ConfigError::SpeedLimits(_)
                | ConfigError::MotorModel(_)
                | ConfigError::LoopParameter(_)
                | ConfigError::Supervisor
                | ConfigError::Geometry
                | ConfigError::Commissioning => {}
            }
        }
        all
    }

    /// Every refused command, with every state, a fault and every inverse failure it carries.
    fn every_rejection() -> Vec<Rejection> {
        let states = [
            State::Idle,
            State::Commissioning,
            State::ChangingSpeed,
            State::Running,
            State::Stopping,
            State::Fault,
        ];
        let mut all = vec![
            Rejection::NotFinite,
            Rejection::InvalidResidenceTime,
            Rejection::Inverse(InverseFailure::Unreachable),
            Rejection::Inverse(InverseFailure::ModelRejected),
            Rejection::SplitFailed,
            Rejection::Faulted(Fault::Stall(1)),
            Rejection::NotFaulted,
            Rejection::InvalidTuning,
        ];
        for a in [0, 1] {
            all.extend([Rejection::AboveMaxSpeed(a), Rejection::BelowMinSpeed(a)]);
        }
        all.extend(states.map(Rejection::WrongState));
        all.extend(
            every_config_error()
                .into_iter()
                .map(Rejection::InvalidConfig),
        );
        for r in &all {
            match r {
                Rejection::NotFinite
                | Rejection::AboveMaxSpeed(_)
                | Rejection::BelowMinSpeed(_)
                | Rejection::InvalidResidenceTime
                | Rejection::Inverse(InverseFailure::Unreachable | InverseFailure::ModelRejected)
                | Rejection::SplitFailed
                | Rejection::WrongState(_)
                | Rejection::Faulted(_)
                | Rejection::NotFaulted
                | Rejection::InvalidConfig(_)
                | Rejection::InvalidTuning => {}
            }
        }
        all
    }

    /// Every message reads as one line of plain words: no run of spaces (a string continued
    /// onto the next source line without its `\` keeps the indentation), no space at either
    /// end, and none of the Rust names its value prints with `{:?}`.
    #[test]
    fn every_message_is_plain_words() {
        let messages = every_config_error()
            .into_iter()
            .map(|e| (format!("{e:?}"), config(e)))
            .chain(
                every_rejection()
                    .into_iter()
                    .map(|r| (format!("{r:?}"), rejection(r))),
            );
        for (debug, text) in messages {
            assert!(!text.contains("  "), "{debug}: {text:?}");
            assert_eq!(text.trim(), text, "{debug}");
            assert!(!text.is_empty(), "{debug}");
            let words: Vec<&str> = text.split(|c: char| !c.is_alphanumeric()).collect();
            for name in debug
                .split(|c: char| !c.is_alphanumeric())
                .filter(|w| w.starts_with(char::is_uppercase))
            {
                assert!(!words.contains(&name), "{debug} named in {text:?}");
            }
        }
    }
}
