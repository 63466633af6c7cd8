//! The simulated rig's current sense, shorted bridge and supply cut (model-core/src/sim/plant.rs),
//! checked against the motor's own equations: `i = (V d - k w) / R` once the inductance has
//! settled, and a reading of `(1 + gain) i + offset + noise`.

use model_core::sim::{CurrentSense, Plant, PlantParams};

const DT_S: f32 = 0.001;

fn sensed_rig() -> PlantParams {
    let mut p = PlantParams::nominal();
    for a in &mut p.axes {
        a.current_sense = CurrentSense::TYPICAL;
    }
    p
}

/// `(1 + gain) i + offset`, and the noise bound around it.
fn expected_reading(c: CurrentSense, i: f32) -> (f32, f32) {
    ((1.0 + c.gain_error) * i + c.offset_a, c.noise_a + 1e-5)
}

#[test]
fn no_current_sense_reads_nothing_and_changes_nothing() {
    let mut a = Plant::new(PlantParams::nominal(), 3);
    let mut b = Plant::new(sensed_rig(), 3);
    assert_eq!(a.sensed_current_a(0), None);
    for _ in 0..2000 {
        a.advance([0.4, 0.3], DT_S);
        b.advance([0.4, 0.3], DT_S);
    }
    // The sense only reads: the physics is the same with and without it.
    assert_eq!(a.speed_rad_s(0), b.speed_rad_s(0));
    assert_eq!(a.angle_rad(1), b.angle_rad(1));
    assert_eq!(a.sensed_current_a(1), None);
}

#[test]
fn a_coasting_bridge_reads_the_offset_and_a_driving_one_the_armature_current() {
    let p = sensed_rig();
    let c = p.axes[0].current_sense;
    let mut rig = Plant::new(p, 5);
    for _ in 0..50 {
        rig.advance([0.0; 2], DT_S);
        let (mean, band) = expected_reading(c, 0.0);
        let r = rig.sensed_current_a(0).unwrap();
        assert!((r - mean).abs() <= band, "{r}");
    }
    // Below stiction the shaft stays at rest: the current is V d / R exactly.
    let m = p.axes[0].motor;
    let d = 0.8 * m.ideal_breakaway_duty(p.supply_v);
    for _ in 0..5 {
        rig.advance([d, 0.0], DT_S);
    }
    assert_eq!(rig.speed_rad_s(0), 0.0);
    let stall_a = p.supply_v * d / m.resistance_ohm;
    let (mean, band) = expected_reading(c, stall_a);
    let r = rig.sensed_current_a(0).unwrap();
    assert!((r - mean).abs() <= band + 1e-3 * stall_a, "{r} vs {mean}");
    // Turning, the back-EMF takes its share.
    for _ in 0..3000 {
        rig.advance([0.5, 0.0], DT_S);
    }
    let w = rig.speed_rad_s(0);
    assert!(w > 1.0, "{w}");
    let i = (p.supply_v * 0.5 - m.torque_constant * w) / m.resistance_ohm;
    let (mean, band) = expected_reading(c, i);
    let r = rig.sensed_current_a(0).unwrap();
    assert!((r - mean).abs() <= band + 0.01 * i.abs(), "{r} vs {mean}");
    // The noise varies from sample to sample (not a fixed second offset).
    let mut seen = Vec::new();
    for _ in 0..20 {
        rig.advance([0.0; 2], DT_S);
        seen.push(rig.sensed_current_a(0).unwrap());
    }
    let spread = seen.iter().cloned().fold(f32::MIN, f32::max)
        - seen.iter().cloned().fold(f32::MAX, f32::min);
    assert!(
        spread > 0.5 * c.noise_a && spread <= 2.0 * c.noise_a,
        "{spread}"
    );
}

#[test]
fn a_shorted_bridge_drives_at_zero_duty_until_the_supply_is_cut() {
    let mut p = sensed_rig();
    p.axes[1].faults.bridge_shorted_from_s = 0.5;
    let mut rig = Plant::new(p, 1);
    for _ in 0..500 {
        rig.advance([0.0, 0.2], DT_S);
    }
    let before = rig.speed_rad_s(1);
    for _ in 0..300 {
        rig.advance([0.0, 0.0], DT_S);
    }
    // Full duty, though told to coast: faster than 0.2 duty ever drove it.
    assert!(
        rig.speed_rad_s(1) > 2.0 * before,
        "{before} -> {}",
        rig.speed_rad_s(1)
    );
    // At the full-duty speed the current is the load's, `(b w + Tc) / k`, still well above the
    // offset and noise of a coasting bridge.
    let m = p.axes[1].motor;
    let w = rig.speed_rad_s(1);
    let load_a = (m.viscous_nm_s * w + m.coulomb_nm) / m.torque_constant;
    let (mean, band) = expected_reading(p.axes[1].current_sense, load_a);
    let r = rig.sensed_current_a(1).unwrap();
    assert!((r - mean).abs() < band + 0.1 * load_a, "{r} vs {mean}");
    assert!(r > 0.02 + 3.0 * band, "{r}");
    assert!(!rig.supply_is_cut());
    rig.cut_supply();
    for _ in 0..3000 {
        rig.advance([0.0, 0.5], DT_S);
    }
    assert!(rig.supply_is_cut());
    assert_eq!(rig.speed_rad_s(1), 0.0);
    assert_eq!(rig.current_a(1), 0.0);
    // The cut removes all drive: the healthy axis too, whatever it is told.
    assert_eq!(rig.speed_rad_s(0), 0.0);
}

#[test]
fn a_bridge_stuck_on_still_coasts_at_zero_duty() {
    let mut p = sensed_rig();
    p.axes[0].faults.bridge_stuck_from_s = 0.0;
    let mut rig = Plant::new(p, 1);
    for _ in 0..300 {
        rig.advance([0.1, 0.0], DT_S);
    }
    assert!(rig.speed_rad_s(0) > 1.0);
    for _ in 0..3000 {
        rig.advance([0.0, 0.0], DT_S);
    }
    assert_eq!(rig.speed_rad_s(0), 0.0);
}
