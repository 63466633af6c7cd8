//! The CSV form of telemetry, shared by `bowl replay --csv` and `bowl monitor --log`: one row per
//! telemetry frame, keyed on (boot, device time); the values stay the wire's scaled integers, with
//! the unit in each column name.

use std::io::Write;

use anyhow::Result;
use model_core::wire::{Residence, Telemetry};

/// The header line.
pub const HEADER: &str = "boot,device_time_ms,seq,state,fault,\
prec_set_mrad_s,prec_measured_mrad_s,prec_duty_bp,prec_pulses,\
spin_set_mrad_s,spin_measured_mrad_s,spin_duty_bp,spin_pulses,\
bowl_mrad_s,residence_flat_ms,residence_coriolis_ms";

fn residence(r: Residence) -> String {
    match r {
        Residence::Ms(ms) => ms.to_string(),
        Residence::NeverLeaves => "never".to_string(),
        Residence::Unavailable => String::new(),
    }
}

/// Writes one row. `boot` counts the device restarts seen before this frame, so the key stays
/// unique when the device time starts again from zero.
pub fn write_row(out: &mut impl Write, boot: u64, t: &Telemetry) -> Result<()> {
    writeln!(
        out,
        "{},{},{},{:?},{:?},{},{},{},{},{},{},{},{},{},{},{}",
        boot,
        t.time_ms,
        t.seq,
        t.state,
        t.fault,
        t.precession.set_mrad_s,
        t.precession.measured_mrad_s,
        t.precession.duty_bp,
        t.precession.pulses,
        t.spin.set_mrad_s,
        t.spin.measured_mrad_s,
        t.spin.duty_bp,
        t.spin.pulses,
        t.bowl_mrad_s,
        residence(t.residence_flat),
        residence(t.residence_coriolis),
    )?;
    Ok(())
}
