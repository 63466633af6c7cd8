//! Which wall the measured times prefer (`bowl fit --bowl-walls`): every bowl wall fitted is
//! ranked by its AIC, and the verdict says in words either which wall and by how much, or that
//! these runs cannot tell the two best apart, by how much they differ against the runs' own
//! scatter, and what to measure to tell them. Method: docs/experiment.md ("Which wall: the verdict").

use serde_json::json;

use super::models::{Equation, Run, bowl_release};
use super::stats::AIC_DECISIVE;
use super::{K2, ModelFit};

/// Separation, in the runs' own timing standard deviations over all runs (`D` of the AIC
/// decision, docs/experiment.md "Decision"), at which the right model wins by more than
/// [`AIC_DECISIVE`] with probability above 98 %.
const D_DECISIVE: f64 = 6.0;

/// One wall in the ranking.
#[derive(Debug, Clone, PartialEq)]
pub struct RankedWall {
    /// Candidate name.
    pub name: &'static str,
    /// Its AIC.
    pub aic: f64,
    /// AIC above the best wall's.
    pub delta_aic: f64,
    /// Fitted `mu_s` and its 95 % interval.
    pub mu_s: f64,
    /// The interval.
    pub mu_s_ci95: (f64, f64),
    /// Why it cannot reproduce the runs, if it cannot.
    pub cannot_reproduce: Option<String>,
}

/// The verdict on the wall.
#[derive(Debug, Clone, PartialEq)]
pub struct WallVerdict {
    /// The wall named decisively; `None`: undecided.
    pub preferred: Option<&'static str>,
    /// Every bowl wall with a finite AIC, best first.
    pub ranked: Vec<RankedWall>,
    /// Runs compared at their own release azimuth (the rest with the azimuths' mean).
    pub runs_with_azimuth: usize,
    /// The verdict in words.
    pub text: String,
}

