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
pub use bowl::BowlGeometry;

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
        let line = e
            .span()
            .map_or(String::new(), |s| format!(", line {}", at(s.start)));
        anyhow!("rig file {file}{line}: {}", e.message().trim())
    };
    let is_family = text
        .parse::<toml::Table>()
        .map_err(syntax)?
        .contains_key("plant");
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
            seed: check.get(&t.seed, "seed", 0.0, u32::MAX as f64, 1.0)? as u32,
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

/// `x` as written by a person: the plant holds f32, so a nominal 0.02 reads 0.02, not the
/// f64 digits of the nearest f32.
fn shortest(x: f64) -> String {
    let narrow = x as f32;
    if f64::from(narrow) == x {
        format!("{narrow}")
    } else {
        format!("{x}")
    }
}

struct Checker<'a> {
    file: &'a str,
    at: &'a dyn Fn(usize) -> usize,
}

impl Checker<'_> {
    /// The value of `key` (or `default`), checked against `[lo, hi]`.
    fn get(&self, v: &Num, key: &str, lo: f64, hi: f64, default: f64) -> Result<f64> {
        let Some(v) = v else { return Ok(default) };
        let x = *v.get_ref();
        if x.is_finite() && x >= lo && x <= hi {
            Ok(x)
        } else {
            Err(anyhow!(
                "rig file {}, line {}: {key} = {x} is outside its range {} to {}; \
                 change it or leave the key out for the nominal value {}",
                self.file,
                (self.at)(v.span().start),
                shortest(lo),
                shortest(hi),
                shortest(default)
            ))
        }
    }

    fn integer(&self, v: &Num, key: &str, lo: f64, hi: f64, default: f64) -> Result<f64> {
        let x = self.get(v, key, lo, hi, default)?;
        if x.fract() != 0.0 {
            let line = v.as_ref().map_or(0, |v| (self.at)(v.span().start));
            return Err(anyhow!(
                "rig file {}, line {line}: {key} = {x} must be a whole number",
                self.file
            ));
        }
        Ok(x)
    }

    fn rig(&self, t: &RigToml) -> Result<PlantParams> {
        let mut p = PlantParams::nominal();
        p.supply_v = self.get(&t.supply_v, "supply_v", 1.0, 60.0, 12.0)? as f32;
        p.coupling = self.get(&t.coupling, "coupling", -1.0, 1.0, 0.5)? as f32;
        p.timer_hz = self.integer(&t.timer_hz, "timer_hz", 10_000.0, 1e9, 1e6)? as u32;
        let bits = self.integer(&t.timer_bits, "timer_bits", 16.0, 32.0, 32.0)?;
        if bits != 16.0 && bits != 32.0 {
            let line = t
                .timer_bits
                .as_ref()
                .map_or(0, |v| (self.at)(v.span().start));
            return Err(anyhow!(
                "rig file {}, line {line}: timer_bits = {bits} must be 16 or 32",
                self.file
            ));
        }
        p.timer_bits = bits as u8;
        let empty = AxisToml::default();
        for (i, (section, axis)) in [("precession", &t.precession), ("spin", &t.spin)]
            .into_iter()
            .enumerate()
        {
            self.axis(section, axis.as_ref().unwrap_or(&empty), &mut p.axes[i])?;
        }
        self.current_sense(t, &mut p)?;
        Ok(p)
    }

    /// The bridges' current sense (both axes: one driver board) and its errors.
    fn current_sense(&self, t: &RigToml, p: &mut PlantParams) -> Result<()> {
        let typical = CurrentSense::TYPICAL;
        let f = |v: &Num, key: &str, lo: f64, hi: f64, d: f32| -> Result<f32> {
            Ok(self.get(v, key, lo, hi, d.into())? as f32)
        };
        let c = CurrentSense {
            enabled: t.current_sense.unwrap_or(false),
            offset_a: f(
                &t.current_offset_a,
                "current_offset_a",
                -1.0,
                1.0,
                typical.offset_a,
            )?,
            gain_error: f(
                &t.current_gain_error,
                "current_gain_error",
                -0.5,
                0.5,
                typical.gain_error,
            )?,
            noise_a: f(
                &t.current_noise_a,
                "current_noise_a",
                0.0,
                1.0,
                typical.noise_a,
            )?,
        };
        let error_key = [
            &t.current_offset_a,
            &t.current_gain_error,
            &t.current_noise_a,
        ]
        .into_iter()
        .flatten()
        .next();
        if let (false, Some(v)) = (c.enabled, error_key) {
            return Err(anyhow!(
                "rig file {}, line {}: a current-sense error key without `current_sense = true`; \
                 add that line, or leave the error keys out",
                self.file,
                (self.at)(v.span().start)
            ));
        }
        for a in &mut p.axes {
            a.current_sense = if c.enabled { c } else { CurrentSense::NONE };
        }
        Ok(())
    }

    /// The `[particle]` table, each key checked against [`ParticleParams::ranges`]; with
    /// `model = "bowl"` the granule in the rig's `[bowl]` ([`Checker::granule_in_bowl`]).
    fn particle(&self, t: &ParticleToml, bowl: Option<&bowl::BowlToml>) -> Result<ParticleParams> {
        let mut p = ParticleParams::default();
        let mut in_bowl = None;
        if let Some(m) = &t.model {
            let line = (self.at)(m.span().start);
            match m.get_ref().as_str() {
                "flat" => p.model = Model::Flat,
                "coriolis" => p.model = Model::Coriolis,
                "bowl" => in_bowl = Some(line),
                other => {
                    return Err(anyhow!(
                        "rig file {}, line {line}: [particle] model = {other:?} must be \"flat\", \
                         \"coriolis\" or \"bowl\"",
                        self.file,
                    ));
                }
            };
        }
        // In the order of `ParticleParams::ranges`: mu, mu_spread, k2, release_radius_m,
        // rim_radius_m, release_spread_m, gate_jitter_s.
        let given: [&Num; 7] = [
            &t.mu,
            &t.mu_spread,
            &t.k2,
            &t.release_radius_m,
            &t.rim_radius_m,
            &t.release_spread_m,
            &t.gate_jitter_s,
        ];
        let mut values = [0.0; 7];
        for ((slot, (key, default, lo, hi)), v) in values
            .iter_mut()
            .zip(ParticleParams::default().ranges())
            .zip(given)
        {
            *slot = self.get(v, &format!("[particle] {key}"), lo, hi, default)?;
        }
        [
            p.mu,
            p.mu_spread,
            p.k2,
            p.release_radius_m,
            p.rim_radius_m,
            p.release_spread_m,
            p.gate_jitter_s,
        ] = values;
        self.granule_in_bowl(t, bowl, in_bowl, &mut p)?;
        if p.release_radius_m >= p.rim_radius_m {
            let line = t
                .release_radius_m
                .as_ref()
                .or(t.rim_radius_m.as_ref())
                .map_or(0, |v| (self.at)(v.span().start));
            return Err(anyhow!(
                "rig file {}, line {line}: [particle] release_radius_m = {} must lie inside the \
                 rim (rim_radius_m = {})",
                self.file,
                p.release_radius_m,
                p.rim_radius_m
            ));
        }
        Ok(p)
    }

    fn axis(&self, section: &str, a: &AxisToml, p: &mut AxisParams) -> Result<()> {
        let key = |k: &str| format!("[{section}] {k}");
        let m = &mut p.motor;
        let f = |v: &Num, k: &str, lo: f64, hi: f64, d: f32| -> Result<f32> {
            Ok(self.get(v, &key(k), lo, hi, d as f64)? as f32)
        };
        m.resistance_ohm = f(
            &a.resistance_ohm,
            "resistance_ohm",
            0.01,
            1000.0,
            m.resistance_ohm,
        )?;
        m.inductance_h = f(&a.inductance_h, "inductance_h", 1e-6, 1.0, m.inductance_h)?;
        m.torque_constant = f(
            &a.torque_constant,
            "torque_constant",
            1e-3,
            100.0,
            m.torque_constant,
        )?;
        m.inertia_kg_m2 = f(
            &a.inertia_kg_m2,
            "inertia_kg_m2",
            1e-6,
            100.0,
            m.inertia_kg_m2,
        )?;
        m.viscous_nm_s = f(&a.viscous_nm_s, "viscous_nm_s", 0.0, 100.0, m.viscous_nm_s)?;
        m.coulomb_nm = f(&a.coulomb_nm, "coulomb_nm", 0.0, 100.0, m.coulomb_nm)?;
        // Stiction is at least the sliding friction; without the key it keeps the nominal
        // ratio to it.
        let nominal_ratio = m.stiction_nm / m.coulomb_nm.max(f32::MIN_POSITIVE);
        let default_stiction = if a.coulomb_nm.is_some() {
            m.coulomb_nm * nominal_ratio
        } else {
            m.stiction_nm
        };
        m.stiction_nm = f(
            &a.stiction_nm,
            "stiction_nm",
            m.coulomb_nm as f64,
            100.0,
            default_stiction,
        )?;
        p.ripple_nm = f(&a.ripple_nm, "ripple_nm", 0.0, 100.0, p.ripple_nm)?;
        p.load_step_nm = f(&a.load_step_nm, "load_step_nm", 0.0, 100.0, p.load_step_nm)?;
        p.sensor.pulses_per_rev = self.integer(
            &a.pulses_per_rev,
            &key("pulses_per_rev"),
            1.0,
            1000.0,
            p.sensor.pulses_per_rev as f64,
        )? as u16;
        p.sensor.tooth_error = f(
            &a.tooth_error,
            "tooth_error",
            0.0,
            0.45,
            p.sensor.tooth_error,
        )?;
        p.sensor.jitter_s = f(&a.jitter_s, "jitter_s", 0.0, 0.01, p.sensor.jitter_s)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_file_is_the_nominal_rig() {
        let r = parse("", "x.toml", "x").unwrap();
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].params, PlantParams::nominal());
        assert_eq!(r[0].seed, 1);
        assert_eq!(r[0].particle, None);
    }

    fn particle(text: &str) -> Result<ParticleParams> {
        Ok(parse(text, "rig.toml", "rig")?[0].particle.unwrap())
    }

    #[test]
    fn the_particle_table_reads_every_key() {
        let p = particle(
            "[particle]\nmodel = \"flat\"\nmu = 0.03\nmu_spread = 0.001\nk2 = 0.6\n\
             release_radius_m = 0.04\nrim_radius_m = 0.12\nrelease_spread_m = 0.002\n\
             gate_jitter_s = 0.01\n",
        )
        .unwrap();
        assert_eq!(p.model, Model::Flat);
        assert_eq!(
            (p.mu, p.mu_spread, p.k2, p.release_radius_m),
            (0.03, 0.001, 0.6, 0.04)
        );
        assert_eq!(
            (p.rim_radius_m, p.release_spread_m, p.gate_jitter_s),
            (0.12, 0.002, 0.01)
        );
        // Keys left out keep the defaults; the plant keys beside it are read too.
        let r = &parse(
            "supply_v = 10.0\n[particle]\nmu = 0.05\n",
            "rig.toml",
            "rig",
        )
        .unwrap()[0];
        assert_eq!(r.params.supply_v, 10.0);
        let p = r.particle.unwrap();
        assert_eq!((p.mu, p.k2), (0.05, ParticleParams::default().k2));
    }

    #[test]
    fn particle_errors_name_the_line_the_key_and_the_range() {
        let e = particle("\n[particle]\nmu = -1\n").unwrap_err().to_string();
        assert!(
            e.contains("rig.toml, line 3")
                && e.contains("[particle] mu = -1 is outside its range 0 to 1"),
            "{e}"
        );
        let e = particle("[particle]\nmodel = \"round\"\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 2") && e.contains("\"flat\", \"coriolis\" or \"bowl\""),
            "{e}"
        );
        let e = particle("[particle]\nmus = 1\n").unwrap_err().to_string();
        assert!(e.contains("unknown field `mus`"), "{e}");
        let e = particle("[particle]\nk2 = \"a\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2"), "{e}");
        let e = particle("[particle]\nrelease_radius_m = 0.2\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("must lie inside the rim (rim_radius_m = 0.15)"),
            "{e}"
        );
    }

    #[test]
    fn keys_reach_the_plant() {
        let r = parse(
            "supply_v = 10.5\nseed = 7\n[spin]\ninertia_kg_m2 = 0.05\npulses_per_rev = 60\n",
            "x.toml",
            "x",
        )
        .unwrap();
        assert_eq!(r[0].params.supply_v, 10.5);
        assert_eq!(r[0].seed, 7);
        assert_eq!(r[0].params.axes[1].motor.inertia_kg_m2, 0.05);
        assert_eq!(r[0].params.axes[1].sensor.pulses_per_rev, 60);
        assert_eq!(r[0].params.axes[0], PlantParams::nominal().axes[0]);
    }

    #[test]
    fn current_sense_is_off_by_default_and_its_keys_reach_both_axes() {
        let r = parse("", "x.toml", "x").unwrap();
        assert!(!r[0].params.axes[0].current_sense.enabled);
        assert_eq!(r[0].params, PlantParams::nominal());
        let r = parse("current_sense = true\n", "x.toml", "x").unwrap();
        assert_eq!(r[0].params.axes[1].current_sense, CurrentSense::TYPICAL);
        let r = parse(
            "[[plant]]\nname = \"a\"\ncurrent_sense = true\ncurrent_offset_a = -0.05\n\
             current_gain_error = 0.1\ncurrent_noise_a = 0.002\n[[plant]]\nname = \"b\"\n",
            "f.toml",
            "x",
        )
        .unwrap();
        let c = r[0].params.axes[0].current_sense;
        assert!(c.enabled);
        assert_eq!((c.offset_a, c.gain_error, c.noise_a), (-0.05, 0.1, 0.002));
        assert_eq!(r[0].params.axes[1].current_sense, c);
        assert!(!r[1].params.axes[0].current_sense.enabled);
        assert!(
            r[1].clone().with_current_sense().params.axes[0]
                .current_sense
                .enabled
        );
    }

    #[test]
    fn a_current_sense_error_key_needs_current_sense() {
        let e = parse("current_noise_a = 0.01\n", "c.toml", "x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("c.toml, line 1"), "{e}");
        assert!(e.contains("current_sense = true"), "{e}");
        let e = parse(
            "current_sense = true\ncurrent_gain_error = 0.9\n",
            "c.toml",
            "x",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("line 2") && e.contains("current_gain_error"),
            "{e}"
        );
    }

    #[test]
    fn a_value_out_of_range_names_file_line_key_and_range() {
        let e = parse(
            "seed = 2\n[precession]\ntooth_error = 0.7\n",
            "bad.toml",
            "x",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("bad.toml"), "{e}");
        assert!(e.contains("line 3"), "{e}");
        assert!(e.contains("[precession] tooth_error"), "{e}");
        assert!(e.contains("0 to 0.45"), "{e}");
    }

    #[test]
    fn an_unknown_key_names_its_line() {
        let e = parse(
            "[[plant]]\nname = \"a\"\n[[plant]]\nname = \"b\"\nsuply_v = 3\n",
            "f.toml",
            "x",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("line 5"), "{e}");
        assert!(e.contains("suply_v"), "{e}");
    }

    #[test]
    fn a_family_needs_names() {
        let e = parse("[[plant]]\nsupply_v = 11\n", "f.toml", "x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no name"), "{e}");
        let r = parse(
            "[[plant]]\nname = \"a\"\n[[plant]]\nname = \"b\"\nsupply_v = 11\n",
            "f",
            "x",
        )
        .unwrap();
        assert_eq!(r.len(), 2);
        assert_eq!(r[1].name, "b");
        assert_eq!(r[1].params.supply_v, 11.0);
    }
}
