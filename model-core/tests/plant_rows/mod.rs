//! A plant of a family file written as numbers in a test (`bowl sim make-family` rows), shared
//! by the control tests that reproduce one family plant.

use model_core::sim::{CurrentSense, PlantParams};

/// The nominal plant with the family row's supply, coupling and per axis `[torque constant,
/// inertia, viscous, Coulomb, stiction, tooth error, jitter, ripple, material]` (the keys of a
/// rig file's `[precession]` / `[spin]` tables, in that order; SI units).
pub fn rig_from_table(supply_v: f32, coupling: f32, axes: [[f32; 9]; 2]) -> PlantParams {
    let mut rig = PlantParams::nominal();
    rig.supply_v = supply_v;
    rig.coupling = coupling;
    for (a, v) in rig.axes.iter_mut().zip(axes) {
        a.motor.torque_constant = v[0];
        a.motor.inertia_kg_m2 = v[1];
        a.motor.viscous_nm_s = v[2];
        a.motor.coulomb_nm = v[3];
        a.motor.stiction_nm = v[4];
        a.sensor.tooth_error = v[5];
        a.sensor.jitter_s = v[6];
        a.ripple_nm = v[7];
        a.load_step_nm = v[8];
    }
    rig
}

/// `rig` with the typical current sense on both axes (the `current_sense = true` of a rig file).
#[allow(dead_code)] // only the current-sense tests call it
pub fn sensed(mut rig: PlantParams) -> PlantParams {
    for a in &mut rig.axes {
        a.current_sense = CurrentSense::TYPICAL;
    }
    rig
}