/// The verdict on the bowl walls among `models` (`None` when no bowl wall was fitted).
pub fn verdict(runs: &[Run], models: &[ModelFit]) -> Option<WallVerdict> {
    let walls: Vec<&ModelFit> = models
        .iter()
        .filter(|m| matches!(m.candidate.equation, Equation::Bowl(_)))
        .collect();
    if walls.is_empty() {
        return None;
    }
    let runs_with_azimuth = runs.iter().filter(|r| r.bowl.azimuth_rad.is_some()).count();
    let mut finite: Vec<&ModelFit> = walls
        .iter()
        .copied()
        .filter(|m| m.aic.is_finite())
        .collect();
    finite.sort_by(|a, b| a.aic.total_cmp(&b.aic));
    let Some(best) = finite
        .iter()
        .copied()
        .find(|m| m.cannot_reproduce.is_none())
    else {
        return Some(WallVerdict {
            preferred: None,
            ranked: Vec::new(),
            runs_with_azimuth,
            text: "no wall reproduces these runs (each holds a release or cannot match the \
                   times): the bowl is not one of the walls tried"
                .into(),
        });
    };
    let ranked: Vec<RankedWall> = finite
        .iter()
        .map(|m| RankedWall {
            name: m.candidate.name,
            aic: m.aic,
            delta_aic: m.aic - best.aic,
            mu_s: m.mu,
            mu_s_ci95: m.mu_ci95,
            cannot_reproduce: m.cannot_reproduce.clone(),
        })
        .collect();
    let held: Vec<&str> = walls
        .iter()
        .filter(|m| !m.aic.is_finite())
        .map(|m| m.candidate.name)
        .collect();
    let held_words = if held.is_empty() {
        String::new()
    } else {
        format!(
            " ({} cannot: some release never leaves under it)",
            held.join(", ")
        )
    };
    let next = finite.iter().copied().find(|m| !std::ptr::eq(*m, best));
    let Some(next) = next else {
        return Some(WallVerdict {
            preferred: Some(best.candidate.name),
            ranked,
            runs_with_azimuth,
            text: format!(
                "the {}: the only wall that reproduces these runs{held_words}; mu_s {:.3} \
                 [{:.3}, {:.3}]",
                best.candidate.name, best.mu, best.mu_ci95.0, best.mu_ci95.1
            ),
        });
    };
    let gap = next.aic - best.aic;
    if gap > AIC_DECISIVE {
        return Some(WallVerdict {
            preferred: Some(best.candidate.name),
            ranked,
            runs_with_azimuth,
            text: format!(
                "the {}: AIC {gap:.1} lower than the {} (the next best wall; decisive above \
                 {AIC_DECISIVE}){held_words}; mu_s {:.3} [{:.3}, {:.3}]",
                best.candidate.name, next.candidate.name, best.mu, best.mu_ci95.0, best.mu_ci95.1
            ),
        });
    }
    // Undecided: how far apart the two walls' fitted times are against the runs' scatter.
    let n = runs.len() as f64;
    let apart_pct = (best
        .errors_pct
        .iter()
        .zip(&next.errors_pct)
        .map(|(b, x)| (x - b).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let noise_pct = best.rms_error_pct;
    let needed = releases_needed(apart_pct, noise_pct);
    let mut text = format!(
        "cannot tell the {} from the {} with these {} runs (AIC {gap:.1} apart, decisive above \
         {AIC_DECISIVE}): their fitted times differ by {apart_pct:.2} % (RMS over the runs), the \
         runs scatter by {noise_pct:.2} % about the better one{held_words}",
        best.candidate.name,
        next.candidate.name,
        runs.len()
    );
    if runs_with_azimuth < runs.len() {
        let at_azimuth = azimuth_apart_pct(runs, best, next);
        text += &format!(
            "; {} of the runs have no recorded release azimuth and are compared with the mean \
             over the azimuths, which the random azimuth scatters; at a known azimuth these walls \
             differ by {at_azimuth:.1} % (RMS over twelve azimuths at these speeds): record each \
             release's azimuth (results column release_azimuth_deg) to tell them apart",
            runs.len() - runs_with_azimuth
        );
        if let Some(k) = needed {
            text += &format!(", or measure about {k} releases without it");
        }
    } else if let Some(k) = needed {
        text += &format!("; about {k} such releases would tell them apart");
    } else {
        text += "; they predict the same times: no number of such releases tells them apart";
    }
    Some(WallVerdict {
        preferred: None,
        ranked,
        runs_with_azimuth,
        text,
    })
}

/// Releases for the two walls to sit [`D_DECISIVE`] standard deviations apart, if they differ
/// at all: `D = sqrt(n) apart / noise`.
fn releases_needed(apart_pct: f64, noise_pct: f64) -> Option<u64> {
    (apart_pct > 1e-9 && noise_pct.is_finite()).then(|| {
        let k = (D_DECISIVE * noise_pct / apart_pct).powi(2).ceil();
        k.clamp(3.0, 1e12) as u64
    })
}

/// RMS relative difference, %, between the two walls' times at each of the twelve azimuths over
/// the runs, each at its fitted `mu_s`.
fn azimuth_apart_pct(runs: &[Run], a: &ModelFit, b: &ModelFit) -> f64 {
    let (Equation::Bowl(wa), Equation::Bowl(wb)) = (a.candidate.equation, b.candidate.equation)
    else {
        return f64::NAN;
    };
    let k2 = |m: &ModelFit, r: &Run| match m.k2 {
        K2::Fitted(k, _) => k,
        _ => r.k2,
    };
    let one = |r: &Run| {
        let (mut sum, mut count) = (0.0, 0.0);
        for deg in model_core::particle::rolling::AZIMUTHS_DEG {
            let beta = deg.to_radians();
            let ta = bowl_release(r, wa, a.mu, k2(a, r), beta);
            let tb = bowl_release(r, wb, b.mu, k2(b, r), beta);
            if ta.is_finite() && tb.is_finite() {
                sum += ((tb - ta) / ta).powi(2);
                count += 1.0;
            }
        }
        (sum, count)
    };
    let parts = crate::parallel::parallel(runs, one);
    let (sum, count) = parts
        .iter()
        .fold((0.0, 0.0), |acc, p| (acc.0 + p.0, acc.1 + p.1));
    if count > 0.0 {
        100.0 * (sum / count).sqrt()
    } else {
        f64::NAN
    }
}

/// The verdict's JSON: `preferred` (a wall or `undecided`), `verdict`, `runs_with_azimuth` and
/// `ranked` (name, aic, delta_aic, mu_s, mu_s_ci95, cannot_reproduce when it cannot).
pub fn to_json(v: &WallVerdict) -> serde_json::Value {
    let ranked: Vec<serde_json::Value> = v
        .ranked
        .iter()
        .map(|w| {
            let mut o = json!({
                "name": w.name,
                "aic": w.aic,
                "delta_aic": w.delta_aic,
                "mu_s": w.mu_s,
                "mu_s_ci95": [w.mu_s_ci95.0, w.mu_s_ci95.1],
            });
            if let Some(why) = &w.cannot_reproduce {
                o["cannot_reproduce"] = json!(why);
            }
            o
        })
        .collect();
    json!({
        "preferred": v.preferred.unwrap_or("undecided"),
        "verdict": v.text,
        "runs_with_azimuth": v.runs_with_azimuth,
        "ranked": ranked,
    })
}

#[cfg(test)]
mod tests {
    use super::super::models::{BOWL_CANDIDATES, BowlRun, Candidate, Method};
    use super::*;

    fn run(w: f64, azimuth_deg: Option<f64>) -> Run {
        Run {
            row: 2,
            condition: 1,
            residence_s: 0.17,
            mean_rad_s: w,
            release_radius_m: 0.0375,
            rim_radius_m: 0.075,
            k2: 5.0 / 7.0,
            trace: vec![(0.0, w)],
            method: Method::ClosedForm,
            axes_angle_rad: 60f64.to_radians(),
            bowl: BowlRun {
                azimuth_rad: azimuth_deg.map(f64::to_radians),
                ..BowlRun::default()
            },
        }
    }

    fn fitted(candidate: Candidate, mu: f64, aic: f64, errors_pct: Vec<f64>) -> ModelFit {
        let rms = (errors_pct.iter().map(|e| e * e).sum::<f64>() / errors_pct.len() as f64).sqrt();
        ModelFit {
            candidate,
            mu,
            mu_ci95: (mu, mu),
            rms_error_pct: rms,
            aic,
            errors_pct,
            k2: K2::Given,
            at_limit: false,
            cannot_reproduce: None,
        }
    }

    /// Two walls 3 AIC apart on runs without an azimuth: undecided, with the walls' RMS
    /// difference and the scatter computed from the runs' errors (1.00 % and 2.00 %), the
    /// releases that would put them 6 standard deviations apart (36 (2/1)^2 = 144), and the
    /// advice to record the azimuth with the walls' difference at a known azimuth, which at
    /// these walls (10 mm at mu_s 0.4 and 20 mm at 0) is larger than their means' difference.
    #[test]
    fn close_walls_without_azimuths_are_undecided_and_say_what_to_measure() {
        let runs = vec![run(1.5, None), run(3.0, None), run(4.5, None)];
        let ten = fitted(BOWL_CANDIDATES[1], 0.4, -100.0, vec![2.0, -2.0, 2.0]);
        let twenty = fitted(BOWL_CANDIDATES[2], 0.0, -97.0, vec![3.0, -1.0, 1.0]);
        let v = verdict(&runs, &[ten, twenty]).unwrap();
        assert_eq!(v.preferred, None);
        assert_eq!(v.runs_with_azimuth, 0);
        assert_eq!(v.ranked.len(), 2);
        assert_eq!(v.ranked[1].delta_aic, 3.0);
        let t = &v.text;
        assert!(
            t.starts_with(
                "cannot tell the bowl-wall-60deg-10mm from the bowl-wall-60deg-20mm with these 3 \
                 runs (AIC 3.0 apart"
            ) && t.contains("differ by 1.00 %")
                && t.contains("scatter by 2.00 %")
                && t.contains("record each release's azimuth")
                && t.contains("or measure about 144 releases without it"),
            "{t}"
        );
        let at = t.split("these walls differ by ").nth(1).unwrap();
        let pct: f64 = at.split(' ').next().unwrap().parse().unwrap();
        assert!(pct > 2.4 && pct < 20.0, "{t}");
    }

    /// A wall more than 10 AIC below the next is named with its margin; the vertical wall
    /// that holds a release (infinite AIC) is named as unable; with no wall able to reproduce
    /// the runs, the verdict says so.
    #[test]
    fn a_clear_wall_is_named_and_no_wall_is_said() {
        let runs = vec![
            run(1.5, Some(10.0)),
            run(3.0, Some(200.0)),
            run(4.5, Some(90.0)),
        ];
        let ten = fitted(BOWL_CANDIDATES[1], 0.4, -100.0, vec![0.1, -0.1, 0.1]);
        let twenty = fitted(BOWL_CANDIDATES[2], 0.0, -60.0, vec![3.0, -1.0, 1.0]);
        let vertical = fitted(
            BOWL_CANDIDATES[3],
            0.0,
            f64::INFINITY,
            vec![f64::INFINITY; 3],
        );
        let v = verdict(&runs, &[twenty.clone(), ten, vertical.clone()]).unwrap();
        assert_eq!(v.preferred, Some("bowl-wall-60deg-10mm"));
        assert_eq!(v.runs_with_azimuth, 3);
        assert!(
            v.text.starts_with(
                "the bowl-wall-60deg-10mm: AIC 40.0 lower than the bowl-wall-60deg-20mm"
            ) && v.text.contains("bowl-wall-vertical-20mm cannot"),
            "{}",
            v.text
        );
        let mut unable = twenty;
        unable.cannot_reproduce = Some("its RMS error is too large".into());
        let v = verdict(&runs, &[unable, vertical]).unwrap();
        assert_eq!(v.preferred, None);
        assert!(
            v.text.starts_with("no wall reproduces these runs"),
            "{}",
            v.text
        );
        assert!(verdict(&runs, &[]).is_none());
    }
}
