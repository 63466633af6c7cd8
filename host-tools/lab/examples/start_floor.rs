//! The physical floor of the overshoot from rest with pulses only (issue 27, docs/control.md
//! "From rest to 1 rad/s: the floor of a start from pulses"). For every plant of a rig file:
//! commissioned, material poured in, commanded from rest to the target; per axis:
//! - the controller's run on the plant's true speed (breakaway, first edge, first measurement,
//!   peak, the duty at the breakaway);
//! - oracle "break": the same plant driven with the controller's duties until the shaft breaks
//!   away, then at once the duty that holds the target on the true plant (material included);
//!   what no loop can beat, with or without the current;
//! - oracle "edge": the controller's duties until the breakaway, then the duty it broke away at
//!   held until the first edge (the loop cannot know of the motion before it), then the duty
//!   that holds the target, or none while the shaft is above it: the floor of a start that
//!   learns of the breakaway only from the first edge;
//! - the leap: `(Ts - Tc) / (k^2 / R + b)`, the speed the breakaway duty holds a shaft at.
//!
//! `cargo run -p lab --release --example start_floor -- FILE [TARGET]` prints one CSV row per axis.

use lab::sim_reports::{commissioned, config_for, pour_material};
use model_core::sim::{ClosedLoop, Plant};

const RUN_S: f32 = 6.0;

/// Duty that holds `w` on axis `i` of the true plant (material included, ripple left out).
fn hold_duty(p: &Plant, i: usize, w: f32) -> f32 {
    let a = p.params().axes[i];
    let m = a.motor;
    let load = a.faults.load_step_nm;
    (m.resistance_ohm * (m.viscous_nm_s * w + m.coulomb_nm + load) / m.torque_constant
        + m.torque_constant * w)
        / p.params().supply_v
}

/// Peak true speed of axis `i` within `RUN_S` of an oracle run from `start`: `duties` replayed
/// until the shaft moves; then `after(plant, moved_duty, edge_seen)` gives the duty.
fn oracle(start: &ClosedLoop, duties: &[[f32; 2]], i: usize, w: f32, wait_for_edge: bool) -> f32 {
    let mut p = start.rig;
    let dt = start.dt_s();
    let n = (RUN_S / dt) as usize;
    let mut moved_at: Option<f32> = None;
    let mut edge = false;
    let mut peak = 0.0f32;
    for k in 0..n {
        let replay = duties.get(k).copied().unwrap_or([0.0; 2]);
        let mut d = replay;
        if let Some(dm) = moved_at {
            if wait_for_edge && !edge {
                d[i] = dm;
            } else {
                d[i] = if p.speed_rad_s(i) > w {
                    0.0
                } else {
                    hold_duty(&p, i, w)
                };
            }
        }
        // The other axis: the controller's duties throughout.
        p.advance(d, dt);
        if !p.edges(i).is_empty() && moved_at.is_some() {
            edge = true;
        }
        if moved_at.is_none() && p.speed_rad_s(i) != 0.0 {
            moved_at = Some(replay[i]);
        }
        peak = peak.max(p.speed_rad_s(i));
    }
    peak
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        eprintln!("usage: start_floor FILE [TARGET_RAD_S]");
        std::process::exit(2);
    };
    let target: f32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1.0);
    let rigs = match rig_file::load(std::path::Path::new(path)) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    };
    println!(
        "plant,axis,overshoot_pct,t_break_s,t_first_edge_s,t_first_meas_s,t_peak_s,w_first_edge,duty_break,duty_hold,duty_true_break,id_kick_level,leap_rad_s,oracle_break_pct,oracle_edge_pct"
    );
    for rig in &rigs {
        let Ok(mut cl) = commissioned(rig, config_for(rig)) else {
            println!("{},refused", rig.name);
            continue;
        };
        pour_material(&mut cl);
        let _ = cl.ctrl.set_motor_speeds(target, target);
        let _ = cl.ctrl.start();
        let start = cl;
        let ids = cl.ctrl.identified();
        let dt = cl.dt_s();
        let mut duties = Vec::new();
        let mut t_break = [None; 2];
        let mut t_edge = [None; 2];
        let mut t_meas = [None; 2];
        let mut w_edge = [0.0f32; 2];
        let mut d_break = [0.0f32; 2];
        let mut peak = [(0.0f32, 0.0f32); 2];
        let n = (RUN_S / dt) as usize;
        for k in 0..n {
            let d = cl.tick();
            duties.push(d);
            let t = (k + 1) as f32 * dt;
            let s = cl.ctrl.status();
            for i in 0..2 {
                let w = cl.rig.speed_rad_s(i);
                if t_break[i].is_none() && w != 0.0 {
                    t_break[i] = Some(t);
                    d_break[i] = d[i];
                }
                if t_edge[i].is_none() && t_break[i].is_some() && !cl.rig.edges(i).is_empty() {
                    t_edge[i] = Some(t);
                    w_edge[i] = w;
                }
                if t_meas[i].is_none() && s.axes[i].measured_rad_s != 0.0 && t_break[i].is_some() {
                    t_meas[i] = Some(t);
                }
                if w > peak[i].0 {
                    peak[i] = (w, t);
                }
            }
        }
        for i in 0..2 {
            let a = start.rig.params().axes[i];
            let m = a.motor;
            let v = start.rig.params().supply_v;
            let load = a.faults.load_step_nm;
            let leap = (m.stiction_nm - m.coulomb_nm)
                / (m.torque_constant * m.torque_constant / m.resistance_ohm + m.viscous_nm_s);
            let true_break = m.resistance_ohm * (m.stiction_nm + load) / (m.torque_constant * v);
            let kick = ids[i].map_or(f32::NAN, |id| {
                let md = id.model;
                (md.breakaway_duty - md.friction_duty - target * md.volts_per_rad_s / v).max(0.0)
            });
            let ob = oracle(&start, &duties, i, target, false);
            let oe = oracle(&start, &duties, i, target, true);
            let pct = |w: f32| (100.0 * (w - target) / target).max(0.0);
            let f = |t: Option<f32>| t.map_or("-".to_string(), |t| format!("{t:.3}"));
            println!(
                "{},{},{:.1},{},{},{},{:.3},{:.3},{:.4},{:.4},{:.4},{:.4},{:.3},{:.1},{:.1}",
                rig.name,
                ["precession", "spin"][i],
                pct(peak[i].0),
                f(t_break[i]),
                f(t_edge[i]),
                f(t_meas[i]),
                peak[i].1,
                w_edge[i],
                d_break[i],
                hold_duty(&start.rig, i, target),
                true_break,
                kick,
                leap,
                pct(ob),
                pct(oe)
            );
        }
    }
}
