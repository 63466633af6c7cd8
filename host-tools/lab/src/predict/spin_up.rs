//! `bowl predict --spin-up-from-rad-s W0 --time-constant-s TAU`: the residence time while the
//! bowl spins up from `W0` to `--omega-rad-s` as a tuned speed loop drives it,
//! `omega(t) = omega + (W0 - omega) e^{-t / TAU}`, the particle released at t = 0. The chooser
//! picks the model and the integrator; with `--tolerance` on the host it reads them from its
//! precomputed error table without running the scene (`model_core::choose::table`).

use anyhow::{Result, anyhow, bail};
use model_core::choose::Plan;
use model_core::ode::SpinUp;
use model_core::particle::Scene;

use super::target::RunsOn;

/// Runs `bowl predict --spin-up-from-rad-s`.
pub fn run(
    scene: &Scene<f64>,
    start_rad_s: f64,
    time_constant_s: f64,
    need: &model_core::choose::Need<f64>,
    runs_on: RunsOn,
    json: bool,
    sliding_mu: f64,
) -> Result<()> {
    if !(start_rad_s.is_finite() && start_rad_s >= 0.0) {
        bail!("--spin-up-from-rad-s {start_rad_s}: the start speed must be zero or positive");
    }
    if !(time_constant_s.is_finite() && time_constant_s > 0.0) {
        bail!(
            "--time-constant-s {time_constant_s}: the spin-up's time constant must be a \
             positive number of seconds"
        );
    }
    if !(scene.omega_rad_s.is_finite() && scene.omega_rad_s > 0.0) {
        bail!(
            "--omega-rad-s {}: the speed the spin-up approaches must be positive",
            scene.omega_rad_s
        );
    }
    scene
        .validate_except_omega()
        .map_err(|e| anyhow!(super::refusals::scene(e)))?;
    let speed = SpinUp {
        start_rad_s,
        final_rad_s: scene.omega_rad_s,
        time_constant_s,
    };
    let choice = super::target::spin_up(scene, need, &speed, runs_on)
        .map_err(|e| anyhow!(super::choice::error_words(e)))?;
    let time_s = match choice.plan {
        Plan::ClosedForm => 0.0,
        Plan::ClosedFormAtMeanSpeed { .. } => bail!(
            "the chooser answered a spin-up with a closed form at a mean speed, which only a \
             logged trace asks for: please report this scene"
        ),
        Plan::Integrate(method) => super::ode::plan_time_s(scene, choice.model, &speed, method)?,
    };
    let top = start_rad_s.max(scene.omega_rad_s);
    let validity = super::validity::paper_up_to(scene, choice.model, top, sliding_mu);
    let head = serde_json::json!({
        "spin_up": {
            "start_rad_s": start_rad_s, "final_rad_s": scene.omega_rad_s,
            "time_constant_s": time_constant_s,
        },
    });
    let choice_json = super::choice::json(&choice, runs_on);
    if validity.start_answer(json, choice.model, head, choice_json, time_s) {
        println!(
            "spin-up: from {start_rad_s} to {} rad/s with time constant {time_constant_s} s, \
             the particle released at t = 0; mu {}, ri {} m, R {} m",
            scene.omega_rad_s, scene.mu, scene.ri_m, scene.rim_radius_m
        );
        println!("{}", super::choice::describe(&choice, need, runs_on));
        println!("{}", super::ode::plan_time_line(choice.model, time_s));
    }
    Ok(())
}
