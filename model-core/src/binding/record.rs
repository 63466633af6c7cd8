//! The layout of the record persisted in flash: the wire parameters (wire order), then per axis
//! the motor model in force (identified by commissioning, or nominal): back-EMF constant,
//! friction duty, time constant, breakaway duty, reaction duty, as f32 bit patterns; then one
//! word whose bit `i` says that axis `i`'s model was identified by commissioning (so the flag
//! survives a reset with the model it describes). The flash format around it (slots, version, CRC) is the firmware's
//! parameter log.

use super::AXES;
use super::configure::default_params;
use crate::control::{ControllerConfig, MotorModel};
use crate::wire::{PARAM_COUNT, ParamValues};

/// Values in one persisted record.
pub const PERSISTED_COUNT: usize = PARAM_COUNT + MODEL_VALUES * AXES + 1;
/// Values of one motor model in the record.
const MODEL_VALUES: usize = 5;
/// One persisted record's values.
pub type Persisted = [i32; PERSISTED_COUNT];

/// What a persisted record holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Record {
    /// The wire parameters.
    pub params: ParamValues,
    /// The motor models in force, precession then spin.
    pub models: [MotorModel; AXES],
    /// Whether each model was identified by commissioning (on this board, at some boot).
    pub identified: [bool; AXES],
}

const FLAGS_AT: usize = PARAM_COUNT + MODEL_VALUES * AXES;

/// Joins parameters, motor models and their identified flags into a record.
pub fn persisted(r: &Record) -> Persisted {
    let mut v = [0i32; PERSISTED_COUNT];
    v[..PARAM_COUNT].copy_from_slice(&r.params);
    for (i, m) in r.models.iter().enumerate() {
        let at = PARAM_COUNT + MODEL_VALUES * i;
        v[at] = m.volts_per_rad_s.to_bits() as i32;
        v[at + 1] = m.friction_duty.to_bits() as i32;
        v[at + 2] = m.time_constant_s.to_bits() as i32;
        v[at + 3] = m.breakaway_duty.to_bits() as i32;
        v[at + 4] = m.reaction_duty_s2_per_rad.to_bits() as i32;
    }
    v[FLAGS_AT] = r
        .identified
        .iter()
        .enumerate()
        .fold(0, |acc, (i, &on)| acc | (i32::from(on) << i));
    v
}

/// Splits a record into parameters, motor models and their identified flags.
pub fn split_persisted(v: &Persisted) -> Record {
    let mut params = [0i32; PARAM_COUNT];
    params.copy_from_slice(&v[..PARAM_COUNT]);
    let f = |k: usize| f32::from_bits(v[k] as u32);
    let model = |i: usize| {
        let at = PARAM_COUNT + MODEL_VALUES * i;
        MotorModel {
            volts_per_rad_s: f(at),
            friction_duty: f(at + 1),
            time_constant_s: f(at + 2),
            breakaway_duty: f(at + 3),
            reaction_duty_s2_per_rad: f(at + 4),
        }
    };
    let flag = |i: usize| v[FLAGS_AT] & (1 << i) != 0;
    Record {
        params,
        models: [model(0), model(1)],
        identified: [flag(0), flag(1)],
    }
}

/// The record a new board starts with: [`default_params`], the nominal motor models, nothing
/// identified.
pub fn default_persisted() -> Persisted {
    let cfg = ControllerConfig::nominal();
    persisted(&Record {
        params: default_params(),
        models: [cfg.axes[0].model, cfg.axes[1].model],
        identified: [false; AXES],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_splits_back_into_its_parameters_and_models() {
        let mut params = default_params();
        params[3] = -123_456;
        let models = [
            MotorModel {
                volts_per_rad_s: 0.25,
                friction_duty: 0.031,
                time_constant_s: 0.11,
                breakaway_duty: 0.2,
                reaction_duty_s2_per_rad: 0.0043,
            },
            MotorModel {
                volts_per_rad_s: -0.0,
                friction_duty: f32::MIN_POSITIVE,
                time_constant_s: 7.5,
                breakaway_duty: 1.0,
                reaction_duty_s2_per_rad: -1e-30,
            },
        ];
        for identified in [[false, false], [true, false], [false, true], [true, true]] {
            let r = split_persisted(&persisted(&Record {
                params,
                models,
                identified,
            }));
            assert_eq!(r.identified, identified);
        }
        let r = split_persisted(&persisted(&Record {
            params,
            models,
            identified: [true, false],
        }));
        assert_eq!(r.params, params);
        for (a, b) in r.models.iter().zip(&models) {
            assert_eq!(a.volts_per_rad_s.to_bits(), b.volts_per_rad_s.to_bits());
            assert_eq!(a.friction_duty.to_bits(), b.friction_duty.to_bits());
            assert_eq!(a.time_constant_s.to_bits(), b.time_constant_s.to_bits());
            assert_eq!(a.breakaway_duty.to_bits(), b.breakaway_duty.to_bits());
            assert_eq!(
                a.reaction_duty_s2_per_rad.to_bits(),
                b.reaction_duty_s2_per_rad.to_bits()
            );
        }
    }
}
