//! Releases the integrator gave up on, said once for the run: what happened, at which
//! azimuths, and only advice that works at the current settings (the advice said "a tighter
//! --tol (1e-7 or below)" with the default 1e-9 already in force, and "try --method dp54" to
//! the bowl model, which runs dp54; the chooser repeated one sentence per release).

use model_core::ode::system::SystemError;
use model_core::particle::bowl::BowlError;
use model_core::particle::rolling::{MAX_STEPS, RollingError, RollingMethod};

/// The tolerance at and below which a stall at a roll/slide switch is the scene's own, not the
/// tolerance's: the stall watch's loose-tolerance stalls go away by 1e-7; tighter ones
/// (1e-10, 1e-12) still fail the same release and 1e-14 more of them.
const STALL_TOL: f64 = 1e-7;

/// The tightest tolerance DP5(4)'s error estimate can honour in f64: below it the estimate is
/// rounding noise and the steps shrink until the stall watch ends the run, on releases that
/// roll throughout (a 5 deg scene whose release at 150 deg leaves at 1e-12 and 2e-13 stalled at
/// 1e-13 and at every tighter one, and was told that no setting gets it through).
const ROUNDING_TOL: f64 = 1e-12;

/// How the run was set: what the user can still change.
pub enum Settings {
    /// `--model bowl`: its method and `--max-time-s`.
    Bowl {
        method: RollingMethod<f64>,
        max_time_s: f64,
    },
    /// `--model auto`: the chooser sets the tolerance and tightens it for such releases itself;
    /// `--max-time-s` as the bowl model's.
    Chooser { max_time_s: f64 },
}

/// What happened to one release, without advice.
pub fn what(e: &BowlError) -> String {
    match e {
        BowlError::Scene(RollingError::Integration(SystemError::Stalled)) => {
            "the steps stopped advancing the time at a roll/slide switch (a granule chattering \
             at the stick threshold)"
                .into()
        }
        BowlError::Scene(RollingError::Integration(SystemError::StepLimit)) => {
            format!("the step cap ({MAX_STEPS} steps) was reached")
        }
        BowlError::Scene(RollingError::Integration(SystemError::NotFinite)) => {
            "a state became infinite".into()
        }
        other => super::bowl::words(*other),
    }
}

/// The one sentence for the releases in `failed` (azimuth in degrees and why) of `releases`.
pub fn sentence(failed: &[(f64, BowlError)], releases: usize, settings: &Settings) -> String {
    // Below rounding the stall is the tolerance's, wherever the granule is: no switch to name.
    let rounding = matches!(settings, Settings::Bowl { method: RollingMethod::Dp54 { rtol }, .. }
        if *rtol < ROUNDING_TOL);
    let mut kinds: Vec<String> = Vec::new();
    for (_, e) in failed {
        let w = match e {
            BowlError::Scene(RollingError::Integration(SystemError::Stalled)) if rounding => {
                "the steps stopped advancing the time".into()
            }
            e => what(e),
        };
        if !kinds.contains(&w) {
            kinds.push(w);
        }
    }
    let at: Vec<String> = failed.iter().map(|(d, _)| format!("{d}")).collect();
    // With every release given up there are no others to give times over.
    let rest = if failed.len() < releases {
        "so they have no residence time and the times given are over the others"
    } else {
        "so no release has a residence time"
    };
    format!(
        "the integration gave up on {} of {} (at {} deg: {}), {rest}; {}",
        failed.len(),
        crate::number::count(releases, "release", "releases"),
        at.join(", "),
        kinds.join("; "),
        advice(failed, settings)
    )
}

