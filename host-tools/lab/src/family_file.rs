//! `bowl sim make-family`: a seeded family file of plants spread the way a lab rig differs from
//! its datasheet, written as `[[plant]]` tables of rig-file keys (tests/rigs/family-60.toml is
//! `bowl sim make-family --seed 1 --plants 60`).
//!
//! Spread, per axis unless said otherwise: inertia x0.3..3 and friction (viscous, Coulomb and
//! stiction together) x0.2..5, both log-uniform; torque constant +-30 %; supply 10..14 V (per
//! rig); each tooth off by up to 0..5 % of a pitch; edge jitter 0.1..1 ms; an eccentric bowl load
//! on the spin axis, 2..10 mN m once per revolution; coupling 0.4..0.6 (per rig); material poured
//! in after commissioning, 0..0.05 N m on the precession axis and 0.02..0.1 N m on the spin.

use model_core::sim::PlantParams;
use model_core::sim::prng::Prng;
use std::fmt::Write;

fn log_uniform(rng: &mut Prng, lo: f32, hi: f32) -> f32 {
    libm::expf(rng.range(libm::logf(lo), libm::logf(hi)))
}

/// The family file's text.
pub fn family_toml(seed: u32, plants: u32) -> String {
    let mut out = format!(
        "# {plants} plants: `bowl sim make-family --seed {seed} --plants {plants}` \
         (spread: host-tools/lab/src/family_file.rs)\n"
    );
    let nominal = PlantParams::nominal();
    for index in 0..plants {
        let mut rng = Prng::new(seed.wrapping_mul(0x9e37_79b9) ^ index.wrapping_mul(0x85eb_ca6b));
        let _ = writeln!(out, "\n[[plant]]\nname = \"p{index:02}\"");
        let _ = writeln!(
            out,
            "seed = {}",
            seed.wrapping_mul(1000).wrapping_add(index)
        );
        let _ = writeln!(out, "supply_v = {:.3}", rng.range(10.0, 14.0));
        let _ = writeln!(out, "coupling = {:.3}", rng.range(0.4, 0.6));
        for (i, section) in ["precession", "spin"].into_iter().enumerate() {
            let m = nominal.axes[i].motor;
            let inertia = log_uniform(&mut rng, 0.3, 3.0);
            let friction = log_uniform(&mut rng, 0.2, 5.0);
            let kt = rng.range(0.7, 1.3);
            let _ = writeln!(out, "[plant.{section}]");
            let _ = writeln!(out, "torque_constant = {:.4}", m.torque_constant * kt);
            let _ = writeln!(out, "inertia_kg_m2 = {:.5}", m.inertia_kg_m2 * inertia);
            let _ = writeln!(out, "viscous_nm_s = {:.5}", m.viscous_nm_s * friction);
            let _ = writeln!(out, "coulomb_nm = {:.4}", m.coulomb_nm * friction);
            let _ = writeln!(out, "stiction_nm = {:.4}", m.stiction_nm * friction);
            let _ = writeln!(out, "tooth_error = {:.4}", rng.range(0.0, 0.05));
            let _ = writeln!(out, "jitter_s = {:.6}", rng.range(100e-6, 1e-3));
            let (ripple, load) = if i == 1 {
                (rng.range(0.002, 0.01), rng.range(0.02, 0.1))
            } else {
                (nominal.axes[i].ripple_nm, rng.range(0.0, 0.05))
            };
            let _ = writeln!(out, "ripple_nm = {ripple:.4}");
            let _ = writeln!(out, "load_step_nm = {load:.4}");
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_family_parses_and_stays_inside_its_spread() {
        let text = super::family_toml(3, 20);
        let rigs = rig_file::parse(&text, "gen", "x").unwrap();
        assert_eq!(rigs.len(), 20);
        let nominal = model_core::sim::PlantParams::nominal();
        for r in &rigs {
            assert!((10.0..=14.0).contains(&r.params.supply_v));
            for i in 0..2 {
                let (m, n) = (r.params.axes[i].motor, nominal.axes[i].motor);
                let j = m.inertia_kg_m2 / n.inertia_kg_m2;
                assert!((0.299..=3.01).contains(&j), "{j}");
                let f = m.coulomb_nm / n.coulomb_nm;
                assert!((0.199..=5.01).contains(&f), "{f}");
                assert!(m.stiction_nm >= m.coulomb_nm);
                assert!(r.params.axes[i].sensor.tooth_error <= 0.05);
            }
        }
    }
}
