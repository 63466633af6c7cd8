//! An independent high-precision reference for the residence time T and the radial exit speed.
//!
//! Why our own: the chart measures the model's closed forms and integrators, so the yardstick must
//! not share their code or their tricks. Here everything is computed with 256-bit binary floats
//! (astro-float, pure Rust), from the plain textbook forms:
//! - flat model (paper Eq. 6, 7): `T = acosh(1 + x) / (k omega)`, `r'(T) = (ri - a) k omega sinh(k omega T)`;
//! - Coriolis model (paper Eq. 10, 11 with the corrected A and B of docs/model.md section 3):
//!   the root of `A (e^{l1 T} - 1) + B (e^{l2 T} - 1) = x` found by plain bisection (no Newton,
//!   no clever bracket: 300 halvings of `[0, ln(1 + (x + B)/A)/l1]`), and
//!   `r'(T) = (ri - a) (k omega / (2 s)) (e^{l1 T} - e^{l2 T})`.
//!
//! With 77 decimal digits, the cancellations that the model must avoid (acosh near 1, e^z - 1 for
//! small z) cost at most a few dozen digits here and leave far more than f64 needs. The result is
//! rounded once to f64.

use astro_float::{BigFloat, Consts, RoundingMode};

/// Working precision in bits.
const P: usize = 256;
const RM: RoundingMode = RoundingMode::ToEven;

/// A scene in f64 (the exact inputs a method sees; f32 methods are referenced at their rounded inputs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefScene {
    /// Combined bowl speed omega (rad/s).
    pub omega_rad_s: f64,
    /// Effective rolling resistance coefficient mu (dimensionless).
    pub mu: f64,
    /// Gravity g (m/s^2).
    pub g_m_s2: f64,
    /// Rolling factor k2 = m rp^2 / (I + m rp^2) (5/7 for a solid sphere).
    pub k2: f64,
    /// Start radius ri (m).
    pub start_radius_m: f64,
    /// Rim radius R (m).
    pub rim_radius_m: f64,
}

/// The same scene as the model's.
impl From<&model_core::particle::Scene<f64>> for RefScene {
    fn from(s: &model_core::particle::Scene<f64>) -> Self {
        Self {
            omega_rad_s: s.omega_rad_s,
            mu: s.mu,
            g_m_s2: s.g_m_s2,
            k2: s.k2,
            start_radius_m: s.ri_m,
            rim_radius_m: s.rim_radius_m,
        }
    }
}

/// Which equation of motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RefModel {
    /// Paper Eq. 5: no Coriolis term.
    Flat,
    /// Paper Eq. 9: with the Coriolis friction term.
    Coriolis,
}

/// The same equation as the model's.
impl From<model_core::particle::Model> for RefModel {
    fn from(m: model_core::particle::Model) -> Self {
        match m {
            model_core::particle::Model::Flat => Self::Flat,
            model_core::particle::Model::Coriolis => Self::Coriolis,
        }
    }
}

/// What the reference says happens.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RefOutcome {
    /// Leaves the rim at `time_s` with radial speed `radial_velocity_m_s`.
    Leaves {
        /// Residence time T (s).
        time_s: f64,
        /// r'(T) (m/s).
        radial_velocity_m_s: f64,
    },
    /// Starts at or beyond the rim: T = 0.
    AtRim,
    /// ri <= a: friction holds the particle.
    NeverLeaves,
}

struct Ctx {
    cc: Consts,
}

impl Ctx {
    fn new() -> Self {
        // Consts::new only fails on allocation failure.
        Ctx {
            cc: Consts::new().expect("astro-float constants cache"),
        }
    }
    fn inputs(&self, s: &RefScene) -> [BigFloat; 6] {
        [
            s.omega_rad_s,
            s.mu,
            s.g_m_s2,
            s.k2,
            s.start_radius_m,
            s.rim_radius_m,
        ]
        .map(|v| self.f(v))
    }
    fn f(&self, v: f64) -> BigFloat {
        BigFloat::from_f64(v, P)
    }
    fn exp(&mut self, v: &BigFloat) -> BigFloat {
        v.exp(P, RM, &mut self.cc)
    }
    fn round_to_f64(&mut self, v: &BigFloat) -> f64 {
        // Decimal with far more digits than f64 holds, then one correctly rounded parse.
        v.format(astro_float::Radix::Dec, RM, &mut self.cc)
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    }
}

/// The reference outcome of `scene` under `model`.
pub fn outcome(scene: &RefScene, model: RefModel) -> RefOutcome {
    if scene.start_radius_m >= scene.rim_radius_m {
        return RefOutcome::AtRim;
    }
    let mut c = Ctx::new();
    let inputs = c.inputs(scene);
    match solve(&mut c, &inputs, model) {
        None => RefOutcome::NeverLeaves,
        Some((t, v)) => RefOutcome::Leaves {
            time_s: c.round_to_f64(&t),
            radial_velocity_m_s: c.round_to_f64(&v),
        },
    }
}