fn advice(failed: &[(f64, BowlError)], settings: &Settings) -> String {
    let is = |k: SystemError| {
        failed
            .iter()
            .all(|(_, e)| *e == BowlError::Scene(RollingError::Integration(k)))
    };
    let nothing = "no setting gets those releases through";
    match settings {
        // The step cap is met by long runs under the chooser too: said "no setting gets
        // through" with `--max-time-s 3000` on a granule held in the corner, where 3 s answers.
        Settings::Chooser { max_time_s } if is(SystemError::StepLimit) => {
            format!("a shorter --max-time-s (now {max_time_s} s) may get through")
        }
        Settings::Chooser { .. } => {
            format!("the chooser already tightens its tolerance for such releases, so {nothing}")
        }
        Settings::Bowl {
            method: RollingMethod::Dp54 { rtol },
            max_time_s,
        } => {
            if is(SystemError::Stalled) {
                if *rtol < ROUNDING_TOL {
                    format!(
                        "--tol {rtol:e} asks for less than f64's rounding can tell (the step's \
                         error estimate is rounding noise there, and the steps shrink to \
                         nothing): a looser --tol ({ROUNDING_TOL:e}) may get through"
                    )
                } else if *rtol > STALL_TOL {
                    format!(
                        "a tighter --tol ({STALL_TOL:e} or below; now {rtol:e}) may get through"
                    )
                } else {
                    format!(
                        "--tol is {rtol:e} already, and a tighter one stalls the same way (at \
                         {STALL_TOL:e} and below the stall is the scene's): {nothing}"
                    )
                }
            } else if is(SystemError::NotFinite) {
                format!("the adaptive dp54 already controls its step: {nothing}")
            } else {
                // The step cap is met by long runs: a shorter horizon shortens them.
                format!("a shorter --max-time-s (now {max_time_s} s) may get through")
            }
        }
        // The cap counts steps: a smaller step meets it sooner (the advice said "a smaller
        // --step-s" to a run at 1e-5 s over 60 s, 6 000 000 steps a release).
        Settings::Bowl {
            method: RollingMethod::Rk4 { step_s },
            max_time_s,
        } if is(SystemError::StepLimit) => format!(
            "{MAX_STEPS} steps of --step-s {} s follow a release for {} s: a larger --step-s \
             (at least {} s for --max-time-s {max_time_s} s), a shorter --max-time-s, or \
             --method dp54 (the default) may get through",
            crate::number::echo(*step_s),
            crate::number::echo(*step_s * f64::from(MAX_STEPS)),
            crate::number::echo(*max_time_s / f64::from(MAX_STEPS))
        ),
        Settings::Bowl {
            method: RollingMethod::Rk4 { step_s },
            ..
        } => format!(
            "a smaller --step-s (now {step_s} s) or --method dp54 (the default) may get through"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const STALL: BowlError = BowlError::Scene(RollingError::Integration(SystemError::Stalled));

    /// At the default tolerance a stall gets no "tighter --tol" advice; looser, it does; the
    /// azimuths are listed once, the sentence said once.
    #[test]
    fn the_advice_holds_at_the_settings_given() {
        let bowl = |rtol| Settings::Bowl {
            method: RollingMethod::Dp54 { rtol },
            max_time_s: 3.0,
        };
        let s = sentence(&[(150.0, STALL), (180.0, STALL)], 12, &bowl(1e-9));
        assert!(s.contains("2 of 12 releases (at 150, 180 deg"), "{s}");
        assert!(s.contains("no setting gets those releases through"), "{s}");
        assert!(!s.contains("may get through"), "{s}");
        assert_eq!(s.matches("roll/slide switch").count(), 1, "{s}");
        let s = sentence(&[(150.0, STALL)], 12, &bowl(1e-5));
        assert!(
            s.contains("a tighter --tol (1e-7 or below; now 1e-5)"),
            "{s}"
        );
        assert!(!s.contains("--method dp54"), "{s}");
    }

    /// A stall at a tolerance tighter than rounding is the tolerance's: the advice is a looser
    /// one (it said "--tol is 1e-13 already, ... no setting gets those releases through", where
    /// 1e-12 gets the release through).
    #[test]
    fn a_stall_at_a_tolerance_below_rounding_advises_a_looser_one() {
        let bowl = |rtol| Settings::Bowl {
            method: RollingMethod::Dp54 { rtol },
            max_time_s: 5.0,
        };
        for rtol in [1e-13, 1e-17] {
            let s = sentence(&[(150.0, STALL)], 12, &bowl(rtol));
            assert!(s.contains("a looser --tol (1e-12) may get through"), "{s}");
            assert!(s.contains(&format!("--tol {rtol:e} asks for less")), "{s}");
            assert!(!s.contains("no setting"), "{s}");
            assert!(!s.contains("roll/slide switch"), "{s}");
        }
        let s = sentence(&[(150.0, STALL)], 12, &bowl(1e-12));
        assert!(s.contains("no setting gets those releases through"), "{s}");
    }

    /// Every release given up: no "times given over the others" (there are none), and one
    /// release is not "1 of 1 releases".
    #[test]
    fn every_release_given_up_says_none_has_a_time() {
        let s = sentence(&[(0.0, STALL)], 1, &Settings::Chooser { max_time_s: 3.0 });
        assert!(
            s.contains("gave up on 1 of 1 release (at 0 deg: the steps stopped advancing"),
            "{s}"
        );
        assert!(s.contains("so no release has a residence time;"), "{s}");
        assert!(!s.contains("over the others"), "{s}");
        let s = sentence(&[(0.0, STALL)], 12, &Settings::Chooser { max_time_s: 3.0 });
        assert!(s.contains("1 of 12 releases (at 0 deg"), "{s}");
        assert!(s.contains("over the others"), "{s}");
    }

    /// RK4 at the step cap is told a larger step or a shorter horizon, never a smaller step
    /// (which meets the cap sooner).
    #[test]
    fn rk4_at_the_step_cap_is_told_a_larger_step() {
        let cap = BowlError::Scene(RollingError::Integration(SystemError::StepLimit));
        let rk4 = Settings::Bowl {
            method: RollingMethod::Rk4 { step_s: 1e-5 },
            max_time_s: 60.0,
        };
        let s = sentence(&[(0.0, cap)], 12, &rk4);
        assert!(
            s.contains(
                "2000000 steps of --step-s 1e-5 s follow a release for 20 s: a larger \
                 --step-s (at least 3e-5 s for --max-time-s 60 s), a shorter --max-time-s"
            ),
            "{s}"
        );
        assert!(!s.contains("a smaller --step-s"), "{s}");
        let s = sentence(&[(0.0, STALL)], 12, &rk4);
        assert!(s.contains("a smaller --step-s"), "{s}");
    }

    /// Under the chooser a stall gets "no setting", the step cap the shorter horizon (it said
    /// "no setting" for both).
    #[test]
    fn the_chooser_advises_a_shorter_horizon_for_the_step_cap() {
        let cap = BowlError::Scene(RollingError::Integration(SystemError::StepLimit));
        let chooser = Settings::Chooser { max_time_s: 3000.0 };
        let s = sentence(&[(90.0, cap)], 12, &chooser);
        assert!(
            s.contains("a shorter --max-time-s (now 3000 s) may get through"),
            "{s}"
        );
        assert!(!s.contains("no setting"), "{s}");
        let s = sentence(&[(90.0, STALL)], 12, &chooser);
        assert!(s.contains("no setting gets those releases through"), "{s}");
    }
}
