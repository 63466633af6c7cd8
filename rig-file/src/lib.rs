//! Rig files: a lab rig described in TOML, turned into the one simulated plant's parameters
//! (`model_core::sim::PlantParams`).
//!
//! Every key is optional and defaults to the nominal rig (docs/control.md). A rig file holds the
//! keys at the top level; a family file holds `[[plant]]` tables of the same keys, each with a
//! `name`. A bad file gets an error naming the file, the line, the key and the accepted range.
//! Keys and units: docs/rigs/nominal.toml.

use anyhow::{Result, anyhow};
use model_core::particle::Model;
use model_core::sim::granule::ParticleParams;
use model_core::sim::{AxisParams, CurrentSense, PlantParams};
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

mod bowl;
mod check;
mod words;
pub use bowl::BowlGeometry;
use check::Checker;
pub use words::toml_error_words;

/// One rig from a file: its name, the plant and the seed of its tooth offsets and jitter.
#[derive(Debug, Clone)]
pub struct Rig {
    /// `name` of the `[[plant]]` table, or the file's stem for a single rig.
    pub name: String,
    /// The plant.
    pub params: PlantParams,
    /// Seed of the tooth offsets and the edge jitter.
    pub seed: u32,
    /// The `[particle]` table: the hidden truth of the simulated granules (`bowl experiment`),
    /// if the file has one.
    pub particle: Option<ParticleParams>,
    /// The `[bowl]` table: the bowl's shape and tilt (`bowl predict --model bowl`), if any.
    pub bowl: Option<BowlGeometry>,
}

impl Rig {
    /// Gives every axis the typical current sense ([`CurrentSense::TYPICAL`]) where the file
    /// gave it none (`bowl sim --current-sense`: a family file run as if its rigs had one).
    pub fn with_current_sense(mut self) -> Self {
        for a in &mut self.params.axes {
            if !a.current_sense.enabled {
                a.current_sense = CurrentSense::TYPICAL;
            }
        }
        self
    }
}

type Num = Option<Spanned<f64>>;

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct AxisToml {
    resistance_ohm: Num,
    inductance_h: Num,
    torque_constant: Num,
    inertia_kg_m2: Num,
    viscous_nm_s: Num,
    coulomb_nm: Num,
    stiction_nm: Num,
    ripple_nm: Num,
    load_step_nm: Num,
    pulses_per_rev: Num,
    tooth_error: Num,
    jitter_s: Num,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct ParticleToml {
    model: Option<Spanned<String>>,
    mu: Num,
    mu_spread: Num,
    k2: Num,
    release_radius_m: Num,
    rim_radius_m: Num,
    release_spread_m: Num,
    gate_jitter_s: Num,
    sliding_mu: Num,
    sliding_mu_spread: Num,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RigToml {
    name: Option<String>,
    supply_v: Num,
    coupling: Num,
    timer_hz: Num,
    timer_bits: Num,
    seed: Num,
    current_sense: Option<bool>,
    current_offset_a: Num,
    current_gain_error: Num,
    current_noise_a: Num,
    precession: Option<AxisToml>,
    spin: Option<AxisToml>,
    particle: Option<ParticleToml>,
    bowl: Option<bowl::BowlToml>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FamilyToml {
    plant: Vec<RigToml>,
}

/// Reads a rig file or a family file: one rig per `[[plant]]` table, or the one rig.
pub fn load(path: &Path) -> Result<Vec<Rig>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow!("cannot read the rig file {}: {e}", path.display()))?;
    let stem = path
        .file_stem()
        .map_or("rig".into(), |s| s.to_string_lossy().into_owned());
    parse(&text, &path.display().to_string(), &stem)
}

/// Parses rig-file text; `file` names it in errors, `default_name` names a single rig.
pub fn parse(text: &str, file: &str, default_name: &str) -> Result<Vec<Rig>> {
    let at = |offset: usize| 1 + text[..offset.min(text.len())].matches('\n').count();
    let syntax = |e: toml::de::Error| {
        let (line, words) = toml_error_words(text, &e);
        let line = line.map_or(String::new(), |n| format!(", line {n}"));
        anyhow!("rig file {file}{line}: {words}")
    };
    let top = text.parse::<toml::Table>().map_err(syntax)?;
    let is_family = top.contains_key("plant");
    // A rig wrapped in [[plant]] whose tables kept their rig-file names ([precession]) puts
    // them at the top level, beside the plants: serde's "unknown field `precession`, expected
    // `plant`" did not say where they go.
    let stray: Vec<String> = top
        .iter()
        .filter(|(k, _)| is_family && k.as_str() != "plant")
        .map(|(k, v)| match v {
            toml::Value::Table(_) => format!("[{k}] (write it [plant.{k}])"),
            _ => format!("{k} (write it after the plant's [[plant]] line)"),
        })
        .collect();
    if !stray.is_empty() {
        return Err(anyhow!(
            "rig file {file}: a family file holds [[plant]] tables only, and {} is outside \
             them: each plant's keys follow its [[plant]] line, its tables are [plant.precession], \
             [plant.spin], [plant.particle] and [plant.bowl] (one rig needs no [[plant]] at all)",
            stray.join(", ")
        ));
    }
    let tables = if is_family {
        toml::from_str::<FamilyToml>(text).map_err(syntax)?.plant
    } else {
        vec![toml::from_str::<RigToml>(text).map_err(syntax)?]
    };
    if tables.is_empty() {
        return Err(anyhow!(
            "rig file {file}: the family has no [[plant]] table"
        ));
    }
    let mut rigs = Vec::with_capacity(tables.len());
    for (i, t) in tables.iter().enumerate() {
        let check = Checker { file, at: &at };
        let name = match (&t.name, is_family) {
            (Some(n), _) => n.clone(),
            (None, false) => default_name.to_string(),
            (None, true) => {
                return Err(anyhow!(
                    "rig file {file}: [[plant]] number {} has no name; give each plant a `name`",
                    i + 1
                ));
            }
        };
        rigs.push(Rig {
            params: check.rig(t)?,
            seed: check.integer(&t.seed, "seed", 0.0, u32::MAX as f64, 1.0)? as u32,
            particle: t
                .particle
                .as_ref()
                .map(|p| check.particle(p, t.bowl.as_ref()))
                .transpose()?,
            bowl: t.bowl.as_ref().map(|b| check.bowl(b)).transpose()?,
            name,
        });
    }
    Ok(rigs)
}

#[cfg(test)]
mod tests;
