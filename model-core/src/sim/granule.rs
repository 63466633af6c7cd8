//! A granule in the simulated rig: released at rest at a start radius, it follows the chosen
//! equation of motion (paper Eq. 5 flat, Eq. 9 Coriolis; docs/model.md) under the bowl speed as
//! it actually evolves, and an exit gate at the rim reports when it gets there.
//!
//! The closed forms of [`crate::particle`] assume a constant bowl speed; a real bowl spins up,
//! ripples and drifts, so here the equation is integrated step by step with the speed the plant
//! gives at each step (the combined speed of paper Eq. 2 from the two true shaft speeds). The
//! same integrator serves the fit of measured runs ([`Granule::residence_over_trace`]), so the
//! simulated rig and the fit share one equation of motion.
//!
//! Static friction: a granule at rest stays where it is while `r omega^2 <= mu g` (below the
//! equilibrium radius `a = mu g / omega^2`); a moving granule that the resistance brings to a
//! stop stops there (the equation would drag it inward, which is unphysical).

use super::bowl_granule::BowlTruth;
use crate::particle::Model;
use crate::sim::prng::Prng;
use crate::wire::{ParamId, ParamValues};

/// Gravity, m/s^2 (the value the particle model defaults to).
pub const G_M_S2: f64 = 9.81;

/// The `[particle]` section of a rig file: the hidden truth of a simulated rig's granules.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParticleParams {
    /// Which equation of motion the simulated granule follows.
    pub model: Model,
    /// True effective rolling resistance (dimensionless).
    pub mu: f64,
    /// Granule-to-granule spread of `mu` (standard deviation).
    pub mu_spread: f64,
    /// `k2 = m rp^2 / (I + m rp^2)`, in (0, 1]; 5/7 for a solid sphere.
    pub k2: f64,
    /// Start radius, m.
    pub release_radius_m: f64,
    /// Rim radius (where the exit gate sits), m.
    pub rim_radius_m: f64,
    /// Standard deviation of the start radius, m.
    pub release_spread_m: f64,
    /// Standard deviation of the exit gate's timing error, s.
    pub gate_jitter_s: f64,
    /// `Some`: the granule follows the bowl model in this bowl instead of `model`
    /// (`[particle] model = "bowl"`, [`super::bowl_granule`]); `mu` is then its rolling
    /// resistance and `rim_radius_m` the bowl's bottom radius.
    pub bowl: Option<BowlTruth>,
}

/// A `[particle]` value outside its range: which key, and the range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParticleParamError {
    /// The key as written in the rig file.
    pub key: &'static str,
    /// The smallest allowed value.
    pub min: f64,
    /// The largest allowed value.
    pub max: f64,
}

impl Default for ParticleParams {
    /// The project's default scene (docs/model.md): Coriolis, mu 0.029, solid sphere, start
    /// 0.05 m, rim 0.15 m, no spread, no gate jitter.
    fn default() -> Self {
        Self {
            model: Model::Coriolis,
            mu: 0.029,
            mu_spread: 0.0,
            k2: 5.0 / 7.0,
            release_radius_m: 0.05,
            rim_radius_m: 0.15,
            release_spread_m: 0.0,
            gate_jitter_s: 0.0,
            bowl: None,
        }
    }
}

