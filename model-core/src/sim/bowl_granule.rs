//! A simulated granule in the real bowl (issue 30, docs/model.md §10): when a rig file's
//! `[particle] model = "bowl"`, the granules a simulated rig drops follow the bowl model
//! ([`crate::particle::bowl`]: rolling, sliding, flying on the bottom, the fillet and the wall,
//! leaving when the centre passes the lip's radius) instead of the paper's radial equations
//! ([`super::granule`]).
//!
//! The bowl model takes the two motor speeds separately and holds them constant over a release
//! (its flight phase uses the closed-form rotation of the precessing frame), so a release is
//! computed once, at the plant's true shaft speeds at the moment the granule drops: the exit
//! time is then known at the release and the gate fires when it comes ([`super::gates`]). The
//! speed's ripple and drift during the release (a few tenths of a percent on a settled rig) do
//! not reach this granule; at the rig's tilt they would move `T` by far less than that (docs/model.md
//! §11: `T` changes by 1 % or less over the whole speed range at 60 degrees).

use super::granule::{G_M_S2, ParticleParams, gaussian};
use super::prng::Prng;
use crate::particle::bowl::{self, BowlOutcome, BowlShape};
use crate::particle::rolling::{MAX_STEPS, RollingMethod, RollingScene, SystemLimits};

/// A release still inside after this long has not left: the experiment's own give-up time
/// (60 s), so the model never reports an exit the rig would not wait for.
pub const HORIZON_S: f64 = 60.0;

/// The integration of a release: DP5(4) at rtol 1e-9, `bowl predict --model bowl`'s default
/// (`--tol`), whose error in `T` is far under any gate's timing error.
pub const METHOD: RollingMethod<f64> = RollingMethod::Dp54 { rtol: 1e-9 };

/// The bowl a simulated granule rolls in and its friction: the rig file's `[bowl]` table with
/// `[particle] sliding_mu` and `sliding_mu_spread`. The rest of the granule (rolling
/// resistance `mu`, `k2`, start radius and its spread, gate jitter) is its [`ParticleParams`];
/// the bowl's bottom radius is their `rim_radius_m`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlTruth {
    /// The wall, fillet and restitution.
    pub shape: BowlShape<f64>,
    /// Angle between the vertical (precession axis) and the bowl's axis, rad (paper Eq. 2).
    pub axes_angle_rad: f64,
    /// Granule radius, m.
    pub particle_radius_m: f64,
    /// True sliding friction `mu_s` of the granule on the bowl.
    pub sliding_mu: f64,
    /// Granule-to-granule spread of `mu_s` (standard deviation).
    pub sliding_mu_spread: f64,
}

/// One granule drawn and followed: where it started, its friction and when it left.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlRelease {
    /// Release azimuth from the downhill direction (as `bowl predict --release-azimuth-deg`),
    /// rad, uniform in [0, 2 pi).
    pub azimuth_rad: f64,
    /// Its sliding friction.
    pub sliding_mu: f64,
    /// Its start radius, m.
    pub release_radius_m: f64,
    /// Seconds from the release to the centre passing the lip; `None`: it never left (held by
    /// the wall or at rest, still inside after [`HORIZON_S`], lifted off with no landing, or
    /// an integration that gave up).
    pub exit_s: Option<f64>,
}

impl BowlTruth {
    /// The bowl model's scene for one granule at the motor speeds `speeds_rad_s`
    /// (`[precession, spin]`, true): the rolling resistance, `k2` and bottom radius from
    /// `particle`.
    pub fn scene(
        &self,
        particle: &ParticleParams,
        speeds_rad_s: [f64; 2],
        sliding_mu: f64,
        release_radius_m: f64,
    ) -> RollingScene<f64> {
        RollingScene {
            precession_rad_s: speeds_rad_s[0],
            spin_rad_s: speeds_rad_s[1],
            axes_angle_rad: self.axes_angle_rad,
            rolling_resistance: particle.mu,
            sliding_friction: sliding_mu,
            g_m_s2: G_M_S2,
            k2: particle.k2,
            particle_radius_m: self.particle_radius_m,
            rod_length_m: 0.0,
            ri_m: release_radius_m,
            rim_radius_m: particle.rim_radius_m,
        }
    }

