//! The `[bowl]` table: the bowl's shape and its tilt, for the granule model of the real bowl
//! (`bowl predict --model bowl --rig-file`, model-core `particle::bowl`, docs/model.md §10).
//! How to measure each key on a real bowl: docs/rigs/nominal.toml.

use anyhow::{Result, anyhow};
use model_core::particle::bowl::{BowlError, BowlShape};
use model_core::particle::rolling::RollingError;
use model_core::sim::bowl_granule::BowlTruth;
use model_core::sim::granule::ParticleParams;
use serde::Deserialize;

use super::{Checker, Num, ParticleToml};

/// `[particle] sliding_mu`: default and range (the paper's measured 0.4).
const SLIDING_MU: (f64, f64, f64) = (0.4, 0.0, 2.0);
/// `[particle] sliding_mu_spread`: default and range.
const SLIDING_MU_SPREAD: (f64, f64, f64) = (0.0, 0.0, 0.5);

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
        let g = BowlGeometry {
            axes_angle_deg: v[0],
            rim_radius_m: v[1],
            wall_angle_deg: v[2],
            wall_height_m: v[3],
            fillet_radius_m: v[4],
            restitution: v[5],
            particle_radius_m: v[6],
        };
        // Every [bowl] table (`bowl predict --model bowl --rig-file` and `bowl fit --rig-file`
        // read it without a granule in the bowl): its fillet must end on its wall.
        let shape = BowlShape {
            wall_angle_rad: g.wall_angle_deg.to_radians(),
            wall_height_m: g.wall_height_m,
            fillet_radius_m: g.fillet_radius_m,
            restitution: g.restitution,
        };
        if shape.check_fillet().is_err() {
            let line = (self.at)(
                t.fillet_radius_m
                    .as_ref()
                    .or(t.wall_height_m.as_ref())
                    .map_or(0, |v| v.span().start),
            );
            let why = if g.wall_height_m <= 0.0 {
                format!(
                    "[bowl] fillet_radius_m = {} m with no wall (wall_height_m = 0, a bare rim): \
                     a fillet rounds the corner between the bottom and a wall, and a bare rim \
                     has none; give fillet_radius_m = 0, or the wall",
                    g.fillet_radius_m
                )
            } else {
                format!(
                    "[bowl] fillet_radius_m = {} m rises {:.4} m up the wall at wall_angle_deg = \
                     {} before it meets it, above wall_height_m = {} m: a fillet ends on its \
                     wall; measure the fillet again (the width of the rounded band seen from \
                     above divided by tan(wall_angle / 2)), or the wall's height",
                    g.fillet_radius_m,
                    shape.fillet_rise_m(),
                    g.wall_angle_deg,
                    g.wall_height_m
                )
            };
            return Err(anyhow!("rig file {}, line {line}: {why}", self.file));
        }
        Ok(g)
    }
}

