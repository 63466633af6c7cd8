//! Setpoints from a target residence time, checked against an independent closed form.

use model_core::control::{
    BowlSpeedForResidence, Controller, ControllerConfig, InverseFailure, Rejection,
};

/// Flat model (paper Eq. 6/7, docs/model.md form): `T = acosh(1 + (R - ri)/(ri - a)) / (k omega)`,
/// `a = mu g / omega^2`, inverted by bisection in f64 here, independently of model-core.
struct FlatInverse {
    rim_m: f64,
    start_m: f64,
    mu: f64,
    k2: f64,
}

impl FlatInverse {
    fn time_s(&self, omega: f64) -> Option<f64> {
        let a = self.mu * 9.81 / (omega * omega);
        if self.start_m <= a {
            return None;
        }
        let x = (self.rim_m - self.start_m) / (self.start_m - a);
        Some((1.0 + x).acosh() / (self.k2.sqrt() * omega))
    }
}

impl BowlSpeedForResidence for FlatInverse {
    fn omega_rad_s(&self, target_s: f32) -> Result<f32, InverseFailure> {
        // T decreases with omega; bracket [0.1, 10] rad/s.
        let (mut lo, mut hi) = (0.1f64, 10.0f64);
        let t = target_s as f64;
        match (self.time_s(lo), self.time_s(hi)) {
            (_, Some(t_hi)) if t < t_hi => return Err(InverseFailure::Unreachable),
            (Some(t_lo), _) if t > t_lo => return Err(InverseFailure::Unreachable),
            (_, None) => return Err(InverseFailure::Unreachable),
            _ => {}
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            match self.time_s(mid) {
                Some(tm) if tm > t => lo = mid,
                Some(_) => hi = mid,
                None => lo = mid,
            }
        }
        Ok((0.5 * (lo + hi)) as f32)
    }
}

fn scene() -> FlatInverse {
    FlatInverse {
        rim_m: 0.15,
        start_m: 0.05,
        mu: 0.029,
        k2: 5.0 / 7.0,
    }
}

#[test]
fn target_time_gives_speeds_whose_combined_speed_reproduces_it() {
    let model = scene();
    for &target in &[1.0f32, 1.5, 2.5] {
        for &ratio in &[0.5f32, 1.0, 2.0] {
            let mut cfg = ControllerConfig::nominal();
            cfg.spin_per_precession = ratio;
            let mut c = Controller::new(cfg).unwrap();
            let speeds = c.set_target_residence_time(target, &model).unwrap();
            // Independent Eq. 2 in f64 (vector sum at 60 degrees).
            let (w1, w2) = (speeds[0] as f64, speeds[1] as f64);
            let a = std::f64::consts::FRAC_PI_3;
            let omega = ((w1 + w2 * a.cos()).powi(2) + (w2 * a.sin()).powi(2)).sqrt();
            let t = model.time_s(omega).unwrap();
            assert!(
                (t - target as f64).abs() < 2e-3 * target as f64,
                "target {target} ratio {ratio}: {t}"
            );
            assert!((w2 - ratio as f64 * w1).abs() < 1e-5 * (1.0 + w2));
            let s = c.status();
            assert_eq!(s.axes[0].target_rad_s, speeds[0]);
            assert!((s.combined_target_rad_s as f64 - omega).abs() < 1e-4 * omega);
        }
    }
}

#[test]
fn unreachable_or_invalid_targets_are_rejected_and_change_nothing() {
    let model = scene();
    let mut c = Controller::new(ControllerConfig::nominal()).unwrap();
    c.set_motor_speeds(1.0, 1.0).unwrap();
    let before = c;
    assert_eq!(
        c.set_target_residence_time(-1.0, &model),
        Err(Rejection::InvalidResidenceTime)
    );
    assert_eq!(
        c.set_target_residence_time(f32::NAN, &model),
        Err(Rejection::InvalidResidenceTime)
    );
    // A scene where the particle never leaves below 10 rad/s (mu = 1).
    let stuck = FlatInverse { mu: 1.0, ..scene() };
    assert_eq!(
        c.set_target_residence_time(2.0, &stuck),
        Err(Rejection::Inverse(InverseFailure::Unreachable))
    );
    // Too short: needs a combined speed above what the motors may run (4 rad/s each).
    assert!(matches!(
        c.set_target_residence_time(0.3, &model),
        Err(Rejection::AboveMaxSpeed(_))
    ));
    assert_eq!(c, before);
}