impl ParticleParams {
    /// Each value with its allowed range (inclusive).
    pub fn ranges(&self) -> [(&'static str, f64, f64, f64); 7] {
        [
            ("mu", self.mu, 0.0, 1.0),
            ("mu_spread", self.mu_spread, 0.0, 0.5),
            ("k2", self.k2, 1e-3, 1.0),
            ("release_radius_m", self.release_radius_m, 0.0, 10.0),
            ("rim_radius_m", self.rim_radius_m, 1e-3, 10.0),
            ("release_spread_m", self.release_spread_m, 0.0, 1.0),
            ("gate_jitter_s", self.gate_jitter_s, 0.0, 10.0),
        ]
    }

    /// Checks every value against [`ParticleParams::ranges`] (NaN fails) and that the start lies
    /// inside the rim.
    pub fn validate(&self) -> Result<(), ParticleParamError> {
        for (key, v, min, max) in self.ranges() {
            if !(v >= min && v <= max) {
                return Err(ParticleParamError { key, min, max });
            }
        }
        if self.release_radius_m >= self.rim_radius_m {
            return Err(ParticleParamError {
                key: "release_radius_m",
                min: 0.0,
                max: self.rim_radius_m,
            });
        }
        Ok(())
    }

    /// A simulated rig's parameter table describes its own bowl, as an engineer sets a real
    /// rig's (docs/bring-up.md): the start radius, rim radius and k2 of the granules these
    /// parameters drop. Its mu stays the table's (`MU_PPM`, the model's guess): that is the
    /// truth an experiment has to find. Values outside a parameter's range are held at its
    /// limit.
    pub fn describe_bowl(&self, params: &mut ParamValues) {
        for (id, value) in [
            (ParamId::StartUm, self.release_radius_m),
            (ParamId::RimUm, self.rim_radius_m),
            (ParamId::K2Ppm, self.k2),
        ] {
            let (lo, hi) = id.range();
            let micro = libm::round(value * 1e6).clamp(f64::from(lo), f64::from(hi));
            params[id.index()] = micro as i32;
        }
    }

    /// One granule drawn from the spreads: `mu` and the start radius Gaussian, clamped to be
    /// non-negative and inside the rim. It follows `model` (a granule in the bowl model is
    /// drawn by [`BowlTruth::release`]).
    pub fn release(&self, rng: &mut Prng) -> Granule {
        let mu = (self.mu + self.mu_spread * gaussian(rng)).max(0.0);
        let r0 = (self.release_radius_m + self.release_spread_m * gaussian(rng))
            .clamp(0.0, self.rim_radius_m);
        Granule::new(self.model, mu, self.k2, r0, self.rim_radius_m)
    }

    /// A gate timing error drawn from `gate_jitter_s`, s.
    pub fn gate_error_s(&self, rng: &mut Prng) -> f64 {
        self.gate_jitter_s * gaussian(rng)
    }
}

/// A standard normal draw (Box-Muller, one of the pair).
pub fn gaussian(rng: &mut Prng) -> f64 {
    // 1 - unit() is in (0, 1]: the logarithm is finite.
    let u1 = 1.0 - f64::from(rng.unit());
    let u2 = f64::from(rng.unit());
    libm::sqrt(-2.0 * libm::log(u1)) * libm::cos(core::f64::consts::TAU * u2)
}

/// One granule in the bowl. SI units; time counts from the release.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Granule {
    model: Model,
    mu: f64,
    k2: f64,
    rim_radius_m: f64,
    radius_m: f64,
    radial_velocity_m_s: f64,
    time_s: f64,
    exit_s: Option<f64>,
}

impl Granule {
    /// At rest at `radius_m`. Non-finite or negative inputs are replaced by 0 (a granule that
    /// never moves) rather than poisoning the state; `k2` is clamped to (0, 1].
    pub fn new(model: Model, mu: f64, k2: f64, radius_m: f64, rim_radius_m: f64) -> Self {
        let clean = |x: f64| if x.is_finite() && x > 0.0 { x } else { 0.0 };
        let k2 = if k2.is_finite() {
            k2.clamp(1e-6, 1.0)
        } else {
            1.0
        };
        let radius_m = clean(radius_m);
        let rim_radius_m = clean(rim_radius_m);
        Self {
            model,
            mu: clean(mu),
            k2,
            rim_radius_m,
            radius_m,
            radial_velocity_m_s: 0.0,
            time_s: 0.0,
            exit_s: (radius_m >= rim_radius_m).then_some(0.0),
        }
    }

    /// Radius now, m.
    pub fn radius_m(&self) -> f64 {
        self.radius_m
    }

    /// Time since the release, s.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Time since the release at which the granule reached the rim, if it has.
    pub fn exit_s(&self) -> Option<f64> {
        self.exit_s
    }

    /// `r''` at radius `r`, radial velocity `v`, bowl speed `w` (paper Eq. 5 / 9).
    fn acceleration(&self, r: f64, v: f64, w: f64) -> f64 {
        let coriolis = match self.model {
            Model::Flat => 0.0,
            Model::Coriolis => 2.0 * self.mu * w * v,
        };
        self.k2 * (r * w * w - self.mu * G_M_S2 - coriolis)
    }

