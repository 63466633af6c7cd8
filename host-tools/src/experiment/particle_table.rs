//! The `[particle]` table of a rig file: the hidden truth of a simulated rig's granules
//! (`model_core::sim::granule::ParticleParams`). Every key is optional and defaults to
//! `ParticleParams::default()`; an unknown key, a wrong type or a value out of range is an error
//! that names the key and the range.

use anyhow::{Result, anyhow, bail};
use model_core::particle::Model;
use model_core::sim::granule::ParticleParams;

/// Reads a `[particle]` table (already parsed as TOML). `file` names the rig file in errors.
pub fn particle_from_table(table: &toml::Table, file: &str) -> Result<ParticleParams> {
    let mut p = ParticleParams::default();
    for (key, value) in table {
        let number = || -> Result<f64> {
            match value {
                toml::Value::Float(x) => Ok(*x),
                toml::Value::Integer(i) => Ok(*i as f64),
                other => Err(anyhow!(
                    "{file}: [particle] {key} must be a number, not {}",
                    other.type_str()
                )),
            }
        };
        match key.as_str() {
            "model" => {
                p.model = match value.as_str() {
                    Some("flat") => Model::Flat,
                    Some("coriolis") => Model::Coriolis,
                    _ => bail!(
                        "{file}: [particle] model must be \"flat\" or \"coriolis\", not {value}"
                    ),
                }
            }
            "mu" => p.mu = number()?,
            "mu_spread" => p.mu_spread = number()?,
            "k2" => p.k2 = number()?,
            "release_radius_m" => p.release_radius_m = number()?,
            "rim_radius_m" => p.rim_radius_m = number()?,
            "release_spread_m" => p.release_spread_m = number()?,
            "gate_jitter_s" => p.gate_jitter_s = number()?,
            other => bail!(
                "{file}: [particle] has no key {other:?}; the keys are model, mu, mu_spread, k2, \
                 release_radius_m, rim_radius_m, release_spread_m, gate_jitter_s"
            ),
        }
    }
    p.validate().map_err(|e| {
        anyhow!(
            "{file}: [particle] {} must lie in {} ..= {} (and the release radius inside the rim)",
            e.key,
            e.min,
            e.max
        )
    })?;
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ParticleParams> {
        let t: toml::Table = text.parse().unwrap();
        particle_from_table(t["particle"].as_table().unwrap(), "rig.toml")
    }

    #[test]
    fn reads_every_key() {
        let p = parse(
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
    }

    #[test]
    fn errors_name_the_key() {
        let e = parse("[particle]\nmu = -1\n").unwrap_err().to_string();
        assert!(
            e.contains("rig.toml") && e.contains("mu must lie in 0 ..= 1"),
            "{e}"
        );
        let e = parse("[particle]\nmodel = \"round\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("\"flat\" or \"coriolis\""), "{e}");
        let e = parse("[particle]\nmus = 1\n").unwrap_err().to_string();
        assert!(e.contains("no key \"mus\""), "{e}");
        let e = parse("[particle]\nk2 = \"a\"\n").unwrap_err().to_string();
        assert!(e.contains("k2 must be a number"), "{e}");
    }
}
