//! The commissioned breakaway duty against the plant's truth (static friction in duty,
//! `Ts R / (k V)`), per axis of every plant of a rig file (issue 27, docs/control.md
//! "The breakaway duty from the first edge").
//!
//! `cargo run -p lab --release --example breakaway_truth -- FILE` prints one CSV row per axis
//! and, on stderr, the ratio's spread per axis.

use lab::sim_reports::{commissioned, config_for};

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
        "plant,axis,breakaway_duty,true_breakaway_duty,friction_duty,ratio,volts_per_rad_s,time_constant_s"
    );
    let mut ratios: [Vec<f32>; 2] = [Vec::new(), Vec::new()];
    for rig in &rigs {
        let Ok(cl) = commissioned(rig, config_for(rig)) else {
            println!("{},refused", rig.name);
            continue;
        };
        for (i, id) in cl.ctrl.identified().iter().enumerate() {
            let Some(id) = id else { continue };
            let truth = rig.params.axes[i]
                .motor
                .ideal_breakaway_duty(rig.params.supply_v);
            let m = id.model;
            let ratio = m.breakaway_duty / truth;
            ratios[i].push(ratio);
            println!(
                "{},{},{:.4},{:.4},{:.4},{:.3},{:.4},{:.4}",
                rig.name,
                i,
                m.breakaway_duty,
                truth,
                m.friction_duty,
                ratio,
                m.volts_per_rad_s,
                m.time_constant_s
            );
        }
    }
    for (i, r) in ratios.iter_mut().enumerate() {
        r.sort_by(f32::total_cmp);
        if r.is_empty() {
            continue;
        }
        let q = |f: f32| r[((r.len() - 1) as f32 * f).round() as usize];
        eprintln!(
            "axis {i}: identified/true min {:.3} median {:.3} max {:.3}; below truth {} of {}",
            q(0.0),
            q(0.5),
            q(1.0),
            r.iter().filter(|&&x| x < 1.0).count(),
            r.len()
        );
    }
}
