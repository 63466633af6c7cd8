//! Restarting shafts that still coast, the way a lab engineer does all day: after a fault and its
//! CLEAR, after a STOP, or after one axis was set to zero and back. The loop then starts while
//! the speed estimator still holds edges from before (the shaft turns too slowly for a new edge
//! to come soon, but not so slowly that the estimator has called it stopped). Issue 27: on the
//! emulated Black Pill a restart 4.5 s after a dead-sensor fault ran the precession shaft 25 %
//! past 2 rad/s and faulted it as a runaway.

use super::harness::ClosedLoop;
use crate::control::{Fault, State};

/// How the shafts were let go before the restart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Halt {
    /// The spin sensor dies; the rig faults "sensor lost or stall, spin" (both motors off); the
    /// sensor is back 1.5 s after the fault and CLEAR comes 2.5 s after it (the scenario
    /// `tests/scenarios/fault-and-clear.toml`); the restart is SPEED + START.
    DeadSpinSensor,
    /// STOP: both axes ramp down, then Idle once both read zero; the restart is START.
    Stop,
    /// The precession's speed set to zero while the spin runs on; the restart is SPEED with the
    /// first speeds again.
    PrecessionToZero,
}

/// What the restart gave, measured on the rig's true speeds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestartOutcome {
    /// A fault latched after the restart (None on a healthy plant).
    pub fault: Option<Fault>,
    /// The true speeds `[precession, spin]` when the restart was commanded, rad/s.
    pub coast_rad_s: [f32; 2],
    /// The largest true speed past the target, % of the target (0 if never past it).
    pub overshoot_pct: [f32; 2],
}

/// Run before the halt, s: long enough to settle at the first speeds.
pub const RUN_BEFORE_HALT_S: f32 = 6.0;
/// Measured after the restart, s.
pub const RUN_AFTER_RESTART_S: f32 = 8.0;

/// Runs `cl` (a controller in Idle on its plant, commissioned or given a model) at `speeds`
/// (both positive) for [`RUN_BEFORE_HALT_S`], halts as `halt` says and, for each wait in
/// `waits_s` (from the fault, the Idle after STOP, or the zero command), restarts at `speeds`.
/// `Err` says in words when the run before the restart did not go as planned (a fault before
/// the halt, no fault from the dead sensor, STOP never reaching Idle).
pub fn restarts_after(
    mut cl: ClosedLoop,
    speeds: [f32; 2],
    halt: Halt,
    waits_s: &[f32],
    mut each: impl FnMut(f32, RestartOutcome),
) -> Result<(), &'static str> {
    cl.ctrl
        .set_motor_speeds(speeds[0], speeds[1])
        .map_err(|_| "the speeds were refused")?;
    cl.ctrl.start().map_err(|_| "START was refused")?;
    cl.run(RUN_BEFORE_HALT_S, |_| {});
    if cl.ctrl.fault().is_some() {
        return Err("faulted before the halt");
    }
    let dt = cl.dt_s();
    // Ticks from the halt's reference instant to the restart, and the restart itself.
    let mut halted = cl;
    let mut clear_at = None;
    match halt {
        Halt::DeadSpinSensor => {
            let now = halted.rig.time_s() as f32;
            halted.rig.params_mut().axes[1].faults.dead_sensor_from_s = now;
            let mut ticks = 0;
            while halted.ctrl.fault().is_none() && ticks < 2000 {
                halted.tick();
                ticks += 1;
            }
            if halted.ctrl.fault() != Some(Fault::SensorLostOrStall(1)) {
                return Err("the dead spin sensor did not fault as expected");
            }
            clear_at = Some(2.5);
        }
        Halt::Stop => {
            halted.ctrl.stop().map_err(|_| "STOP was refused")?;
            let mut ticks = 0;
            while halted.ctrl.state() != State::Idle && ticks < 60_000 {
                halted.tick();
                ticks += 1;
            }
            if halted.ctrl.state() != State::Idle {
                return Err("STOP did not reach Idle within 60 s");
            }
        }
        Halt::PrecessionToZero => {
            halted
                .ctrl
                .set_motor_speeds(0.0, speeds[1])
                .map_err(|_| "the zero speed was refused")?;
        }
    }
    let mut waits: [f32; 32] = [0.0; 32];
    let n = waits_s.len().min(waits.len());
    waits[..n].copy_from_slice(&waits_s[..n]);
    waits[..n].sort_unstable_by(f32::total_cmp);
    let mut t = 0.0f32;
    let mut sensor_back = false;
    let mut cleared = false;
    for &wait in &waits[..n] {
        while t + 0.5 * dt < wait {
            if halt == Halt::DeadSpinSensor && !sensor_back && t >= 1.5 {
                halted.rig.params_mut().axes[1].faults.dead_sensor_from_s = f32::INFINITY;
                sensor_back = true;
            }
            if let Some(c) = clear_at
                && !cleared
                && t >= c
            {
                halted.ctrl.clear_fault().map_err(|_| "CLEAR was refused")?;
                cleared = true;
            }
            halted.tick();
            t += dt;
        }
        let mut run = halted;
        if halt == Halt::DeadSpinSensor {
            run.rig.params_mut().axes[1].faults.dead_sensor_from_s = f32::INFINITY;
            if run.ctrl.fault().is_some() {
                run.ctrl.clear_fault().map_err(|_| "CLEAR was refused")?;
            }
        }
        let coast_rad_s = [run.rig.speed_rad_s(0), run.rig.speed_rad_s(1)];
        run.ctrl
            .set_motor_speeds(speeds[0], speeds[1])
            .map_err(|_| "the restart's speeds were refused")?;
        if halt != Halt::PrecessionToZero {
            run.ctrl
                .start()
                .map_err(|_| "the restart's START was refused")?;
        }
        let mut peak = [0.0f32; 2];
        let mut fault = None;
        run.run(RUN_AFTER_RESTART_S, |c| {
            for (i, p) in peak.iter_mut().enumerate() {
                *p = p.max(c.rig.speed_rad_s(i));
            }
            if fault.is_none() {
                fault = c.ctrl.fault();
            }
        });
        let over = |i: usize| (100.0 * (peak[i] - speeds[i]) / speeds[i]).max(0.0);
        each(
            wait,
            RestartOutcome {
                fault,
                coast_rad_s,
                overshoot_pct: [over(0), over(1)],
            },
        );
    }
    Ok(())
}