impl Checker<'_> {
    /// `[particle] model = "bowl"` (declared on line `in_bowl`): the granule follows the bowl
    /// model in the rig's `[bowl]` table, which it needs; its `sliding_mu` and
    /// `sliding_mu_spread` are read (and refused without `model = "bowl"`), and its rim is the
    /// bowl's bottom radius (a `[particle] rim_radius_m` that differs is refused: one rim).
    pub(crate) fn granule_in_bowl(
        &self,
        t: &ParticleToml,
        bowl: Option<&BowlToml>,
        in_bowl: Option<usize>,
        p: &mut ParticleParams,
    ) -> Result<()> {
        let Some(line) = in_bowl else {
            if let Some(v) = t.sliding_mu.as_ref().or(t.sliding_mu_spread.as_ref()) {
                return Err(anyhow!(
                    "rig file {}, line {}: [particle] sliding_mu and sliding_mu_spread are the \
                     bowl model's: give them with model = \"bowl\" (and a [bowl] table) or \
                     leave them out",
                    self.file,
                    (self.at)(v.span().start)
                ));
            }
            return Ok(());
        };
        let Some(b) = bowl else {
            return Err(anyhow!(
                "rig file {}, line {line}: [particle] model = \"bowl\" needs a [bowl] table (the \
                 bowl's tilt, bottom radius and wall; keys in docs/rigs/nominal.toml)",
                self.file
            ));
        };
        let g = self.bowl(b)?;
        if let Some(v) = &t.rim_radius_m
            && *v.get_ref() != g.rim_radius_m
        {
            return Err(anyhow!(
                "rig file {}, line {}: [particle] rim_radius_m = {} differs from [bowl] \
                 rim_radius_m = {}: in the bowl model the rim is the bowl's bottom radius; leave \
                 [particle] rim_radius_m out",
                self.file,
                (self.at)(v.span().start),
                v.get_ref(),
                g.rim_radius_m
            ));
        }
        p.rim_radius_m = g.rim_radius_m;
        let (d, lo, hi) = SLIDING_MU;
        let sliding_mu = self.get(&t.sliding_mu, "[particle] sliding_mu", lo, hi, d)?;
        let (d, lo, hi) = SLIDING_MU_SPREAD;
        let sliding_mu_spread = self.get(
            &t.sliding_mu_spread,
            "[particle] sliding_mu_spread",
            lo,
            hi,
            d,
        )?;
        let truth = BowlTruth {
            shape: BowlShape {
                wall_angle_rad: g.wall_angle_deg.to_radians(),
                wall_height_m: g.wall_height_m,
                fillet_radius_m: g.fillet_radius_m,
                restitution: g.restitution,
            },
            axes_angle_rad: g.axes_angle_deg.to_radians(),
            particle_radius_m: g.particle_radius_m,
            sliding_mu,
            sliding_mu_spread,
        };
        // The shape against the granule's scene at its nominal start (speeds do not matter);
        // a start outside the rim is refused after this, in the [particle] table's words.
        let scene = truth.scene(p, [1.0, 1.0], sliding_mu, p.release_radius_m);
        let why = match truth.shape.validate(&scene) {
            _ if p.release_radius_m >= p.rim_radius_m => None,
            Ok(()) => None,
            Err(BowlError::FilletReachesRelease) => Some(format!(
                "the granule's start (release_radius_m = {} m) must lie on the flat bottom, \
                 clear of the fillet between bottom and wall (fillet_radius_m = {} m, bottom \
                 radius {} m) with the granule's radius (particle_radius_m = {} m): give a smaller \
                 release_radius_m, fillet_radius_m or particle_radius_m",
                p.release_radius_m, g.fillet_radius_m, g.rim_radius_m, g.particle_radius_m
            )),
            Err(BowlError::Scene(RollingError::InvalidK2)) => Some(format!(
                "[particle] k2 = {} must be below 1 in the bowl model (a rolling sphere: 5/7 for \
                 a solid one)",
                p.k2
            )),
            Err(_) => Some(
                "the [bowl] table and [particle] do not make a scene the bowl model accepts: \
                 check them against docs/rigs/nominal.toml"
                    .into(),
            ),
        };
        if let Some(why) = why {
            return Err(anyhow!("rig file {}, line {line}: {why}", self.file));
        }
        p.bowl = Some(truth);
        Ok(())
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

    #[test]
    fn a_granule_in_the_bowl_takes_the_bowls_rim_and_its_sliding_friction() {
        let rigs = parse(
            "[particle]\nmodel = \"bowl\"\nmu = 0.029\nrelease_radius_m = 0.0375\n\
             sliding_mu = 0.35\nsliding_mu_spread = 0.02\n\
             [bowl]\naxes_angle_deg = 60\nrim_radius_m = 0.075\nwall_angle_deg = 60\n\
             wall_height_m = 0.01\nrestitution = 0\n",
            "t.toml",
            "t",
        )
        .unwrap();
        let p = rigs[0].particle.unwrap();
        let b = p.bowl.unwrap();
        assert_eq!(p.rim_radius_m, 0.075);
        assert_eq!((b.sliding_mu, b.sliding_mu_spread), (0.35, 0.02));
        assert_eq!(b.shape.wall_height_m, 0.01);
        assert!((b.axes_angle_rad - 60f64.to_radians()).abs() < 1e-15);
        // Without model = "bowl" the granule follows the paper's equations.
        let rigs = parse("[particle]\nmu = 0.03\n[bowl]\n", "t.toml", "t").unwrap();
        assert_eq!(rigs[0].particle.unwrap().bowl, None);
    }

    #[test]
    fn a_granule_in_the_bowl_is_refused_in_words() {
        let err = |text: &str| parse(text, "t.toml", "t").unwrap_err().to_string();
        let e = err("[particle]\nmodel = \"bowl\"\n");
        assert!(
            e.contains("line 2") && e.contains("needs a [bowl] table"),
            "{e}"
        );
        let e = err("[particle]\nsliding_mu = 0.4\n");
        assert!(
            e.contains("line 2") && e.contains("model = \"bowl\""),
            "{e}"
        );
        let e = err("[particle]\nmodel = \"bowl\"\nrim_radius_m = 0.15\n[bowl]\n");
        assert!(
            e.contains("line 3") && e.contains("differs from [bowl]"),
            "{e}"
        );
        let e = err("[particle]\nmodel = \"bowl\"\nsliding_mu = 3\n[bowl]\n");
        assert!(
            e.contains("sliding_mu = 3 is outside its range 0 to 2"),
            "{e}"
        );
        let e = err("[particle]\nmodel = \"bowl\"\nrelease_radius_m = 0.06\n\
             [bowl]\nwall_height_m = 0.03\nfillet_radius_m = 0.02\n");
        assert!(e.contains("line 2") && e.contains("flat bottom"), "{e}");
        // A fillet above its wall, and one with no wall, are no bowl (the granule climbed the
        // arc past the lip).
        let e = err(
            "[particle]\nmodel = \"bowl\"\n[bowl]\nwall_angle_deg = 60\n\
             wall_height_m = 0.01\nfillet_radius_m = 0.05\n",
        );
        assert!(
            e.contains("line 6: [bowl] fillet_radius_m = 0.05 m rises 0.0250 m up the wall")
                && e.contains("above wall_height_m = 0.01 m"),
            "{e}"
        );
        // Any [bowl] table, a granule in it or not (predict and fit read it alone).
        let e = err("[bowl]\nfillet_radius_m = 0.005\n");
        assert!(
            e.contains("line 2: [bowl] fillet_radius_m = 0.005 m with no wall"),
            "{e}"
        );
        let e = err("[particle]\nmodel = \"bowl\"\nrelease_radius_m = 0.08\n[bowl]\n");
        assert!(e.contains("must lie inside the rim"), "{e}");
    }
}
