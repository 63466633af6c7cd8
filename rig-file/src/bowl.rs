//! The `[bowl]` table: the bowl's shape and its tilt, for the granule model of the real bowl
//! (`bowl predict --model bowl --rig-file`, model-core `particle::bowl`, docs/model.md §10).
//! How to measure each key on a real bowl: docs/rigs/nominal.toml.

use anyhow::Result;
use serde::Deserialize;

use super::{Checker, Num};

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct BowlToml {
    axes_angle_deg: Num,
    rim_radius_m: Num,
    wall_angle_deg: Num,
    wall_height_m: Num,
    fillet_radius_m: Num,
    restitution: Num,
    particle_radius_m: Num,
}

/// The `[bowl]` table's values (SI, angles in degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlGeometry {
    /// Angle between the vertical (the precession axis) and the bowl's own axis, degrees: the
    /// angle of paper Eq. 2. A rod at 60 degrees from the horizontal is 30 here.
    pub axes_angle_deg: f64,
    /// Radius of the flat bottom, where the wall starts, m.
    pub rim_radius_m: f64,
    /// Wall angle from the bottom plane, degrees (90 = vertical).
    pub wall_angle_deg: f64,
    /// Wall height above the bottom, m (0 = a bare rim).
    pub wall_height_m: f64,
    /// Fillet radius between bottom and wall, m (0 = a sharp corner).
    pub fillet_radius_m: f64,
    /// Coefficient of restitution of a granule against the wall.
    pub restitution: f64,
    /// Granule radius, m.
    pub particle_radius_m: f64,
}

impl BowlGeometry {
    /// Each key with its default and range: `(key, default, lo, hi)`.
    pub const RANGES: [(&'static str, f64, f64, f64); 7] = [
        ("axes_angle_deg", 60.0, 0.0, 89.9),
        ("rim_radius_m", 0.075, 0.005, 1.0),
        ("wall_angle_deg", 90.0, 1.0, 90.0),
        ("wall_height_m", 0.0, 0.0, 0.5),
        ("fillet_radius_m", 0.0, 0.0, 0.2),
        ("restitution", 0.5, 0.0, 1.0),
        ("particle_radius_m", 0.003, 0.0, 0.05),
    ];
}

impl Checker<'_> {
    /// The `[bowl]` table, each key checked against [`BowlGeometry::RANGES`].
    pub(crate) fn bowl(&self, t: &BowlToml) -> Result<BowlGeometry> {
        let given: [&Num; 7] = [
            &t.axes_angle_deg,
            &t.rim_radius_m,
            &t.wall_angle_deg,
            &t.wall_height_m,
            &t.fillet_radius_m,
            &t.restitution,
            &t.particle_radius_m,
        ];
        let mut v = [0.0; 7];
        for ((slot, (key, default, lo, hi)), g) in v.iter_mut().zip(BowlGeometry::RANGES).zip(given)
        {
            *slot = self.get(g, &format!("[bowl] {key}"), lo, hi, default)?;
        }
        Ok(BowlGeometry {
            axes_angle_deg: v[0],
            rim_radius_m: v[1],
            wall_angle_deg: v[2],
            wall_height_m: v[3],
            fillet_radius_m: v[4],
            restitution: v[5],
            particle_radius_m: v[6],
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::parse;

    #[test]
    fn the_bowl_table_reads_every_key_and_defaults_the_rest() {
        let rigs = parse(
            "[bowl]\naxes_angle_deg = 30\nrim_radius_m = 0.1\nwall_angle_deg = 60\n\
             wall_height_m = 0.02\nfillet_radius_m = 0.005\nrestitution = 0.3\n",
            "t.toml",
            "t",
        )
        .unwrap();
        let b = rigs[0].bowl.unwrap();
        assert_eq!(
            (
                b.axes_angle_deg,
                b.rim_radius_m,
                b.wall_angle_deg,
                b.wall_height_m
            ),
            (30.0, 0.1, 60.0, 0.02)
        );
        assert_eq!(
            (b.fillet_radius_m, b.restitution, b.particle_radius_m),
            (0.005, 0.3, 0.003)
        );
        assert!(parse("", "t.toml", "t").unwrap()[0].bowl.is_none());
    }

    #[test]
    fn a_bad_bowl_key_names_line_key_and_range() {
        let err = parse("seed = 2\n[bowl]\nwall_angle_deg = 120\n", "t.toml", "t")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("line 3: [bowl] wall_angle_deg = 120 is outside its range 1 to 90"),
            "{err}"
        );
        let err = parse("[bowl]\nwall_hieght_m = 1\n", "t.toml", "t")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("line 2") && err.contains("wall_hieght_m"),
            "{err}"
        );
    }
}
