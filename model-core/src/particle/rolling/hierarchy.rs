//! The model hierarchy for the tilted, precessing bowl, from the cheapest idealisation to the
//! full rolling model, and how far each member is from the full model on a scene: the measure
//! by which a chooser takes the cheapest member good enough for a tolerance (docs/model.md §9).

use super::{
    AZIMUTHS_DEG, RollingMethod, RollingOutcome, RollingScene, disc_residence_s,
    incline_residence_s, residence, residence_over_azimuths,
};
use crate::Real;
use crate::particle::{self, Model, Outcome, Scene};

/// A member of the hierarchy, cheapest first.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Member {
    /// The paper's flat Eq. 6/7 at the combined speed: no tilt, no rolling coupling.
    PaperFlat,
    /// The paper's Eq. 10/11 (corrected) at the combined speed.
    PaperCoriolis,
    /// The horizontal spinning disc rolled exactly, no resistance, no tilt (closed form).
    HorizontalDisc,
    /// The straight roll down the tilted bottom, no rotation (closed form per azimuth).
    FixedIncline,
    /// The tilted bowl spinning at the combined speed about its own axis, without precession
    /// (integrated per azimuth, like the full model, with gravity fixed in the inertial frame).
    TiltedPlane,
    /// The full rolling model (integrated per azimuth).
    Full,
}

/// Every member, cheapest first.
pub const MEMBERS: [Member; 6] = [
    Member::PaperFlat,
    Member::PaperCoriolis,
    Member::HorizontalDisc,
    Member::FixedIncline,
    Member::TiltedPlane,
    Member::Full,
];

impl Member {
    /// Short name for tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Member::PaperFlat => "paper-flat",
            Member::PaperCoriolis => "paper-coriolis",
            Member::HorizontalDisc => "horizontal-disc",
            Member::FixedIncline => "fixed-incline",
            Member::TiltedPlane => "tilted-plane",
            Member::Full => "rolling",
        }
    }
}

/// The mean residence time over the release azimuths under `member`, s; `None` when the member
/// says the granule does not leave.
pub fn mean_residence_s<T: Real>(
    member: Member,
    scene: &RollingScene<T>,
    method: RollingMethod<T>,
) -> Option<T> {
    let paper = |model: Model| {
        let s = Scene {
            omega_rad_s: scene.combined_speed_rad_s(),
            mu: scene.rolling_resistance,
            g_m_s2: scene.g_m_s2,
            k2: scene.k2,
            ri_m: scene.ri_m,
            rim_radius_m: scene.rim_radius_m,
        };
        match particle::residence(&s, model) {
            Ok(Outcome::Leaves {
                residence_time_s, ..
            }) => Some(residence_time_s),
            _ => None,
        }
    };
    match member {
        Member::PaperFlat => paper(Model::Flat),
        Member::PaperCoriolis => paper(Model::Coriolis),
        Member::HorizontalDisc => disc_residence_s(
            scene.combined_speed_rad_s(),
            scene.k2,
            scene.ri_m,
            scene.rim_radius_m,
        ),
        Member::FixedIncline => {
            let mut sum = T::ZERO;
            for deg in AZIMUTHS_DEG {
                sum += incline_residence_s(scene, T::from_f64(deg.to_radians()))?;
            }
            Some(sum / T::from_f64(AZIMUTHS_DEG.len() as f64))
        }
        Member::TiltedPlane => mean_residence_s(Member::Full, &tilted_plane(scene), method),
        Member::Full => {
            let s = residence_over_azimuths(scene, method).ok()?;
            if s.left as usize == AZIMUTHS_DEG.len() {
                s.mean_s
            } else {
                None
            }
        }
    }
}

/// The scene without precession: the bowl spins at the combined speed about its tilted axis.
fn tilted_plane<T: Real>(scene: &RollingScene<T>) -> RollingScene<T> {
    RollingScene {
        precession_rad_s: T::ZERO,
        spin_rad_s: scene.combined_speed_rad_s(),
        ..*scene
    }
}

