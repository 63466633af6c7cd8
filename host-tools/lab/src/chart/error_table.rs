//! `bowl chart error-table --out model-core/src/choose/error_table.bin`: the chooser's table of
//! RK4's error constant, the Coriolis effect and `T` over a spin-up's dimensionless features
//! (`model_core::choose::table` says what each point holds), measured here on both cores.
//!
//! The file is bytes, not Rust source: 245,700 values would be megabytes of literals.
//! `host-tools/tests/error_table.rs` remeasures grid points and fails when the committed bytes
//! are not what this command writes.

use std::path::Path;

use anyhow::{Context, Result};
use model_core::choose::table::{BYTES, LOG_DAMPING, POINTS, measure};

/// One grid point's bytes, as `model_core::choose::table::measure` gives them.
type Measured = (usize, [u8; 3], Option<u8>);

/// The table's bytes: the Coriolis error constants, the effects and the times (one byte per
/// point of the five-dimensional grid each), then the flat error constants.
pub fn bytes() -> Result<Vec<u8>> {
    let workers = std::thread::available_parallelism().map_or(2, usize::from);
    let measured: Vec<Vec<Measured>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|w| {
                scope.spawn(move || {
                    (w..POINTS)
                        .step_by(workers)
                        .map(|p| {
                            let (three, flat) = measure(p);
                            (p, three, flat)
                        })
                        .collect()
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .map_err(|_| anyhow::anyhow!("a worker measuring the error table failed"))
            })
            .collect::<Result<_>>()
    })?;
    let mut out = vec![0u8; BYTES];
    for (p, three, flat) in measured.into_iter().flatten() {
        for (table, b) in three.into_iter().enumerate() {
            out[table * POINTS + p] = b;
        }
        if let Some(b) = flat {
            out[3 * POINTS + p / LOG_DAMPING.count] = b;
        }
    }
    Ok(out)
}

/// Writes the table to `out`.
pub fn write(out: &Path) -> Result<()> {
    let started = std::time::Instant::now();
    let table = bytes()?;
    std::fs::write(out, &table).with_context(|| format!("cannot write {}", out.display()))?;
    let measured = table.iter().filter(|&&b| b > 0).count();
    super::say(&format!(
        "wrote {} ({} values, {} measured, {:.1} s)",
        out.display(),
        table.len(),
        measured,
        started.elapsed().as_secs_f64()
    ));
    Ok(())
}
