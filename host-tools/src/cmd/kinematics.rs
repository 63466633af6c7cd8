//! `bowl kinematics`: paper Eq. 2 both ways.

use anyhow::{Result, anyhow};
use model_core::bowl::{BowlError, BowlGeometry, MotorSpeeds};

/// Flags of `bowl kinematics`.
#[derive(clap::Args)]
pub struct Args {
    /// Precession speed omega1 (rod about the vertical), rad/s.
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 1.8)]
    precession_rad_s: f64,
    /// Spin speed omega2 (bowl about its own axis), rad/s.
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 1.8)]
    spin_rad_s: f64,
    /// Angle between the spin and precession axes, degrees (see the docs: not the rod's tilt).
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 60.0)]
    axes_angle_deg: f64,
    /// Instead: split this combined bowl speed (rad/s) into motor speeds.
    #[arg(long, value_parser = crate::cmd::number)]
    split_rad_s: Option<f64>,
    /// Spin/precession ratio used by --split-rad-s.
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 1.0)]
    ratio: f64,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs `bowl kinematics`.
pub fn run(args: &Args) -> Result<()> {
    let geometry = BowlGeometry::new(args.axes_angle_deg.to_radians()).map_err(|e| {
        anyhow!(
            "invalid --axes-angle-deg {}: {}",
            args.axes_angle_deg,
            geometry_words(e)
        )
    })?;
    let speeds = match args.split_rad_s {
        Some(omega) => geometry.split(omega, args.ratio).map_err(|e| {
            anyhow!(
                "cannot split {omega} rad/s at ratio {}: {}",
                args.ratio,
                geometry_words(e)
            )
        })?,
        None => MotorSpeeds {
            precession_rad_s: args.precession_rad_s,
            spin_rad_s: args.spin_rad_s,
        },
    };
    let omega = geometry
        .combined_speed_rad_s(speeds)
        .map_err(|e| anyhow!("invalid motor speeds: {}", geometry_words(e)))?;
    if args.json {
        println!(
            "{}",
            serde_json::json!({
                "precession_rad_s": speeds.precession_rad_s,
                "spin_rad_s": speeds.spin_rad_s,
                "axes_angle_deg": args.axes_angle_deg,
                "combined_rad_s": omega,
            })
        );
    } else {
        println!(
            "precession {:.6} rad/s, spin {:.6} rad/s, axes {:.1} deg -> bowl {:.6} rad/s",
            speeds.precession_rad_s, speeds.spin_rad_s, args.axes_angle_deg, omega
        );
    }
    Ok(())
}

/// Paper Eq. 2's refusals in plain words.
fn geometry_words(e: BowlError) -> &'static str {
    match e {
        BowlError::NonFiniteSpeed => "each motor speed must be a finite number (rad/s)",
        BowlError::NegativeTargetSpeed => "the bowl speed to split must be 0 or more (rad/s)",
        BowlError::InvalidRatio => "--ratio must be a finite number, 0 or more",
        BowlError::InvalidAxesAngle => {
            "the angle between the axes must lie in [0, 180) degrees (at 180 the axes oppose and \
             equal speeds cancel)"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every refusal reads as one line of plain words: no run of spaces (a string continued
    /// onto the next source line without its `\` keeps the indentation), no space at either
    /// end, no Rust name.
    #[test]
    fn every_refusal_is_plain_words() {
        let all = [
            BowlError::NonFiniteSpeed,
            BowlError::NegativeTargetSpeed,
            BowlError::InvalidRatio,
            BowlError::InvalidAxesAngle,
        ];
        for e in all {
            // A new refusal fails to compile here until it is listed above.
            match e {
                BowlError::NonFiniteSpeed
                | BowlError::NegativeTargetSpeed
                | BowlError::InvalidRatio
                | BowlError::InvalidAxesAngle => {}
            }
            let text = geometry_words(e);
            assert!(!text.contains("  "), "{e:?}: {text:?}");
            assert_eq!(text.trim(), text, "{e:?}");
            assert!(!text.contains(&format!("{e:?}")), "{e:?}: {text:?}");
        }
    }
}
