//! Whether a model's assumptions hold at the scene (issue 30: no silent T). Every answer of
//! `bowl predict` carries `valid` and `invalid_reason` beside its residence times in JSON, and
//! the text says it first; the exit code stays 0 (the answer is given, with what it is worth,
//! as a coarse step's warning is).

use model_core::particle::{Outcome, Scene};
use serde_json::{Value, json};

/// Valid, or why not, in plain words.
#[derive(Debug, Clone, PartialEq)]
pub struct Validity(pub Option<String>);

impl Validity {
    pub fn valid() -> Self {
        Self(None)
    }

    /// Adds `valid` and `invalid_reason` to a JSON object.
    pub fn add_to(&self, v: &mut Value) {
        if let Some(obj) = v.as_object_mut() {
            obj.insert("valid".into(), json!(self.0.is_none()));
            obj.insert("invalid_reason".into(), json!(self.0));
        }
    }

    /// The line the text output starts with when the model does not hold, else nothing. It
    /// names the model (`rolling model NOT VALID HERE: ...`), as the paper's models' lines
    /// always did: after `--model auto` a bare "NOT VALID HERE" left the reader to guess which.
    pub fn text_line(&self, model: &str) -> Option<String> {
        self.0
            .as_ref()
            .map(|r| format!("{model} model NOT VALID HERE: {r}"))
    }

    /// The start of an answer at a varying speed (a spin-up, a logged trace) of `model`: with
    /// `json`, `v`
    /// with the chooser's `choice` (the JSON of `super::choice::json`), the residence time
    /// (null when the granule never leaves) and this validity, printed, and `false`; in text,
    /// this validity's line first, and `true`: the caller's text follows.
    pub fn start_answer(
        &self,
        json: bool,
        model: model_core::particle::Model,
        mut v: Value,
        choice: Value,
        time_s: f64,
    ) -> bool {
        if !json {
            if let Some(line) = self.text_line(super::model_name(model)) {
                println!("{line}");
            }
            return true;
        }
        if let Some(obj) = v.as_object_mut() {
            obj.insert("choice".into(), choice);
            let time = if time_s.is_finite() {
                json!(time_s)
            } else {
                Value::Null
            };
            obj.insert("residence_time_s".into(), time);
        }
        self.add_to(&mut v);
        println!("{v}");
        false
    }
}

/// The rolling model over releases: it assumes the granule rolls (friction within `mu_s N`)
/// and stays on the bottom (`N > 0`).
pub fn rolling(slid: u32, lifted: u32, releases: u32, max_ratio: f64, sliding_mu: f64) -> Validity {
    let mut why = Vec::new();
    let releases = crate::number::count(releases as usize, "release", "releases");
    if slid > 0 {
        why.push(format!(
            "rolling needs friction up to {max_ratio:.3} of the normal force, more than the \
             {sliding_mu} the contact gives (--sliding-mu): the granule slides in {slid} of \
             {releases}, so this T is the rolling model's, not the rig's (--model bowl \
             follows the sliding granule)"
        ));
    }
    if lifted > 0 {
        why.push(format!(
            "the granule lifts off the bottom (the normal force reaches zero) in {lifted} of \
             {releases}; the model ends there and gives no T for them"
        ));
    }
    if why.is_empty() {
        Validity::valid()
    } else {
        Validity(Some(why.join("; ")))
    }
}

/// The paper's 1-D models (Eq. 5 to 11) on their own horizontal bowl: the granule rolls
/// radially, so the contact must give the friction that spins it, `(1 - k2) m (r omega^2 - mu
/// g)`, and the Coriolis force of its radial motion, `2 m omega r'`, both largest at the rim;
/// beyond `mu_s m g` it slides and the model's rolling `k2` does not apply.
pub fn paper(scene: &Scene<f64>, outcome: &Outcome<f64>, sliding_mu: f64) -> Validity {
    let Outcome::Leaves {
        exit_radial_velocity_m_s,
        ..
    } = *outcome
    else {
        return Validity::valid();
    };
    let w = scene.omega_rad_s;
    let spin_up = (1.0 - scene.k2) * (scene.rim_radius_m * w * w - scene.mu * scene.g_m_s2);
    let coriolis = 2.0 * w * exit_radial_velocity_m_s;
    let need = spin_up.hypot(coriolis);
    let give = sliding_mu * scene.g_m_s2;
    if need > give {
        Validity(Some(format!(
            "rolling out to the rim needs friction of {} of the granule's weight (spin-up \
             and the Coriolis force), more than the {sliding_mu} the contact gives \
             (--sliding-mu): the granule slides there, so this T is the paper's rolling \
             model's",
            // Through `fixed`: at 1e30 rad/s `{:.3}` wrote a 59-digit number.
            crate::number::fixed(need / scene.g_m_s2, 3)
        )))
    } else {
        Validity::valid()
    }
}

/// [`paper`] for a speed that varies up to `max_omega_rad_s` (a spin-up, a logged trace): the
/// friction needed is largest at the highest speed, judged with the closed form there.
pub fn paper_up_to(
    scene: &Scene<f64>,
    model: model_core::particle::Model,
    max_omega_rad_s: f64,
    sliding_mu: f64,
) -> Validity {
    let top = Scene {
        omega_rad_s: max_omega_rad_s,
        ..*scene
    };
    match model_core::particle::residence(&top, model) {
        Ok(outcome) => paper(&top, &outcome, sliding_mu),
        Err(_) => Validity::valid(),
    }
}
