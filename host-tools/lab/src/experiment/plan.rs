//! The experiment plan (TOML): a settle time and a list of conditions, each a combined bowl
//! speed (split into motor speeds by the rig's rule) or the two motor speeds, repeated.

use anyhow::{Result, bail};
use serde::Deserialize;

/// One condition as written.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Condition {
    /// Combined bowl speed (paper Eq. 2), rad/s.
    pub bowl_rad_s: Option<f64>,
    /// Precession speed, rad/s (with `spin_rad_s`, instead of `bowl_rad_s`).
    pub precession_rad_s: Option<f64>,
    /// Spin speed, rad/s.
    pub spin_rad_s: Option<f64>,
    /// Releases at this condition.
    pub repeats: usize,
}

/// A plan.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// Wait after the speeds have settled, before each release, s.
    #[serde(default = "default_settle")]
    pub settle_s: f64,
    /// The conditions, run in order (none: refused below in words, not as serde's "missing
    /// field" blamed on the first line's key).
    #[serde(default)]
    pub condition: Vec<Condition>,
}

/// Releases a condition may ask for: at least one, and a bound on a run that would take days
/// (`bowl experiment --suggest` checks its `--repeats` against the same range).
pub const REPEATS: std::ops::RangeInclusive<usize> = 1..=10_000;

fn default_settle() -> f64 {
    3.0
}

/// Reads and checks a plan.
pub fn parse(text: &str, file: &str) -> Result<Plan> {
    let plan: Plan = toml::from_str(text).map_err(|e| {
        let (line, words) = rig_file::toml_error_words(text, &e);
        let line = line.map_or(String::new(), |n| format!(", line {n}"));
        // Below a [[condition]] line every key is the condition's: the plan's own key there
        // reads as an unknown condition key, so say where it goes.
        let hint = if words.contains("unknown field `settle_s`") {
            " (settle_s is the whole plan's: write it above the first [[condition]])"
        } else {
            ""
        };
        anyhow::anyhow!("{file}{line}: not a valid plan: {words}{hint}")
    })?;
    if !(plan.settle_s.is_finite() && (0.0..=600.0).contains(&plan.settle_s)) {
        bail!(
            "{file}: settle_s = {} must lie in 0 ..= 600 s",
            plan.settle_s
        );
    }
    if plan.condition.is_empty() {
        bail!("{file}: the plan has no [[condition]]");
    }
    for (i, c) in plan.condition.iter().enumerate() {
        let n = i + 1;
        match (c.bowl_rad_s, c.precession_rad_s, c.spin_rad_s) {
            (Some(w), None, None) if w.is_finite() && w > 0.0 => {}
            (None, Some(p), Some(s)) if p.is_finite() && s.is_finite() => {}
            _ => bail!(
                "{file}: condition {n} needs either bowl_rad_s (> 0) or both precession_rad_s \
                 and spin_rad_s, finite"
            ),
        }
        if !REPEATS.contains(&c.repeats) {
            bail!(
                "{file}: condition {n} repeats = {} must lie in {} ..= {}",
                c.repeats,
                REPEATS.start(),
                REPEATS.end()
            );
        }
    }
    Ok(plan)
}

/// Total releases of a plan.
pub fn releases(plan: &Plan) -> usize {
    plan.condition.iter().map(|c| c.repeats).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_both_forms_and_names_errors() {
        let p = parse(
            "settle_s = 1.5\n[[condition]]\nbowl_rad_s = 6.5\nrepeats = 5\n\
             [[condition]]\nprecession_rad_s = 2.0\nspin_rad_s = 3.0\nrepeats = 2\n",
            "p.toml",
        )
        .unwrap();
        assert_eq!(p.settle_s, 1.5);
        assert_eq!(releases(&p), 7);
        let e = parse(
            "[[condition]]\nbowl_rad_s = 6.5\nspin_rad_s = 1\nrepeats = 5\n",
            "p.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("condition 1 needs either"), "{e}");
        let e = parse("[[condition]]\nbowl_rad_s = 6.5\nrepeats = 0\n", "p.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("repeats = 0"), "{e}");
        let e = parse("settle_s = 1\n", "p.toml").unwrap_err().to_string();
        assert_eq!(e, "p.toml: the plan has no [[condition]]");
        let e = parse(
            "[[condition]]\nbowl_rad_s = 3\nrepeats = 1\nsettle_s = 1\n",
            "p.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("line 4") && e.contains("write it above the first [[condition]]"),
            "{e}"
        );
        // serde's Rust type names are said in words, with the key and the line.
        let e = parse("[[condition]]\nbowl_rad_s = 6.5\nrepeats = 1.5\n", "p.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("p.toml, line 3") && e.contains("repeats:"),
            "{e}"
        );
        assert!(e.contains("a whole number") && !e.contains("usize"), "{e}");
    }
}
