//! The tilt the runs were measured at, read back from the results rows: a rig writes each
//! row's target combined speed `bowl_rad_s` and the motor speeds it split it into (paper Eq. 2
//! at its own tilt), so a tilt that does not combine them into `bowl_rad_s` is not the one the
//! runs had. The rolling and bowl models put gravity at the tilt; fitting at the wrong one
//! gives a wrong wall and `mu_s` with confidence (45 deg runs fitted at 60 deg named a 20 mm
//! wall that was not there, AIC 17 ahead).

use std::path::Path;

use anyhow::{Result, bail};

use super::models::{Run, combined_rad_s};

/// Relative difference between the row's `bowl_rad_s` and its motor speeds combined at the
/// fit's tilt above which the tilt is refused. About 2 deg of tilt near 60 deg; well above what
/// a spreadsheet's rounding of the speeds to two decimals does (0.5 %).
const TOLERANCE: f64 = 0.01;

/// The tilt, degrees, at which `speeds_rad_s` combine to `bowl_rad_s` (paper Eq. 2 solved for
/// the angle between the axes); `None` when no tilt does.
pub fn implied_deg(speeds_rad_s: [f64; 2], bowl_rad_s: f64) -> Option<f64> {
    let [w1, w2] = speeds_rad_s;
    let cos = (bowl_rad_s * bowl_rad_s - w1 * w1 - w2 * w2) / (2.0 * w1 * w2);
    (cos.is_finite() && (-1.0..=1.0).contains(&cos)).then(|| cos.acos().to_degrees())
}

/// Where the fit's tilt came from (the refusal names it and says what to give instead).
#[derive(Debug, Clone, Copy)]
pub enum Source<'a> {
    /// The rig file's `[bowl] axes_angle_deg`.
    RigFile(&'a Path),
    /// `--axes-angle-deg`.
    Flag,
    /// The default, 60 deg (the results file does not record the tilt).
    Default,
}

/// Refuses runs whose rows combine their motor speeds at another tilt than `axes_angle_deg`.
/// Rows with a motor at rest say nothing of the tilt.
pub fn check(runs: &[Run], axes_angle_deg: f64, source: Source) -> Result<()> {
    for r in runs {
        let (Some(speeds @ [w1, w2]), Some(bowl)) = (r.bowl.speeds_rad_s, r.bowl.planned_rad_s)
        else {
            continue;
        };
        if !(w1 > 0.0 && w2 > 0.0 && bowl > 0.0) {
            continue;
        }
        let combined = combined_rad_s(speeds, axes_angle_deg.to_radians());
        if (combined / bowl - 1.0).abs() <= TOLERANCE {
            continue;
        }
        let from = match source {
            Source::RigFile(path) => {
                format!("the rig file {}'s [bowl] axes_angle_deg", path.display())
            }
            Source::Flag => "--axes-angle-deg".into(),
            Source::Default => "the default".into(),
        };
        let had = match implied_deg(speeds, bowl) {
            Some(deg) => format!(
                "the rig that wrote it had a tilt of {deg:.1} deg, and the rolling and bowl \
                 models put gravity at the tilt (a wrong one gives a wrong wall and mu); {}",
                match source {
                    Source::RigFile(_) => "fit with the rig file the runs were measured on".into(),
                    _ => format!(
                        "give --axes-angle-deg {deg:.1}, or the rig file the runs were measured on"
                    ),
                }
            ),
            None => "no tilt combines them into it: check the row's three speeds".into(),
        };
        bail!(
            "results line {}: its motor speeds, precession {w1} and spin {w2} rad/s, combine to \
             {combined:.4} rad/s at the tilt of {axes_angle_deg} deg ({from}; paper Eq. 2), but \
             its bowl_rad_s is {bowl}: {had}",
            r.row
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::models::BowlRun;

    fn run(speeds: [f64; 2], bowl: f64) -> Run {
        Run {
            row: 2,
            condition: 1,
            residence_s: 0.2,
            mean_rad_s: bowl,
            release_radius_m: 0.0375,
            rim_radius_m: 0.075,
            k2: 5.0 / 7.0,
            trace: vec![(0.0, bowl)],
            method: crate::fit::models::Method::ClosedForm,
            axes_angle_rad: 60f64.to_radians(),
            bowl: BowlRun {
                speeds_rad_s: Some(speeds),
                planned_rad_s: Some(bowl),
                ..BowlRun::default()
            },
        }
    }

    /// 1.5 rad/s split equally at 45 deg is 0.81179 rad/s a motor (a row of `bowl experiment`
    /// on a 45 deg rig); at 60 deg 0.86603.
    #[test]
    fn runs_from_another_tilt_are_refused_with_theirs() {
        let at45 = [run([0.81179416, 0.81179416], 1.5)];
        let e = check(&at45, 60.0, Source::Default).unwrap_err().to_string();
        assert!(
            e.contains("results line 2") && e.contains("tilt of 45.0 deg") && e.contains("60 deg"),
            "{e}"
        );
        assert!(e.contains("--axes-angle-deg 45.0"), "{e}");
        check(&at45, 45.0, Source::Flag).unwrap();
        check(&[run([0.86602545, 0.86602545], 1.5)], 60.0, Source::Flag).unwrap();
        // Speeds rounded to two decimals in a spreadsheet still fit their tilt.
        check(&[run([0.87, 0.87], 1.5)], 60.0, Source::Flag).unwrap();
        // One motor at rest: the combined speed is the other's at any tilt.
        check(&[run([0.0, 1.5], 1.5)], 60.0, Source::Flag).unwrap();
        let e = check(&[run([0.1, 0.1], 1.5)], 60.0, Source::Flag)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no tilt combines them"), "{e}");
    }
}
