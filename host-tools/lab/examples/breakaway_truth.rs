//! The commissioned motor model against the plant's truth, per axis of every plant of a rig
//! file (issue 27, docs/control.md "The breakaway duty from the first edge" and "The spin
//! released at the precession's first edge"): the breakaway duty against static friction in duty
//! (`Ts R / (k V)`), and the slope, friction duty and time constant against
//! `MotorParams::ideal_model`. The controller's volts are duty times its configured supply; the
//! slope's ratio is also given times `supply_v / configured`, in duty, the unit the loop uses.
//!
//! `cargo run -p lab --release --example breakaway_truth -- FILE` prints one CSV row per axis
//! and, on stderr, each ratio's spread per axis.

use lab::sim_reports::{commissioned, config_for};

const RATIOS: [&str; 5] = [
    "breakaway duty",
    "slope",
    "slope in duty",
    "friction duty",
    "time constant",
];

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: breakaway_truth FILE");
        std::process::exit(2);
    };
    let rigs = match rig_file::load(std::path::Path::new(&path)) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    };
    println!(
        "plant,axis,breakaway_duty,true_breakaway_duty,volts_per_rad_s,true_volts_per_rad_s,\
         friction_duty,true_friction_duty,time_constant_s,true_time_constant_s"
    );
    let mut ratios: [[Vec<f32>; RATIOS.len()]; 2] = Default::default();
    let mut took_s = Vec::new();
    for rig in &rigs {
        let cfg = config_for(rig);
        let configured_v = cfg.supply_v;
        let Ok(cl) = commissioned(rig, cfg) else {
            println!("{},refused", rig.name);
            continue;
        };
        took_s.push(cl.rig.time_s());
        let supply_v = rig.params.supply_v;
        for (i, id) in cl.ctrl.identified().iter().enumerate() {
            let Some(id) = id else { continue };
            let motor = rig.params.axes[i].motor;
            let breakaway = motor.ideal_breakaway_duty(supply_v);
            let (a, c, tau) = motor.ideal_model(supply_v);
            let m = id.model;
            let r = [
                m.breakaway_duty / breakaway,
                m.volts_per_rad_s / a,
                m.volts_per_rad_s / a * supply_v / configured_v,
                m.friction_duty / c,
                m.time_constant_s / tau,
            ];
            for (all, x) in ratios[i].iter_mut().zip(r) {
                all.push(x);
            }
            println!(
                "{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
                rig.name,
                i,
                m.breakaway_duty,
                breakaway,
                m.volts_per_rad_s,
                a,
                m.friction_duty,
                c,
                m.time_constant_s,
                tau
            );
        }
    }
    for (i, axis) in ratios.iter_mut().enumerate() {
        for (name, r) in RATIOS.iter().zip(axis) {
            r.sort_by(f32::total_cmp);
            if r.is_empty() {
                continue;
            }
            let q = |f: f32| r[((r.len() - 1) as f32 * f).round() as usize];
            eprintln!(
                "axis {i} {name}: identified/true min {:.3} median {:.3} max {:.3}; below truth {} of {}",
                q(0.0),
                q(0.5),
                q(1.0),
                r.iter().filter(|&&x| x < 1.0).count(),
                r.len()
            );
        }
    }
    took_s.sort_by(f64::total_cmp);
    if let (Some(lo), Some(hi)) = (took_s.first(), took_s.last()) {
        eprintln!(
            "commissioning took {lo:.1}-{hi:.1} s (median {:.1} s) over {} plants",
            took_s[took_s.len() / 2],
            took_s.len()
        );
    }
}
