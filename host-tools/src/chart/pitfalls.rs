//! The numerical pitfalls of MODEL-NOTES, shown failing in the naive form and avoided (or
//! reported) by the model, each against the independent 256-bit reference.
//!
//! (The integrators' step limits are shown by `bowl chart stability` and its test.)

#[cfg(test)]
mod tests {
    use crate::chart::reference::{RefModel, RefOutcome, RefScene, outcome};
    use model_core::particle::{Model, Outcome, Scene, residence};

    fn paper(ri: f64) -> Scene<f64> {
        Scene {
            omega_rad_s: 3.6,
            mu: 0.029,
            g_m_s2: 9.81,
            k2: 5.0 / 7.0,
            ri_m: ri,
            rim_radius_m: 0.075,
        }
    }

    fn reference(s: &Scene<f64>, model: Model) -> RefOutcome {
        outcome(
            &RefScene {
                omega_rad_s: s.omega_rad_s,
                mu: s.mu,
                g_m_s2: s.g_m_s2,
                k2: s.k2,
                start_radius_m: s.ri_m,
                rim_radius_m: s.rim_radius_m,
            },
            match model {
                Model::Flat => RefModel::Flat,
                Model::Coriolis => RefModel::Coriolis,
            },
        )
    }

    fn ref_time(s: &Scene<f64>, model: Model) -> f64 {
        match reference(s, model) {
            RefOutcome::Leaves { time_s, .. } => time_s,
            o => panic!("reference says {o:?}"),
        }
    }

    fn a_of(s: &Scene<f64>) -> f64 {
        s.mu * s.g_m_s2 / (s.omega_rad_s * s.omega_rad_s)
    }

    /// Near the rim the naive `acosh(1 + x)` loses the digits of x when forming 1 + x; the
    /// model's log1p form keeps them.
    #[test]
    fn naive_acosh_fails_near_the_rim_and_the_model_does_not() {
        for e in [1e-8, 1e-11, 1e-14] {
            let s = paper(0.075 * (1.0 - e));
            let want = ref_time(&s, Model::Flat);
            let a = a_of(&s);
            let x = (s.rim_radius_m - s.ri_m) / (s.ri_m - a);
            let naive = (1.0 + x).acosh() / (s.k2.sqrt() * s.omega_rad_s);
            let naive_err = ((naive - want) / want).abs();
            let Outcome::Leaves {
                residence_time_s,
                condition_number,
                ..
            } = residence(&s, Model::Flat).unwrap()
            else {
                panic!("should leave")
            };
            let ours = ((residence_time_s - want) / want).abs();
            // The naive form's error grows like eps / x: about 1e-8 at x ~ 1e-8, 1e-2 at 1e-14.
            let naive_floor = 1e-3 * f64::EPSILON / x;
            assert!(
                naive_err > naive_floor,
                "e {e}: naive error {naive_err:e} unexpectedly small"
            );
            assert!(ours <= 1e-12 * condition_number, "e {e}: ours {ours:e}");
        }
    }

    /// The Coriolis residence equation G(T) = A (e^{l1 T} - 1) + B (e^{l2 T} - 1) - x has zero
    /// slope at T = 0: Newton started there divides by zero. The model brackets the root and
    /// starts from the upper end.
    #[test]
    fn newton_from_zero_breaks_and_the_model_brackets() {
        let s = paper(0.05);
        let k = s.k2.sqrt();
        let sq = (1.0 + s.k2 * s.mu * s.mu).sqrt();
        let (l1, l2) = (
            k * s.omega_rad_s / (sq + k * s.mu),
            -k * s.omega_rad_s * (sq + k * s.mu),
        );
        let (ca, cb) = ((1.0 + k * s.mu / sq) / 2.0, (1.0 - k * s.mu / sq) / 2.0);
        let a = a_of(&s);
        let x = (s.rim_radius_m - s.ri_m) / (s.ri_m - a);
        let g = |t: f64| ca * (l1 * t).exp_m1() + cb * (l2 * t).exp_m1() - x;
        let dg = |t: f64| ca * l1 * (l1 * t).exp() + cb * l2 * (l2 * t).exp();
        // The slope at 0 is A l1 + B l2 = 0 up to rounding: the first step goes to +-inf or
        // to a huge T.
        let t1 = 0.0 - g(0.0) / dg(0.0);
        let want = ref_time(&s, Model::Coriolis);
        assert!(
            !t1.is_finite() || t1.abs() > 1e6 * want,
            "Newton from 0 should blow up, got {t1}"
        );
        let got = residence(&s, Model::Coriolis).unwrap().residence_time_s();
        assert!(((got - want) / want).abs() < 1e-13, "{got} vs {want}");
    }

    /// Just above the threshold ri = a (1 + d), f32 cannot resolve d below about 1e-7. The
    /// model must then say so (near-threshold flag, or the ill-conditioned flag) rather than
    /// give a confidently wrong number.
    #[test]
    fn f32_just_above_the_threshold_is_reported() {
        let base = paper(0.05);
        let a = a_of(&base);
        let (mut never, mut left) = (0, 0);
        for d in [1e-9, 1e-8, 3e-8, 1e-7, 3e-7, 1e-6, 1e-5, 1e-4] {
            let s = Scene {
                ri_m: a * (1.0 + d),
                ..base
            };
            let s32 = Scene {
                omega_rad_s: s.omega_rad_s as f32,
                mu: s.mu as f32,
                g_m_s2: s.g_m_s2 as f32,
                k2: s.k2 as f32,
                ri_m: s.ri_m as f32,
                rim_radius_m: s.rim_radius_m as f32,
            };
            let o = residence(&s32, Model::Flat).unwrap();
            match o {
                Outcome::NeverLeaves { near_threshold, .. } => {
                    // The exact f64 scene leaves; f32 can only say "never" with the flag.
                    assert!(
                        near_threshold,
                        "d {d}: never-leaves without the near-threshold flag"
                    );
                    never += 1;
                }
                Outcome::Leaves {
                    residence_time_s,
                    condition_number,
                    ill_conditioned,
                    ..
                } => {
                    // Against the exact (f64) scene: the f32 answer must be within the issue's
                    // 2e-6 x condition number, or flagged.
                    let want = ref_time(&s, Model::Flat);
                    let err = ((f64::from(residence_time_s) - want) / want).abs();
                    assert!(
                        ill_conditioned || err <= 2e-6 * f64::from(condition_number),
                        "d {d}: error {err:e}, cond {condition_number}, not flagged"
                    );
                    left += 1;
                }
                Outcome::AlreadyAtRim { .. } => panic!("d {d}: at rim?"),
            }
        }
        // Both sides of f32's resolution are exercised.
        assert!(never >= 1 && left >= 3, "never {never}, left {left}");
    }
}
