//! The f64 physics re-check: the residence times the rig predicted, and the speeds it chose for
//! a residence-time target, computed again on the host in f64 from the rig's parameters (paper
//! Eq. 2, 5-12 with the corrections of docs/model.md).

use model_core::bowl::BowlGeometry;
use model_core::particle::{self, Model, Outcome, Scene};
use model_core::wire::{ParamId, ParamValues, Residence, Telemetry};

use super::frames::set;
use super::report::{Predicted, ResidenceCheck, Tolerances};
use super::script::RESIDENCE_TARGET_MS;

/// The particle scene from the rig's parameters: the one mapping the rig itself uses
/// ([`model_core::binding::scene_from_params`]); `None` when the parameters do not make a scene.
pub fn scene_of(params: &ParamValues) -> Option<Scene<f64>> {
    model_core::binding::scene_from_params(params).ok()
}

fn host_residence_ms(scene: &Scene<f64>, omega: f64, model: Model) -> Option<f64> {
    let s = Scene {
        omega_rad_s: omega,
        ..*scene
    };
    match particle::residence(&s, model) {
        Ok(Outcome::Leaves {
            residence_time_s, ..
        }) => Some(residence_time_s * 1000.0),
        _ => None,
    }
}

fn mean_residence(frames: &[Telemetry], pick: impl Fn(&Telemetry) -> Residence) -> Option<f64> {
    let v: Vec<f64> = frames
        .iter()
        .filter_map(|t| match pick(t) {
            Residence::Ms(ms) => Some(f64::from(ms)),
            _ => None,
        })
        .collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

pub(super) fn predicted(
    frames: &[Telemetry],
    scene: Option<&Scene<f64>>,
    tol: &Tolerances,
) -> Option<Predicted> {
    if frames.is_empty() {
        return None;
    }
    let from = frames.len()
        - ((frames.len() as f64 * tol.steady_fraction).ceil() as usize).clamp(1, frames.len());
    let steady = frames.get(from..)?;
    let bowl =
        steady.iter().map(|t| f64::from(t.bowl_mrad_s)).sum::<f64>() / steady.len() as f64 / 1000.0;
    Some(Predicted {
        bowl_rad_s: bowl,
        flat_ms: mean_residence(steady, |t| t.residence_flat),
        coriolis_ms: mean_residence(steady, |t| t.residence_coriolis),
        host_flat_ms: scene.and_then(|s| host_residence_ms(s, bowl, Model::Flat)),
        host_coriolis_ms: scene.and_then(|s| host_residence_ms(s, bowl, Model::Coriolis)),
    })
}

pub(super) fn residence_check(
    frames: &[Telemetry],
    accepted: bool,
    params: Option<&ParamValues>,
) -> ResidenceCheck {
    let rig_set = frames
        .last()
        .map(|t| [set(t, 0), set(t, 1)])
        .unwrap_or([f64::NAN; 2]);
    let target_s = f64::from(RESIDENCE_TARGET_MS) / 1000.0;
    let (mut bowl, mut split, mut flat) = (None, None, None);
    if let Some(p) = params
        && let Some(scene) = scene_of(p)
        && let Ok(w) = particle::omega_for_residence_time(&scene, Model::Coriolis, target_s)
    {
        bowl = Some(w);
        flat = host_residence_ms(&scene, w, Model::Flat);
        let angle = f64::from(p[ParamId::AxesMdeg.index()]) / 1000.0;
        let ratio = f64::from(p[ParamId::RatioPpm.index()]) / 1e6;
        if let Ok(g) = BowlGeometry::new(angle.to_radians())
            && let Ok(m) = g.split(w, ratio)
        {
            split = Some([m.precession_rad_s, m.spin_rad_s]);
        }
    }
    let split_agrees = accepted
        && split.is_some_and(|s| {
            (s[0] - rig_set[0]).abs() <= 0.005 && (s[1] - rig_set[1]).abs() <= 0.005
        });
    ResidenceCheck {
        target_ms: RESIDENCE_TARGET_MS,
        accepted,
        host_bowl_rad_s: bowl,
        host_split_rad_s: split,
        rig_set_rad_s: rig_set,
        split_agrees,
        host_flat_at_target_ms: flat,
    }
}
