//! The commissioned motor model against the plant's truth (`MotorParams::ideal_model`: slope
//! `k + R b / k`, friction duty `R Tc / (k V)`, time constant), per axis of every plant of a rig
//! file (issue 27, docs/control.md "The identified slope").
//!
//! `cargo run -p lab --release --example model_truth -- FILE` prints one CSV row per axis and, on
//! stderr, each ratio's spread per axis.

use lab::sim_reports::{commissioned, config_for};

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: model_truth FILE");
        std::process::exit(2);
    };
    let rigs = match rig_file::load(std::path::Path::new(&path)) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    };
    println!("plant,axis,slope,true_slope,friction_duty,true_friction_duty,tau_s,true_tau_s");
    let mut ratios: [[Vec<f32>; 3]; 2] = Default::default();
    for rig in &rigs {
        let Ok(cl) = commissioned(rig, config_for(rig)) else {
            println!("{},refused", rig.name);
            continue;
        };
        for (i, id) in cl.ctrl.identified().iter().enumerate() {
            let Some(id) = id else { continue };
            let (a, c, tau) = rig.params.axes[i].motor.ideal_model(rig.params.supply_v);
            let m = id.model;
            ratios[i][0].push(m.volts_per_rad_s / a);
            ratios[i][1].push(m.friction_duty / c);
            ratios[i][2].push(m.time_constant_s / tau);
            println!(
                "{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
                rig.name, i, m.volts_per_rad_s, a, m.friction_duty, c, m.time_constant_s, tau
            );
        }
    }
    for (i, axis) in ratios.iter_mut().enumerate() {
        for (name, r) in ["slope", "friction duty", "time constant"].iter().zip(axis) {
            r.sort_by(f32::total_cmp);
            if r.is_empty() {
                continue;
            }
            let q = |f: f32| r[((r.len() - 1) as f32 * f).round() as usize];
            eprintln!(
                "axis {i} {name}: identified/true min {:.3} p10 {:.3} median {:.3} p90 {:.3} max {:.3}",
                q(0.0),
                q(0.1),
                q(0.5),
                q(0.9),
                q(1.0)
            );
        }
    }
}
