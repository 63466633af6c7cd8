//! The bowl model's scene from the flags and a rig file's `[bowl]` table, checked: the bowl
//! model's and the whole hierarchy's (`--model auto`) one reading of them.

use anyhow::{Result, bail};
use model_core::particle::bowl::{BowlError, BowlShape};
use model_core::particle::rolling::{RollingMethod, RollingScene};

use super::bowl::{BowlInputs, words};
use super::{Inputs, MethodChoice, rolling};

/// The wall flags with the rig file's `[bowl]` table (or the defaults) under them.
pub(super) struct Wall {
    pub(super) angle_deg: f64,
    pub(super) height_m: f64,
    pub(super) fillet_m: f64,
    pub(super) restitution: f64,
}

impl BowlInputs {
    pub(super) fn wall(&self, table: Option<&rig_file::BowlGeometry>) -> Wall {
        let pick =
            |flag: Option<f64>, from: Option<f64>, default: f64| flag.or(from).unwrap_or(default);
        Wall {
            angle_deg: pick(self.wall_angle_deg, table.map(|t| t.wall_angle_deg), 90.0),
            height_m: pick(self.wall_height_m, table.map(|t| t.wall_height_m), 0.0),
            fillet_m: pick(self.fillet_radius_m, table.map(|t| t.fillet_radius_m), 0.0),
            restitution: pick(self.restitution, table.map(|t| t.restitution), 0.5),
        }
    }
}

/// The flags a rig file's `[bowl]` table sets, refused when given too (exit 2): the rig's
/// value was used while a later error blamed the flag's.
fn rig_conflicts(args: &Inputs, path: &std::path::Path, t: &rig_file::BowlGeometry) -> Result<()> {
    for (given, flag, what, value) in [
        (
            args.given.rim_radius_m,
            "--rim-radius-m",
            "the bowl's radius",
            t.rim_radius_m,
        ),
        (
            args.given.particle_radius_m,
            "--particle-radius-m",
            "the granule's radius",
            t.particle_radius_m,
        ),
    ] {
        if given {
            return crate::usage::usage(format!(
                "{flag} conflicts with --rig-file {}, which sets {what} ({value} m): drop one",
                path.display()
            ));
        }
    }
    Ok(())
}

pub(super) struct BowlSetup {
    pub(super) scene: RollingScene<f64>,
    /// The tilt, degrees.
    pub(super) th_deg: f64,
    pub(super) wall: Wall,
    pub(super) shape: BowlShape<f64>,
    pub(super) method: RollingMethod<f64>,
}

