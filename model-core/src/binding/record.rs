//! The layout of the record persisted in flash: the wire parameters (wire order), then per axis
//! the motor model in force (identified by commissioning, or nominal): back-EMF constant,
//! friction duty, time constant, as f32 bit patterns. The flash format around it (slots,
//! version, CRC) is the firmware's parameter log.

use super::AXES;
use super::configure::default_params;
use crate::control::{ControllerConfig, MotorModel};
use crate::wire::{PARAM_COUNT, ParamValues};

/// Values in one persisted record.
pub const PERSISTED_COUNT: usize = PARAM_COUNT + 3 * AXES;
/// One persisted record's values.
pub type Persisted = [i32; PERSISTED_COUNT];

/// Joins parameters and motor models into a record.
pub fn persisted(params: &ParamValues, models: &[MotorModel; AXES]) -> Persisted {
    let mut v = [0i32; PERSISTED_COUNT];
    v[..PARAM_COUNT].copy_from_slice(params);
    for (i, m) in models.iter().enumerate() {
        let at = PARAM_COUNT + 3 * i;
        v[at] = m.volts_per_rad_s.to_bits() as i32;
        v[at + 1] = m.friction_duty.to_bits() as i32;
        v[at + 2] = m.time_constant_s.to_bits() as i32;
    }
    v
}

/// Splits a record into parameters and motor models.
pub fn split_persisted(v: &Persisted) -> (ParamValues, [MotorModel; AXES]) {
    let mut params = [0i32; PARAM_COUNT];
    params.copy_from_slice(&v[..PARAM_COUNT]);
    let f = |k: usize| f32::from_bits(v[k] as u32);
    let model = |i: usize| {
        let at = PARAM_COUNT + 3 * i;
        MotorModel {
            volts_per_rad_s: f(at),
            friction_duty: f(at + 1),
            time_constant_s: f(at + 2),
        }
    };
    (params, [model(0), model(1)])
}

/// The record a new board starts with: [`default_params`] and the nominal motor models.
pub fn default_persisted() -> Persisted {
    let cfg = ControllerConfig::nominal();
    persisted(&default_params(), &[cfg.axes[0].model, cfg.axes[1].model])
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
            },
            MotorModel {
                volts_per_rad_s: -0.0,
                friction_duty: f32::MIN_POSITIVE,
                time_constant_s: 7.5,
            },
        ];
        let (p, m) = split_persisted(&persisted(&params, &models));
        assert_eq!(p, params);
        for (a, b) in m.iter().zip(&models) {
            assert_eq!(a.volts_per_rad_s.to_bits(), b.volts_per_rad_s.to_bits());
            assert_eq!(a.friction_duty.to_bits(), b.friction_duty.to_bits());
            assert_eq!(a.time_constant_s.to_bits(), b.time_constant_s.to_bits());
        }
    }
}
