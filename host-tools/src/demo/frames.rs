//! Reading the telemetry frames the demo recorded: one motor's speeds and drive, device time.

use model_core::wire::Telemetry;

pub(super) const AXES: [&str; 2] = ["precession", "spin"];

pub(super) fn measured(t: &Telemetry, axis: usize) -> f64 {
    let m = if axis == 0 { t.precession } else { t.spin };
    f64::from(m.measured_mrad_s) / 1000.0
}

pub(super) fn set(t: &Telemetry, axis: usize) -> f64 {
    let m = if axis == 0 { t.precession } else { t.spin };
    f64::from(m.set_mrad_s) / 1000.0
}

pub(super) fn duty_bp(t: &Telemetry, axis: usize) -> i16 {
    if axis == 0 {
        t.precession.duty_bp
    } else {
        t.spin.duty_bp
    }
}

pub(super) fn seconds(ms: u32) -> f64 {
    f64::from(ms) / 1000.0
}

/// Frames with `from_ms <= time < to_ms`.
pub(super) fn window(tel: &[Telemetry], from_ms: u32, to_ms: u32) -> Vec<Telemetry> {
    tel.iter()
        .filter(|t| t.time_ms >= from_ms && t.time_ms < to_ms)
        .copied()
        .collect()
}

/// Synthetic telemetry for the analysis tests.
#[cfg(test)]
pub(super) mod fixtures {
    use model_core::wire::{DeviceState, FaultCode, MotorTelemetry, Residence, Telemetry};

    /// Telemetry period, ms.
    pub const FRAME_MS: u32 = 20;

    /// A telemetry frame with both motors at `w` rad/s measured, set to `set`, driven at `duty_bp`.
    pub fn frame(time_ms: u32, set_rad_s: f64, w: [f64; 2], duty_bp: [i16; 2]) -> Telemetry {
        let motor = |axis: usize| MotorTelemetry {
            set_mrad_s: (set_rad_s * 1000.0).round() as i16,
            measured_mrad_s: (w[axis] * 1000.0).round() as i16,
            duty_bp: duty_bp[axis],
            pulses: 0,
        };
        Telemetry {
            time_ms,
            seq: 0,
            state: DeviceState::Running,
            fault: FaultCode::None,
            precession: motor(0),
            spin: motor(1),
            bowl_mrad_s: 0,
            residence_flat: Residence::Unavailable,
            residence_coriolis: Residence::Unavailable,
        }
    }

    /// Frames every [`FRAME_MS`] for `seconds`, both motors measured at `y(t)`, set to `set`.
    pub fn sampled(y: impl Fn(f64) -> f64, set: f64, seconds: f64) -> Vec<Telemetry> {
        (0..=(seconds * 1000.0) as u32 / FRAME_MS)
            .map(|k| {
                let t_ms = k * FRAME_MS;
                let v = y(f64::from(t_ms) / 1000.0);
                frame(t_ms, set, [v, v], [5000, 5000])
            })
            .collect()
    }
}