/// The bowl model's scene, tilt (degrees), wall, shape and method from the flags and the rig
/// file's `[bowl]` table, checked (also the whole-hierarchy chooser's, `--model auto`).
pub(super) fn scene_and_shape(
    args: &Inputs,
    r: &rolling::RollingInputs,
    b: &BowlInputs,
) -> Result<BowlSetup> {
    let (table, particle) = match &b.rig_file {
        Some(path) => {
            let rigs = rig_file::load(path)?;
            let Some(t) = rigs.first().and_then(|rig| rig.bowl) else {
                bail!(
                    "the rig file {} has no [bowl] table (its keys: docs/rigs/nominal.toml)",
                    path.display()
                );
            };
            rig_conflicts(args, path, &t)?;
            (Some(t), rigs.first().and_then(|rig| rig.particle))
        }
        None => (None, None),
    };
    let (mut scene, th_deg) = r.scene(args, "bowl", table.map(|t| t.axes_angle_deg))?;
    if let Some(t) = &table {
        scene.rim_radius_m = t.rim_radius_m;
        scene.particle_radius_m = t.particle_radius_m;
        // The rig's own release radius unless --ri-m is given (the release is the
        // experiment's choice; --store-table used the default 0.05 m on a 0.0375 m rig).
        // The same for the granule's own values: `bowl experiment` runs the rig file's granule,
        // and predict answered with the flags' defaults (mu_r 0.029, mu_s 0.4, k2 5/7) beside it.
        if let Some(p) = &particle {
            let g = &args.given;
            for (given, to, from) in [
                (g.ri_m, &mut scene.ri_m, p.release_radius_m),
                (g.mu, &mut scene.rolling_resistance, p.mu),
                (g.k2, &mut scene.k2, p.k2),
            ] {
                if !given {
                    *to = from;
                }
            }
            if let (false, Some(truth)) = (g.sliding_mu, &p.bowl) {
                scene.sliding_friction = truth.sliding_mu;
            }
        }
        scene.validate().map_err(|e| {
            anyhow::anyhow!("with the rig file's [bowl] table: {}", rolling::words(e))
        })?;
    }
    let wall = b.wall(table.as_ref());
    let method = match args.method {
        MethodChoice::Closed | MethodChoice::Dp54 => RollingMethod::Dp54 { rtol: args.tol },
        MethodChoice::Rk4 => RollingMethod::Rk4 {
            step_s: args.step_s.unwrap_or(1e-4),
        },
        other => {
            bail!(
                "--method {} is not offered for the bowl model: use dp54 (default) or rk4",
                super::method_name(other)
            )
        }
    };
    for (v, flag) in [
        (wall.angle_deg, "--wall-angle-deg"),
        (wall.height_m, "--wall-height-m"),
        (wall.fillet_m, "--fillet-radius-m"),
        (wall.restitution, "--restitution"),
        (b.max_time_s, "--max-time-s"),
    ] {
        if !v.is_finite() {
            bail!("{flag} must be a finite number, not {v}");
        }
    }
    // Checked here, once: the model checks it per release, and its refusal came prefixed with
    // the first release's azimuth although the flag is the whole run's.
    if b.max_time_s <= 0.0 {
        bail!(
            "--max-time-s {} s: each release is followed this long, so it must be above 0 \
             (default 10 s)",
            b.max_time_s
        );
    }
    rolling::fits(&scene)?;
    let shape = BowlShape {
        wall_angle_rad: wall.angle_deg.to_radians(),
        wall_height_m: wall.height_m,
        fillet_radius_m: wall.fillet_m,
        restitution: wall.restitution,
    };
    shape.validate(&scene).map_err(|e| match e {
        BowlError::FilletAboveWall => fillet_above_wall(&wall, shape.fillet_rise_m()),
        // The value given with the range (179.9 was refused without a word of which value).
        BowlError::InvalidWallAngle => anyhow::anyhow!(
            "--wall-angle-deg {}: the wall's angle from the bottom must be above 0 and at most \
             90 degrees (90 = a vertical wall, below 90 flared outwards; a wall leaning in over \
             the bottom is not modelled)",
            crate::number::echo(wall.angle_deg)
        ),
        // The values and the radius the release must stay inside: the words named the flags
        // alone, so a user could not tell by how much.
        BowlError::FilletReachesRelease => match shape.meridian(&scene) {
            // At or past the axis no release radius is inside it: the plain words say what to change.
            Some(m) if m.rho_b_m > 0.0 && m.rho_b_m.is_finite() => anyhow::anyhow!(
                "--ri-m {} m: the granule released there already touches the corner between \
                 bottom and wall (--fillet-radius-m {} m, widened by the granule's radius \
                 --particle-radius-m {} m, starts {} m from the axis); give --ri-m below {} m, \
                 or a smaller fillet or granule (the granule starts on the flat bottom)",
                crate::number::echo(scene.ri_m),
                crate::number::echo(wall.fillet_m),
                crate::number::echo(scene.particle_radius_m),
                crate::number::fixed(m.rho_b_m, 5),
                crate::number::fixed(m.rho_b_m, 5)
            ),
            // No release radius is inside it: "a smaller --ri-m" was advised at --ri-m 0.
            Some(m) if m.rho_b_m <= 0.0 => anyhow::anyhow!(
                "--fillet-radius-m {} m, widened by the granule's radius --particle-radius-m {} \
                 m, reaches the bowl's axis: the corner takes the whole bottom (--rim-radius-m \
                 {} m) and the granule has nowhere to start; give a smaller fillet",
                crate::number::echo(wall.fillet_m),
                crate::number::echo(scene.particle_radius_m),
                crate::number::echo(scene.rim_radius_m)
            ),
            _ => anyhow::anyhow!(words(e)),
        },
        e => anyhow::anyhow!(words(e)),
    })?;
    if wall.height_m > 0.0 && wall.height_m < scene.particle_radius_m {
        // The model meets the granule on the wall's face and ends it over the lip's radius;
        // a step lower than the granule's radius it would meet at the step's edge, which the
        // model does not have: a 1 nm wall held every release where a bare rim let them go.
        bail!(
            "--wall-height-m {} m is lower than the granule's radius {} m \
             (--particle-radius-m): the bowl model's wall meets the granule on its face, not \
             at the lip's edge, so it does not hold for a step that low; give 0 (a bare rim) or \
             a wall at least the granule's radius high",
            wall.height_m,
            scene.particle_radius_m
        );
    }
    Ok(BowlSetup {
        scene,
        th_deg,
        wall,
        shape,
        method,
    })
}

/// Why a fillet above its wall has no bowl, with the values: a bare rim has no corner to round,
/// and a fillet of radius `F` meets a wall at `A` deg `F (1 - cos A)` up it.
fn fillet_above_wall(wall: &Wall, rise_m: f64) -> anyhow::Error {
    use crate::number::echo;
    let f = echo(wall.fillet_m);
    if wall.height_m <= 0.0 {
        return anyhow::anyhow!(
            "--fillet-radius-m {f} m with no wall (--wall-height-m 0, a bare rim): a fillet \
             rounds the corner between the bottom and a wall, and a bare rim has none; give \
             --fillet-radius-m 0, or the wall's height and angle"
        );
    }
    // The largest fillet the wall holds, to four figures rounded down (so it is taken as given).
    let highest = wall.height_m / (1.0 - wall.angle_deg.to_radians().cos());
    let scale = 10f64.powf(3.0 - highest.log10().floor());
    let highest = (highest * scale).floor() / scale;
    anyhow::anyhow!(
        "--fillet-radius-m {f} m rises {} m up a wall at {} deg before it meets it, above the \
         wall's height (--wall-height-m {} m): a fillet ends on its wall; give a fillet of at \
         most {} m, or a taller wall",
        crate::number::fixed(rise_m, 4),
        echo(wall.angle_deg),
        echo(wall.height_m),
        echo(highest)
    )
}