/// What the scene needs the model for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Wanted {
    /// The mean over the release azimuths (a batch of granules dropped anywhere).
    AzimuthMean,
    /// Every single release (one granule at a known azimuth): the worst azimuth counts.
    EachRelease,
}

/// One release's residence time under `member`, s (the paper's forms and the disc do not
/// depend on the azimuth).
fn release_time_s<T: Real>(
    member: Member,
    scene: &RollingScene<T>,
    beta_rad: T,
    method: RollingMethod<T>,
) -> Option<T> {
    match member {
        Member::FixedIncline => incline_residence_s(scene, beta_rad),
        Member::TiltedPlane => release_time_s(Member::Full, &tilted_plane(scene), beta_rad, method),
        Member::Full => match residence(scene, beta_rad, method).ok()?.outcome {
            RollingOutcome::Leaves {
                residence_time_s, ..
            } => Some(residence_time_s),
            _ => None,
        },
        other => mean_residence_s(other, scene, method),
    }
}

/// Each member's relative difference from the full model, in the order of [`MEMBERS`]: for the
/// azimuth mean `|T_member - T_full| / T_full` of the means, for each release the largest such
/// difference over the azimuths. `None` where the member or the full model has no time (then
/// the member cannot stand in for the full model).
pub fn differences<T: Real>(
    scene: &RollingScene<T>,
    method: RollingMethod<T>,
    wanted: Wanted,
) -> [Option<T>; 6] {
    match wanted {
        Wanted::AzimuthMean => {
            let full = mean_residence_s(Member::Full, scene, method);
            MEMBERS.map(|m| {
                let full = full?;
                let t = if m == Member::Full {
                    full
                } else {
                    mean_residence_s(m, scene, method)?
                };
                Some(((t - full) / full).abs())
            })
        }
        Wanted::EachRelease => {
            let mut full = [T::ZERO; AZIMUTHS_DEG.len()];
            for (slot, deg) in full.iter_mut().zip(AZIMUTHS_DEG) {
                match release_time_s(Member::Full, scene, T::from_f64(deg.to_radians()), method) {
                    Some(t) => *slot = t,
                    None => return [None; 6],
                }
            }
            MEMBERS.map(|m| {
                let mut worst = T::ZERO;
                for (f, deg) in full.iter().zip(AZIMUTHS_DEG) {
                    let t = if m == Member::Full {
                        *f
                    } else {
                        release_time_s(m, scene, T::from_f64(deg.to_radians()), method)?
                    };
                    worst = worst.max(((t - *f) / *f).abs());
                }
                Some(worst)
            })
        }
    }
}

/// The tolerance a scene's uncertainty in the rolling resistance sets: the relative change of
/// the full model's mean residence time when `mu_r` moves by `+- mu_uncertainty`. A simpler
/// member within that is as good as the full model for this scene.
pub fn tolerance_from_resistance_uncertainty<T: Real>(
    scene: &RollingScene<T>,
    mu_uncertainty: T,
    method: RollingMethod<T>,
) -> Option<T> {
    let at = |mu: T| {
        let s = RollingScene {
            rolling_resistance: mu.max(T::ZERO),
            ..*scene
        };
        mean_residence_s(Member::Full, &s, method)
    };
    let t = at(scene.rolling_resistance)?;
    let up = at(scene.rolling_resistance + mu_uncertainty)?;
    let down = at(scene.rolling_resistance - mu_uncertainty)?;
    Some((up - down).abs() / (T::TWO * t))
}

/// The cheapest member within `tolerance` (relative) of the full model on this scene for what
/// is `wanted`, and that difference; the full model when nothing cheaper is close enough.
pub fn cheapest_within<T: Real>(
    scene: &RollingScene<T>,
    tolerance: T,
    method: RollingMethod<T>,
    wanted: Wanted,
) -> (Member, Option<T>) {
    let d = differences(scene, method, wanted);
    for (m, diff) in MEMBERS.iter().zip(d) {
        if let Some(x) = diff
            && x <= tolerance
        {
            return (*m, Some(x));
        }
    }
    (Member::Full, d[5])
}