/// The relative condition number of `T`, computed here and not by the model: the sum over the
/// six inputs of `|d ln T / d ln p|`, each by a relative perturbation of 2^-120 (far below f64
/// rounding, far above this precision's). A relative error `e` in every input moves `T` by at
/// most `cond e`. `None` when the particle does not leave.
#[cfg(test)]
pub fn condition(scene: &RefScene, model: RefModel) -> Option<f64> {
    if scene.start_radius_m >= scene.rim_radius_m {
        return None;
    }
    let mut c = Ctx::new();
    let inputs = c.inputs(scene);
    let (t, _) = solve(&mut c, &inputs, model)?;
    let h = BigFloat::from_f64(2f64.powi(-120), P);
    let one = c.f(1.0);
    let mut cond = 0.0;
    for i in 0..inputs.len() {
        let mut moved = inputs.clone();
        moved[i] = moved[i].mul(&one.add(&h, P, RM), P, RM);
        let (tp, _) = solve(&mut c, &moved, model)?;
        let rel = tp.sub(&t, P, RM).div(&t, P, RM).div(&h, P, RM);
        cond += c.round_to_f64(&rel).abs();
    }
    Some(cond)
}

/// `T` and `r'(T)` from the inputs `[omega, mu, g, k2, ri, R]`; `None` when `ri <= a`.
fn solve(c: &mut Ctx, inputs: &[BigFloat; 6], model: RefModel) -> Option<(BigFloat, BigFloat)> {
    let [w, mu, g, k2, ri, rr] = inputs;
    let a = mu.mul(g, P, RM).div(&w.mul(w, P, RM), P, RM);
    let d = ri.sub(&a, P, RM);
    if !d.is_positive() || d.is_zero() {
        return None;
    }
    let x = rr.sub(ri, P, RM).div(&d, P, RM);
    let k = k2.sqrt(P, RM);
    let kw = k.mul(w, P, RM);
    let one = c.f(1.0);
    let (t, v) = match model {
        RefModel::Flat => {
            let t = one.add(&x, P, RM).acosh(P, RM, &mut c.cc).div(&kw, P, RM);
            let z = kw.mul(&t, P, RM);
            let sinh = z.sinh(P, RM, &mut c.cc);
            (t, d.mul(&kw, P, RM).mul(&sinh, P, RM))
        }
        RefModel::Coriolis => {
            let kmu = k.mul(mu, P, RM);
            let s = one
                .add(&k2.mul(mu, P, RM).mul(mu, P, RM), P, RM)
                .sqrt(P, RM);
            let spk = s.add(&kmu, P, RM);
            let l1 = kw.div(&spk, P, RM);
            let l2 = kw.mul(&spk, P, RM).neg();
            let half = c.f(0.5);
            let r = kmu.div(&s, P, RM);
            let aa = half.mul(&one.add(&r, P, RM), P, RM);
            let bb = half.mul(&one.sub(&r, P, RM), P, RM);
            // f(T) = A (e^{l1 T} - 1) + B (e^{l2 T} - 1) - x is increasing on T > 0, f(0) = -x < 0,
            // and f(hi) >= A (e^{l1 hi} - 1) - B - x = 0.
            let mut lo = c.f(0.0);
            let mut hi = one
                .add(&x.add(&bb, P, RM).div(&aa, P, RM), P, RM)
                .ln(P, RM, &mut c.cc)
                .div(&l1, P, RM);
            for _ in 0..300 {
                let mid = half.mul(&lo.add(&hi, P, RM), P, RM);
                let e1 = c.exp(&l1.mul(&mid, P, RM)).sub(&one, P, RM);
                let e2 = c.exp(&l2.mul(&mid, P, RM)).sub(&one, P, RM);
                let f = aa
                    .mul(&e1, P, RM)
                    .add(&bb.mul(&e2, P, RM), P, RM)
                    .sub(&x, P, RM);
                if f.is_negative() {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let t = half.mul(&lo.add(&hi, P, RM), P, RM);
            let e1 = c.exp(&l1.mul(&t, P, RM));
            let e2 = c.exp(&l2.mul(&t, P, RM));
            let v = d.mul(&kw, P, RM).div(&c.f(2.0).mul(&s, P, RM), P, RM).mul(
                &e1.sub(&e2, P, RM),
                P,
                RM,
            );
            (t, v)
        }
    };
    Some((t, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(mu: f64, ri: f64) -> RefScene {
        RefScene {
            omega_rad_s: 3.6,
            mu,
            g_m_s2: 9.81,
            k2: 5.0 / 7.0,
            start_radius_m: ri,
            rim_radius_m: 0.075,
        }
    }

    /// A plain f64 RK4 with a tiny step and cubic Hermite event location: an independent check of
    /// the reference (agreement far below the chart's error range, not bit equality).
    fn rk4_time(s: &RefScene, coriolis: bool) -> (f64, f64) {
        let rhs = |r: f64, v: f64| {
            let c = if coriolis {
                2.0 * s.mu * s.omega_rad_s * v
            } else {
                0.0
            };
            s.k2 * (r * s.omega_rad_s * s.omega_rad_s - s.mu * s.g_m_s2 - c)
        };
        let h = 2e-4 / s.omega_rad_s;
        let (mut t, mut r, mut v) = (0.0, s.start_radius_m, 0.0);
        loop {
            let (k1r, k1v) = (v, rhs(r, v));
            let (k2r, k2v) = (v + 0.5 * h * k1v, rhs(r + 0.5 * h * k1r, v + 0.5 * h * k1v));
            let (k3r, k3v) = (v + 0.5 * h * k2v, rhs(r + 0.5 * h * k2r, v + 0.5 * h * k2v));
            let (k4r, k4v) = (v + h * k3v, rhs(r + h * k3r, v + h * k3v));
            let rn = r + h / 6.0 * (k1r + 2.0 * k2r + 2.0 * k3r + k4r);
            let vn = v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            if rn >= s.rim_radius_m {
                // Hermite cubic in theta on [t, t + h], bisection for r = R.
                let (f0, f1, d0, d1) = (r, rn, h * v, h * vn);
                let p = |th: f64| {
                    let h00 = (1.0 + 2.0 * th) * (1.0 - th) * (1.0 - th);
                    let h10 = th * (1.0 - th) * (1.0 - th);
                    let h01 = th * th * (3.0 - 2.0 * th);
                    let h11 = th * th * (th - 1.0);
                    h00 * f0 + h10 * d0 + h01 * f1 + h11 * d1
                };
                let (mut lo, mut hi) = (0.0, 1.0);
                for _ in 0..60 {
                    let m = 0.5 * (lo + hi);
                    if p(m) < s.rim_radius_m {
                        lo = m
                    } else {
                        hi = m
                    }
                }
                let th = 0.5 * (lo + hi);
                return (t + th * h, v + th * (vn - v));
            }
            t += h;
            r = rn;
            v = vn;
        }
    }

    #[test]
    fn agrees_with_a_fine_independent_integration() {
        for &mu in &[0.0, 0.029, 0.2] {
            for &model in &[RefModel::Flat, RefModel::Coriolis] {
                // omega 8 rad/s keeps a = mu g / omega^2 below ri for mu = 0.2.
                let s = RefScene {
                    omega_rad_s: 8.0,
                    ..scene(mu, 0.06)
                };
                let RefOutcome::Leaves {
                    time_s,
                    radial_velocity_m_s,
                } = outcome(&s, model)
                else {
                    panic!("mu {mu} should leave");
                };
                let (t, v) = rk4_time(&s, model == RefModel::Coriolis);
                assert!(
                    ((t - time_s) / time_s).abs() < 1e-10,
                    "{mu} {model:?} T {t} vs {time_s}"
                );
                // The velocity from the integration is linearly interpolated: a looser check.
                assert!(
                    ((v - radial_velocity_m_s) / v).abs() < 1e-5,
                    "{mu} {model:?} v"
                );
            }
        }
    }

    #[test]
    fn exact_check_values_of_the_notes() {
        // mu = 0.2, k2 = 5/7: l1 = 5 omega / 7, l2 = -omega, A = 7/12, B = 5/12 exactly, so with
        // omega = 1 the root of 7/12 (e^{5T/7} - 1) + 5/12 (e^{-T} - 1) = x can be checked directly.
        let s = RefScene {
            omega_rad_s: 1.0,
            mu: 0.2,
            g_m_s2: 1.0,
            k2: 5.0 / 7.0,
            start_radius_m: 0.3,
            rim_radius_m: 1.0,
        };
        let RefOutcome::Leaves { time_s: t, .. } = outcome(&s, RefModel::Coriolis) else {
            panic!()
        };
        let x = (1.0 - 0.3) / (0.3 - 0.2);
        let lhs = 7.0 / 12.0 * ((5.0 * t / 7.0).exp() - 1.0) + 5.0 / 12.0 * ((-t).exp() - 1.0);
        assert!((lhs - x).abs() < 1e-13 * x, "{lhs} vs {x}");
    }

    #[test]
    fn coriolis_equals_flat_without_friction() {
        let s = scene(0.0, 0.02);
        assert_eq!(outcome(&s, RefModel::Flat), outcome(&s, RefModel::Coriolis));
    }

    #[test]
    fn outcomes_at_the_edges() {
        assert_eq!(
            outcome(&scene(0.029, 0.075), RefModel::Flat),
            RefOutcome::AtRim
        );
        // a = 0.029 * 9.81 / 3.6^2 = 0.02195 m
        assert_eq!(
            outcome(&scene(0.029, 0.02), RefModel::Coriolis),
            RefOutcome::NeverLeaves
        );
        assert!(matches!(
            outcome(&scene(0.029, 0.0220), RefModel::Coriolis),
            RefOutcome::Leaves { .. }
        ));
    }
}
