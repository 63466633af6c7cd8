//! The closed-loop reports on rig files: `bowl sim family --rig-file` (commissioning, then the
//! step from rest on both axes) and `bowl sim faults --rig-file` (the fault matrix), with the
//! fixed JSON shapes docs/control.md describes. Every figure is taken on the plant's *true*
//! speed, never on the controller's estimate.

use model_core::control::{Controller, ControllerConfig, State};
use model_core::sim::{ClosedLoop, Plant};
use model_core::wire::FaultCode;
use rig_file::Rig;

mod faults;
pub mod nominal;
mod step;

pub use faults::*;
pub use step::*;

/// Host-silence timeout the fault matrix configures, s (the link-loss row).
pub const LINK_TIMEOUT_S: f32 = 1.0;
/// Longest commissioning run allowed in a report, s.
const COMMISSION_MAX_S: f32 = 300.0;

/// The controller configuration a lab engineer gives for `rig`: the nominal one with the rig's
/// pulses per revolution and capture timer (everything else is identified).
pub fn config_for(rig: &Rig) -> ControllerConfig {
    let mut cfg = ControllerConfig::nominal();
    cfg.timer_hz = rig.params.timer_hz;
    cfg.timer_bits = rig.params.timer_bits;
    for (a, p) in cfg.axes.iter_mut().zip(&rig.params.axes) {
        a.pulses_per_rev = p.sensor.pulses_per_rev;
    }
    cfg
}

/// Commissions `rig`; returns the closed loop (Idle, identified) or the plain reason.
pub fn commissioned(rig: &Rig, cfg: ControllerConfig) -> Result<ClosedLoop, String> {
    let ctrl = Controller::new(cfg).map_err(|e| {
        format!(
            "configuration rejected: {}",
            virtual_rig::controller_words::config(e)
        )
    })?;
    let mut cl = ClosedLoop::new(Plant::new(rig.params, rig.seed), ctrl);
    match cl.commission(COMMISSION_MAX_S) {
        State::Idle => Ok(cl),
        _ => Err(match cl.ctrl.identify_error() {
            Some(e) => e.reason().to_string(),
            None => match cl.ctrl.fault() {
                Some(f) => format!(
                    "{} during identification",
                    FaultCode::from_code(i64::from(f.code()))
                        .map_or("an unknown fault", FaultCode::words)
                ),
                None => "did not finish".to_string(),
            },
        }),
    }
}

/// The steady speed full duty (`duty_limit`) gives axis `axis` of `rig` against its friction and
/// `load_nm` of material, rad/s (0 when it cannot turn): the most any loop can ask of it.
pub fn full_duty_speed_rad_s(
    rig: &model_core::sim::PlantParams,
    axis: usize,
    duty_limit: f32,
    load_nm: f32,
) -> f32 {
    let m = &rig.axes[axis].motor;
    let (volts_per_rad_s, friction_duty) = {
        let (a, fd, _) = m.ideal_model(rig.supply_v);
        (a, fd)
    };
    let load_duty = m.resistance_ohm * load_nm / (m.torque_constant * rig.supply_v);
    ((duty_limit - friction_duty - load_duty) * rig.supply_v / volts_per_rad_s).max(0.0)
}

/// A line for each axis of `rigs` that full duty, against its friction and material, cannot
/// take to `speed` (named by `flag`): the speed it reaches instead. Its figures at `speed` are
/// taken below it, against bounds reckoned for `speed`.
pub fn unreachable_words(rigs: &[Rig], speed: f32, flag: &str) -> Vec<String> {
    let mut words = Vec::new();
    for rig in rigs {
        let cfg = config_for(rig);
        for (i, name) in ["precession", "spin"].into_iter().enumerate() {
            let load = rig.params.axes[i].load_step_nm;
            let reach = full_duty_speed_rad_s(&rig.params, i, cfg.axes[i].duty_limit, load);
            // Within the 2 % band of the speed is reaching it (the estimate leaves out the
            // load's ripple and the coupling).
            if reach < 0.98 * speed {
                words.push(format!(
                    "plant {}'s {name} axis reaches about {reach:.2} rad/s at full duty against \
                     its friction and material, below {flag} {speed}: it ran at that speed, \
                     judged against the bounds of {speed} rad/s; ask for at most {reach:.2}",
                    rig.name
                ));
            }
        }
    }
    words
}

/// Adds each axis's `load_step_nm` (material poured in after commissioning) from now on.
pub fn pour_material(cl: &mut ClosedLoop) {
    let now = cl.rig.time_s() as f32;
    for a in &mut cl.rig.params_mut().axes {
        a.faults.load_step_from_s = now;
        a.faults.load_step_nm = a.load_step_nm;
    }
}