    /// Seconds from the release at azimuth `azimuth_rad` to the exit over the lip, the speeds
    /// held; `None`: it never leaves (see [`BowlRelease::exit_s`]).
    pub fn residence_s(
        &self,
        particle: &ParticleParams,
        speeds_rad_s: [f64; 2],
        azimuth_rad: f64,
        sliding_mu: f64,
        release_radius_m: f64,
    ) -> Option<f64> {
        let scene = self.scene(particle, speeds_rad_s, sliding_mu, release_radius_m);
        let limits = SystemLimits {
            horizon_s: HORIZON_S,
            max_steps: MAX_STEPS,
        };
        match bowl::residence_f64(&scene, &self.shape, azimuth_rad, METHOD, limits) {
            Ok(r) => match r.outcome {
                BowlOutcome::Leaves {
                    residence_time_s, ..
                } if residence_time_s.is_finite() && residence_time_s >= 0.0 => {
                    Some(residence_time_s)
                }
                _ => None,
            },
            Err(_) => None,
        }
    }

    /// One granule drawn from the spreads (azimuth uniform; `mu_s` and the start radius
    /// Gaussian, `mu_s` non-negative, the start on the bottom) and followed at the motor speeds
    /// `speeds_rad_s` of the moment it drops.
    pub fn release(
        &self,
        particle: &ParticleParams,
        rng: &mut Prng,
        speeds_rad_s: [f64; 2],
    ) -> BowlRelease {
        let azimuth_rad = core::f64::consts::TAU * f64::from(rng.unit());
        let sliding_mu = (self.sliding_mu + self.sliding_mu_spread * gaussian(rng)).max(0.0);
        let release_radius_m = (particle.release_radius_m
            + particle.release_spread_m * gaussian(rng))
        .clamp(0.0, particle.rim_radius_m);
        BowlRelease {
            azimuth_rad,
            sliding_mu,
            release_radius_m,
            exit_s: self.residence_s(
                particle,
                speeds_rad_s,
                azimuth_rad,
                sliding_mu,
                release_radius_m,
            ),
        }
    }
}

/// The rig's bowl for tests: 60 deg tilt, 75 mm bottom, a 60 deg wall 10 mm high, sharp
/// corner; the granule's truth in it.
#[cfg(test)]
pub(crate) fn rig() -> (BowlTruth, ParticleParams) {
    let truth = BowlTruth {
        shape: BowlShape {
            wall_angle_rad: 60f64.to_radians(),
            wall_height_m: 0.01,
            fillet_radius_m: 0.0,
            restitution: 0.0,
        },
        axes_angle_rad: 60f64.to_radians(),
        particle_radius_m: 0.003,
        sliding_mu: 0.4,
        sliding_mu_spread: 0.0,
    };
    let particle = ParticleParams {
        mu: 0.029,
        release_radius_m: 0.0375,
        rim_radius_m: 0.075,
        bowl: Some(truth),
        ..ParticleParams::default()
    };
    (truth, particle)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A release's exit is the bowl model's own answer for the same scene and azimuth, and the
    /// drawn azimuths cover the circle.
    #[test]
    fn a_release_is_the_bowl_models_answer_at_its_azimuth() {
        let (truth, particle) = rig();
        let mut rng = Prng::new(3);
        let speeds = [1.2, 1.2];
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for _ in 0..8 {
            let r = truth.release(&particle, &mut rng, speeds);
            lo = lo.min(r.azimuth_rad);
            hi = hi.max(r.azimuth_rad);
            let scene = truth.scene(&particle, speeds, 0.4, 0.0375);
            let limits = SystemLimits {
                horizon_s: HORIZON_S,
                max_steps: MAX_STEPS,
            };
            let want = bowl::residence(&scene, &truth.shape, r.azimuth_rad, METHOD, limits)
                .unwrap()
                .outcome;
            match want {
                BowlOutcome::Leaves {
                    residence_time_s, ..
                } => assert_eq!(r.exit_s, Some(residence_time_s)),
                other => panic!("{other:?}"),
            }
        }
        assert!(lo < 1.5 && hi > 4.5, "azimuths {lo} to {hi}");
    }

    /// A vertical wall 20 mm high with a sharp corner holds the granule: it never leaves.
    #[test]
    fn a_vertical_wall_holds_it() {
        let (mut truth, particle) = rig();
        truth.shape.wall_angle_rad = core::f64::consts::FRAC_PI_2;
        truth.shape.wall_height_m = 0.02;
        let mut rng = Prng::new(5);
        for _ in 0..4 {
            assert_eq!(truth.release(&particle, &mut rng, [1.2, 1.2]).exit_s, None);
        }
    }
}