    /// Advances `dt_s` at bowl speed `omega_rad_s` (held over the step; classical RK4).
    /// Returns the exit time (since the release) in the step in which the granule reaches the
    /// rim, linearly interpolated within the step; `None` otherwise. After the exit the granule
    /// is gone and further steps do nothing.
    pub fn step(&mut self, omega_rad_s: f64, dt_s: f64) -> Option<f64> {
        if self.exit_s.is_some() || !(dt_s > 0.0 && dt_s.is_finite()) {
            return None;
        }
        let w = if omega_rad_s.is_finite() {
            omega_rad_s.abs()
        } else {
            0.0
        };
        let (r, v) = (self.radius_m, self.radial_velocity_m_s);
        let t0 = self.time_s;
        self.time_s += dt_s;
        if v <= 0.0 && r * w * w <= self.mu * G_M_S2 {
            // Held by static friction.
            self.radial_velocity_m_s = 0.0;
            return None;
        }
        let f = |r: f64, v: f64| (v, self.acceleration(r, v, w));
        let (k1r, k1v) = f(r, v);
        let (k2r, k2v) = f(r + 0.5 * dt_s * k1r, v + 0.5 * dt_s * k1v);
        let (k3r, k3v) = f(r + 0.5 * dt_s * k2r, v + 0.5 * dt_s * k2v);
        let (k4r, k4v) = f(r + dt_s * k3r, v + dt_s * k3v);
        let r1 = r + dt_s / 6.0 * (k1r + 2.0 * k2r + 2.0 * k3r + k4r);
        let v1 = v + dt_s / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
        if v1 <= 0.0 {
            // The resistance stopped it within the step: it rests (never inward).
            self.radius_m = r1.max(r);
            self.radial_velocity_m_s = 0.0;
        } else {
            self.radius_m = r1;
            self.radial_velocity_m_s = v1;
        }
        if self.radius_m >= self.rim_radius_m {
            let frac = if self.radius_m > r {
                ((self.rim_radius_m - r) / (self.radius_m - r)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let exit = t0 + frac * dt_s;
            self.exit_s = Some(exit);
            return Some(exit);
        }
        None
    }

    /// Residence time over a speed trace `(t_s, omega_rad_s)` (times from the release, rising),
    /// integrated in steps of at most `max_step_s` with the speed interpolated linearly; after
    /// the trace's end the last speed holds until `give_up_s`. `None`: it never left by then.
    pub fn residence_over_trace(
        mut self,
        trace: &[(f64, f64)],
        max_step_s: f64,
        give_up_s: f64,
    ) -> Option<f64> {
        if let Some(t) = self.exit_s {
            return Some(t);
        }
        if trace.is_empty() || max_step_s.is_nan() || max_step_s <= 0.0 {
            return None;
        }
        let speed_at = |t: f64, from: &mut usize| -> f64 {
            while *from + 1 < trace.len() && trace[*from + 1].0 <= t {
                *from += 1;
            }
            let (ta, wa) = trace[*from];
            match trace.get(*from + 1) {
                Some(&(tb, wb)) if tb > ta && t >= ta => wa + (wb - wa) * (t - ta) / (tb - ta),
                _ => wa,
            }
        };
        let mut index = 0;
        let steps = libm::ceil(give_up_s / max_step_s).clamp(0.0, 1e8) as u64;
        for _ in 0..steps {
            let mid = self.time_s + 0.5 * max_step_s;
            let w = speed_at(mid, &mut index);
            if let Some(t) = self.step(w, max_step_s) {
                return Some(t);
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::particle::{Scene, residence};

    fn closed_form(model: Model, mu: f64, w: f64) -> f64 {
        let scene = Scene {
            omega_rad_s: w,
            mu,
            g_m_s2: G_M_S2,
            k2: 5.0 / 7.0,
            ri_m: 0.05,
            rim_radius_m: 0.15,
        };
        residence(&scene, model).unwrap().residence_time_s()
    }

    /// At a constant speed the stepped granule meets the closed forms of paper Eq. 6 and 10
    /// (corrected) to within 10 microseconds at a 1 ms step.
    #[test]
    fn constant_speed_matches_the_closed_forms() {
        for model in [Model::Flat, Model::Coriolis] {
            for (mu, w) in [(0.03, 3.0), (0.029, 5.0), (0.1, 6.0), (0.0, 2.0)] {
                let mut g = Granule::new(model, mu, 5.0 / 7.0, 0.05, 0.15);
                let mut exit = None;
                for _ in 0..100_000 {
                    exit = g.step(w, 1e-3);
                    if exit.is_some() {
                        break;
                    }
                }
                let want = closed_form(model, mu, w);
                let got = exit.unwrap();
                assert!(
                    (got - want).abs() < 1e-5,
                    "{model:?} mu {mu} w {w}: {got} vs {want}"
                );
                let via_trace = Granule::new(model, mu, 5.0 / 7.0, 0.05, 0.15)
                    .residence_over_trace(&[(0.0, w)], 1e-3, 100.0)
                    .unwrap();
                assert!((via_trace - want).abs() < 1e-5);
            }
        }
    }

    /// Below the equilibrium radius static friction holds it: never an exit, never inward.
    #[test]
    fn held_below_the_equilibrium_radius() {
        let mut g = Granule::new(Model::Coriolis, 0.4, 5.0 / 7.0, 0.05, 0.15);
        for _ in 0..10_000 {
            assert_eq!(g.step(3.0, 1e-3), None);
        }
        assert_eq!(g.radius_m(), 0.05);
    }

    /// A speed that rises during the residence gives a time between the closed forms at the
    /// start and end speeds.
    #[test]
    fn ramp_lies_between_its_end_speeds() {
        let trace = [(0.0, 3.0), (5.0, 4.0)];
        let t = Granule::new(Model::Flat, 0.03, 5.0 / 7.0, 0.05, 0.15)
            .residence_over_trace(&trace, 1e-3, 100.0)
            .unwrap();
        let (slow, fast) = (
            closed_form(Model::Flat, 0.03, 3.0),
            closed_form(Model::Flat, 0.03, 4.0),
        );
        assert!(t < slow && t > fast, "{fast} < {t} < {slow}");
    }

    /// Out-of-range values are named.
    #[test]
    fn validation_names_the_key() {
        let p = ParticleParams {
            mu: f64::NAN,
            ..ParticleParams::default()
        };
        assert_eq!(p.validate().unwrap_err().key, "mu");
        let p = ParticleParams {
            release_radius_m: 0.2,
            ..ParticleParams::default()
        };
        assert_eq!(p.validate().unwrap_err().key, "release_radius_m");
        assert!(ParticleParams::default().validate().is_ok());
    }

    /// Gaussian draws have mean 0 and variance 1 (to sampling error at 20 000 draws).
    #[test]
    fn gaussian_moments() {
        let mut rng = Prng::new(7);
        let n = 20_000;
        let xs: [f64; 20_000] = core::array::from_fn(|_| gaussian(&mut rng));
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n as f64;
        assert!(mean.abs() < 0.03, "{mean}");
        assert!((var - 1.0).abs() < 0.05, "{var}");
    }

    proptest::proptest! {
        /// Any finite inputs: no panic, the radius stays finite and never moves inward, an exit
        /// time lies within the elapsed time.
        #[test]
        fn any_finite_input_is_safe(
            flat in proptest::bool::ANY,
            mu in -1e3f64..1e3, k2 in -2.0f64..2.0, r0 in -1.0f64..1.0, rim in -1.0f64..1.0,
            w in -1e3f64..1e3, dt in -1.0f64..1.0,
        ) {
            let model = if flat { Model::Flat } else { Model::Coriolis };
            let mut g = Granule::new(model, mu, k2, r0, rim);
            let start = g.radius_m();
            for _ in 0..50 {
                let before = g.radius_m();
                if let Some(t) = g.step(w, dt) {
                    proptest::prop_assert!(t >= 0.0 && t <= g.time_s());
                }
                proptest::prop_assert!(g.radius_m().is_finite() || g.exit_s().is_some());
                proptest::prop_assert!(g.radius_m() >= before && !g.radius_m().is_nan());
            }
            proptest::prop_assert!(start >= 0.0);
            let _ = Granule::new(model, mu, k2, r0, rim).residence_over_trace(&[(0.0, w), (1.0, -w)], dt.abs(), 2.0);
        }
    }
}
