//! The flags the user typed against the model chosen: one the model would ignore, or one a
//! rig file sets, is refused in words (exit 2) instead of answered without it.

use anyhow::Result;

use super::{Inputs, MethodChoice, ModelChoice, whole};

/// Which flags with a default the user typed: a flag the chosen model does not use, or one a
/// rig file sets, is refused in words instead of ignored (`--omega-rad-s` with the bowl model
/// answered for the motor speeds without a word).
#[derive(Debug, Clone, Copy, Default)]
pub struct Given {
    pub omega_rad_s: bool,
    pub ri_m: bool,
    pub rim_radius_m: bool,
    pub particle_radius_m: bool,
    pub method: bool,
    pub mu: bool,
    pub k2: bool,
    pub sliding_mu: bool,
}

/// Flags the chosen model would ignore, refused (exit 2) instead of answered without them.
pub(super) fn refuse_unused(args: &Inputs) -> Result<()> {
    let tilted = match args.model {
        ModelChoice::Rolling => Some("rolling"),
        ModelChoice::Bowl => Some("bowl"),
        ModelChoice::Auto if whole::wanted(args) => Some("tilted-bowl (--model auto)"),
        _ => None,
    };
    if let Some(name) = tilted {
        if args.given.omega_rad_s {
            return crate::usage::usage(format!(
                "--omega-rad-s {} is the paper's level bowl's one combined speed; the {name} \
                 model takes the two motor speeds, --precession-rad-s and --spin-rad-s, and \
                 ignores it: drop --omega-rad-s",
                args.omega_rad_s
            ));
        }
    } else if args.given.particle_radius_m {
        return crate::usage::usage(
            "--particle-radius-m is the tilted bowl's (--model rolling or bowl); the paper's \
             level-bowl models take the granule as a point and would ignore it: drop it",
        );
    }
    if args.model == ModelChoice::Bowl && args.given.method && args.method == MethodChoice::Closed {
        return crate::usage::usage(
            "--method closed: the bowl model has no closed form; it integrates with dp54 \
             (the default) or rk4: drop --method or give one of those",
        );
    }
    Ok(())
}
