//! The candidate equations of motion and a run's predicted residence time under each.
//!
//! A run is predicted from its own measured speed trace: at the trace's mean speed by the closed
//! form (paper Eq. 6 / 10, corrected, `model_core::particle::residence`) when the speed held
//! steady, otherwise by integrating the equation over the trace
//! (`model_core::sim::granule::Granule`, the same integrator the simulated rig's granules use).

use model_core::ode::system::SystemLimits;
use model_core::particle::bowl::{self, BowlOutcome, BowlShape};
use model_core::particle::rolling::{self, RollingMethod, RollingScene};
use model_core::particle::{Model, Scene, residence};
use model_core::sim::granule::{G_M_S2, Granule};

/// Relative standard deviation of the speed trace below which the closed form at the mean
/// speed is used. `T` moves by about 1 to 3 times a relative speed change (more only near the
/// threshold), so 0.02 % keeps the closed form's error under about 0.06 % of `T`: a tenth of
/// the 95 % interval that a 2 ms gate gives on five releases of 0.5 s, so the approximation never
/// moves the fit by as much as its own interval. Everything less steady is integrated.
pub const STEADY_REL_SD: f64 = 0.0002;

/// Integration step over a trace, s (the rig's control period).
pub const TRACE_STEP_S: f64 = 1e-3;

/// An equation of motion the fit can try.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Equation {
    /// The paper's radial equation (flat or Coriolis, docs/model.md sections 2 to 4).
    Paper(Model),
    /// The granule rolling on the tilted, precessing bowl (docs/model.md section 9), the mean
    /// over the twelve release azimuths at the run's mean speed split equally between the
    /// motors, at the run's axes angle.
    Rolling,
    /// The granule in the real bowl with this wall (docs/model.md section 10: rolling, sliding,
    /// flying, over the lip), the mean over the twelve azimuths as [`Equation::Rolling`]; the
    /// fitted parameter is the sliding friction `mu_s` (rolling resistance
    /// [`BOWL_ROLLING_RESISTANCE`], a sharp corner, restitution 0).
    Bowl(Wall),
}

/// A bowl's wall for the bowl model's candidates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wall {
    /// Angle from the bottom plane, degrees (90 = vertical).
    pub angle_deg: f64,
    /// Height above the bottom, m (0 = a bare rim).
    pub height_m: f64,
}

impl Wall {
    /// The rig's fillet as this candidate wall holds it: a fillet ends on its wall, so one
    /// rising above a lower candidate wall is the largest that wall holds, and a bare rim has
    /// none (the bowl model refuses a fillet above its wall; the candidate stays a wall of its
    /// height and angle).
    pub fn fillet_held_m(&self, fillet_m: f64) -> f64 {
        let rise_per_m = 1.0 - self.angle_deg.to_radians().cos();
        fillet_m.min(self.height_m / rise_per_m)
    }
}

/// The bowl model's rolling resistance in the fit (the rig's, docs/model.md section 10): the
/// fit's parameter is `mu_s`, which decides whether and where it slides.
pub const BOWL_ROLLING_RESISTANCE: f64 = 0.029;

/// The bowl model with each wall the fit can tell apart (`bowl fit --bowl-walls`): which wall
/// the measured times prefer, and `mu_s` under each.
pub const BOWL_CANDIDATES: [Candidate; 4] = [
    Candidate {
        name: "bowl-bare-rim",
        equation: Equation::Bowl(Wall {
            angle_deg: 90.0,
            height_m: 0.0,
        }),
    },
    Candidate {
        name: "bowl-wall-60deg-10mm",
        equation: Equation::Bowl(Wall {
            angle_deg: 60.0,
            height_m: 0.01,
        }),
    },
    Candidate {
        name: "bowl-wall-60deg-20mm",
        equation: Equation::Bowl(Wall {
            angle_deg: 60.0,
            height_m: 0.02,
        }),
    },
    Candidate {
        name: "bowl-wall-vertical-20mm",
        equation: Equation::Bowl(Wall {
            angle_deg: 90.0,
            height_m: 0.02,
        }),
    },
];

/// The candidate name of a wall: `bowl-bare-rim`, `bowl-wall-vertical-20mm`,
/// `bowl-wall-60deg-10mm` (the height in whole millimetres, to 0.1 mm when it has a fraction).
pub fn wall_name(wall: Wall) -> String {
    let mm = (wall.height_m * 1e4).round() / 10.0;
    let deg = (wall.angle_deg * 10.0).round() / 10.0;
    if wall.height_m <= 0.0 {
        "bowl-bare-rim".into()
    } else if deg == 90.0 {
        format!("bowl-wall-vertical-{mm}mm")
    } else {
        format!("bowl-wall-{deg}deg-{mm}mm")
    }
}

/// The bowl candidates: [`BOWL_CANDIDATES`], and the rig file's own wall `rig` when it is not
/// one of them (its name leaked once per fit: a handful of bytes per command).
pub fn bowl_candidates(rig: Option<Wall>) -> Vec<Candidate> {
    let mut out = BOWL_CANDIDATES.to_vec();
    if let Some(w) = rig {
        let same = |c: &Candidate| match c.equation {
            Equation::Bowl(o) => {
                (o.height_m <= 0.0 && w.height_m <= 0.0)
                    || ((o.height_m - w.height_m).abs() < 1e-9
                        && (o.angle_deg - w.angle_deg).abs() < 1e-9)
            }
            _ => false,
        };
        if !out.iter().any(same) {
            out.push(Candidate {
                name: Box::leak(wall_name(w).into_boxed_str()),
                equation: Equation::Bowl(w),
            });
        }
    }
    out
}

/// A model the fit can try: a name and an equation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Name in the JSON and the tables.
    pub name: &'static str,
    /// The equation of motion.
    pub equation: Equation,
}

/// The models compared, in output order.
pub const CANDIDATES: [Candidate; 3] = [
    Candidate {
        name: "flat",
        equation: Equation::Paper(Model::Flat),
    },
    Candidate {
        name: "coriolis",
        equation: Equation::Paper(Model::Coriolis),
    },
    Candidate {
        name: "rolling",
        equation: Equation::Rolling,
    },
];

/// The rolling model's integration in the fit: DP5(4) at rtol 1e-9, whose error in the mean
/// residence time (2e-10 relative on the rig, docs/model.md §9) is far under any gate's
/// scatter, and which copes near the stick threshold where looser tolerances chatter.
const ROLLING_METHOD: RollingMethod<f64> = RollingMethod::Dp54 { rtol: 1e-9 };

/// Steps allowed per release in the fit: a release that needs more is near the stick threshold,
/// far slower than any measured run, and counts as not leaving.
const ROLLING_MAX_STEPS: u32 = 5_000;

/// How a run's prediction is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Closed form at the trace's mean speed.
    ClosedForm,
    /// The equation integrated over the trace.
    Integrated,
}

/// One usable run.
#[derive(Debug, Clone)]
pub struct Run {
    /// Line of the results file (header = 1); 0 for a run not read from a file.
    pub row: usize,
    /// Plan condition.
    pub condition: usize,
    /// Measured residence time, s.
    pub residence_s: f64,
    /// Mean measured combined speed, rad/s.
    pub mean_rad_s: f64,
    /// Start radius, m.
    pub release_radius_m: f64,
    /// Rim radius, m.
    pub rim_radius_m: f64,
    /// `k2`.
    pub k2: f64,
    /// Speed trace (time since release, rad/s).
    pub trace: Vec<(f64, f64)>,
    /// Closed form or integrator.
    pub method: Method,
    /// Angle between the bowl's axis and the vertical, rad (the rolling model's tilt).
    pub axes_angle_rad: f64,
    /// What the bowl model needs beyond the paper's: the motor speeds, the release azimuth and
    /// the rig's bowl.
    pub bowl: BowlRun,
}

/// A run as the bowl model sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlRun {
    /// The target motor speeds `[precession, spin]`, rad/s (the results row's): scaled to the
    /// run's measured mean combined speed. `None`: the mean speed split equally.
    pub speeds_rad_s: Option<[f64; 2]>,
    /// Where the granule was dropped, rad from the downhill direction (the results row's
    /// `release_azimuth_deg`): the run is then compared with that one release. `None`: with the
    /// mean over the twelve azimuths.
    pub azimuth_rad: Option<f64>,
    /// The row's target combined speed `bowl_rad_s`, rad/s: the rig combined the motor speeds
    /// into it at its own tilt, so the two say which tilt the runs had (`fit::tilt`).
    pub planned_rad_s: Option<f64>,
    /// The bowl's fillet, restitution and granule, shared by every candidate wall.
    pub base: BowlBase,
}

impl Default for BowlRun {
    fn default() -> Self {
        Self {
            speeds_rad_s: None,
            azimuth_rad: None,
            planned_rad_s: None,
            base: BowlBase::DEFAULT,
        }
    }
}

/// The parts of the bowl and the granule that the candidate walls share: the rig file's
/// `[bowl]` table (`bowl fit --rig-file`), else [`BowlBase::DEFAULT`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BowlBase {
    /// Fillet radius between bottom and wall, m.
    pub fillet_radius_m: f64,
    /// Restitution of a granule against the wall.
    pub restitution: f64,
    /// Granule radius, m.
    pub particle_radius_m: f64,
    /// Rolling resistance `mu_r` (held; the fitted parameter is `mu_s`).
    pub rolling_resistance: f64,
}

impl BowlBase {
    /// Without a rig file: a sharp corner, restitution 0, a 3 mm granule, `mu_r`
    /// [`BOWL_ROLLING_RESISTANCE`].
    pub const DEFAULT: Self = Self {
        fillet_radius_m: 0.0,
        restitution: 0.0,
        particle_radius_m: 0.003,
        rolling_resistance: BOWL_ROLLING_RESISTANCE,
    };
}

/// Predicted residence time at `mu` (for the rolling model, its rolling resistance), s;
/// infinite when the granule would never leave.
pub fn predict(run: &Run, equation: Equation, mu: f64) -> f64 {
    predict_with_k2(run, equation, mu, run.k2)
}

/// As [`predict`], the granule's `k2` (its moment of inertia over `m r^2`) given instead of the
/// run's.
pub fn predict_with_k2(run: &Run, equation: Equation, mu: f64, k2: f64) -> f64 {
    let model = match equation {
        Equation::Paper(m) => m,
        Equation::Rolling => return rolling_mean(run, mu, k2),
        Equation::Bowl(wall) => return bowl_mean(run, wall, mu, k2),
    };
    match run.method {
        Method::ClosedForm => closed_form_with_k2(run, model, mu, k2, run.mean_rad_s),
        Method::Integrated => {
            let give_up = 20.0 * run.residence_s + 10.0;
            Granule::new(model, mu, k2, run.release_radius_m, run.rim_radius_m)
                .residence_over_trace(&run.trace, TRACE_STEP_S, give_up)
                .unwrap_or(f64::INFINITY)
        }
    }
}

/// Closed-form residence time at a constant speed, s (infinite: never leaves or invalid).
pub fn closed_form(run: &Run, model: Model, mu: f64, omega_rad_s: f64) -> f64 {
    closed_form_with_k2(run, model, mu, run.k2, omega_rad_s)
}

fn closed_form_with_k2(run: &Run, model: Model, mu: f64, k2: f64, omega_rad_s: f64) -> f64 {
    let scene = Scene {
        omega_rad_s,
        mu,
        g_m_s2: G_M_S2,
        k2,
        ri_m: run.release_radius_m,
        rim_radius_m: run.rim_radius_m,
    };
    residence(&scene, model).map_or(f64::INFINITY, |o| o.residence_time_s())
}

/// The rolling model's mean residence time over the azimuths at the run's mean speed, s
/// (infinite when a release does not leave). The rolling model takes constant motor speeds: a
/// drifting speed trace is represented by its mean.
fn rolling_mean(run: &Run, mu: f64, k2: f64) -> f64 {
    let scene = RollingScene {
        rolling_resistance: mu,
        k2,
        ri_m: run.release_radius_m,
        rim_radius_m: run.rim_radius_m,
        g_m_s2: G_M_S2,
        ..RollingScene::equal_speeds(run.mean_rad_s, run.axes_angle_rad, run.rim_radius_m)
    };
    let limits = rolling::SystemLimits {
        horizon_s: 20.0 * run.residence_s + 1.0,
        max_steps: ROLLING_MAX_STEPS,
    };
    match rolling::over_azimuths_within(&scene, ROLLING_METHOD, limits) {
        Ok(s) if s.left as usize == rolling::AZIMUTHS_DEG.len() => {
            s.mean_s.unwrap_or(f64::INFINITY)
        }
        _ => f64::INFINITY,
    }
}

/// The bowl model's integration in the fit: DP5(4) at rtol 1e-7, whose error in the mean T on
/// the rig's walled scene is 1e-9 relative (docs/model.md §10, work-precision), far under any
/// gate's scatter, at a third of rtol 1e-9's cost (a fit takes thousands of means).
const BOWL_METHOD: RollingMethod<f64> = RollingMethod::Dp54 { rtol: 1e-7 };

/// The bowl model's residence time for the run with the sliding friction `mu_s`, s (infinite
/// when a release does not leave or gives up): at the run's own release azimuth when the results
/// recorded it, else the mean over the twelve azimuths.
fn bowl_mean(run: &Run, wall: Wall, mu_s: f64, k2: f64) -> f64 {
    match run.bowl.azimuth_rad {
        Some(beta) => bowl_release(run, wall, mu_s, k2, beta),
        None => {
            let mut sum = 0.0;
            for deg in rolling::AZIMUTHS_DEG {
                sum += bowl_release(run, wall, mu_s, k2, deg.to_radians());
            }
            sum / rolling::AZIMUTHS_DEG.len() as f64
        }
    }
}

/// The bowl model's residence time of one release at azimuth `azimuth_rad` (from the downhill
/// direction) at the run's motor speeds, s (infinite when it does not leave or gives up).
pub fn bowl_release(run: &Run, wall: Wall, mu_s: f64, k2: f64, azimuth_rad: f64) -> f64 {
    let base = run.bowl.base;
    let [w1, w2] = motor_speeds(run);
    let scene = RollingScene {
        precession_rad_s: w1,
        spin_rad_s: w2,
        rolling_resistance: base.rolling_resistance,
        sliding_friction: mu_s,
        k2,
        particle_radius_m: base.particle_radius_m,
        ri_m: run.release_radius_m,
        rim_radius_m: run.rim_radius_m,
        g_m_s2: G_M_S2,
        ..RollingScene::equal_speeds(run.mean_rad_s, run.axes_angle_rad, run.rim_radius_m)
    };
    let shape = BowlShape {
        wall_angle_rad: wall.angle_deg.to_radians(),
        wall_height_m: wall.height_m,
        fillet_radius_m: wall.fillet_held_m(base.fillet_radius_m),
        restitution: base.restitution,
    };
    let limits = SystemLimits {
        horizon_s: 20.0 * run.residence_s + 1.0,
        max_steps: 20 * ROLLING_MAX_STEPS,
    };
    match bowl::residence_f64(&scene, &shape, azimuth_rad, BOWL_METHOD, limits) {
        Ok(r) => match r.outcome {
            BowlOutcome::Leaves {
                residence_time_s, ..
            } => residence_time_s,
            _ => f64::INFINITY,
        },
        Err(_) => f64::INFINITY,
    }
}

/// The combined bowl speed of motor speeds `[precession, spin]` with the axes `axes_angle_rad`
/// apart (paper Eq. 2, `model_core::bowl`), rad/s; NaN for speeds that are not finite.
pub fn combined_rad_s(speeds_rad_s: [f64; 2], axes_angle_rad: f64) -> f64 {
    let speeds = model_core::bowl::MotorSpeeds {
        precession_rad_s: speeds_rad_s[0],
        spin_rad_s: speeds_rad_s[1],
    };
    model_core::bowl::combined_speed_from_trig(axes_angle_rad.cos(), axes_angle_rad.sin(), speeds)
        .unwrap_or(f64::NAN)
}

/// The run's motor speeds `[precession, spin]`, rad/s: the row's targets scaled so their
/// combined speed (paper Eq. 2 at the run's tilt) is the measured mean; the mean split equally
/// when the row gave none (or targets that combine to nothing).
pub fn motor_speeds(run: &Run) -> [f64; 2] {
    let equal = || {
        let s = RollingScene::equal_speeds(run.mean_rad_s, run.axes_angle_rad, run.rim_radius_m);
        [s.precession_rad_s, s.spin_rad_s]
    };
    match run.bowl.speeds_rad_s {
        Some(t) => {
            let combined = combined_rad_s(t, run.axes_angle_rad);
            if combined > 0.0 && combined.is_finite() {
                let k = run.mean_rad_s / combined;
                [t[0] * k, t[1] * k]
            } else {
                equal()
            }
        }
        None => equal(),
    }
}

/// The largest `mu` at which the run can leave under `equation`: for the paper's equation
/// `ri omega^2 / g` at its fastest speed; for the rolling model on the tilted bottom, where
/// gravity's in-plane part drives it, `tan th` (the fixed incline's hold) plus that centrifugal
/// bound.
pub fn mu_ceiling_for(run: &Run, equation: Equation) -> f64 {
    match equation {
        Equation::Paper(_) => mu_ceiling(run),
        Equation::Rolling | Equation::Bowl(_) => run.axes_angle_rad.tan() + mu_ceiling(run),
    }
}

/// The largest `mu` at which the run can leave: `ri omega^2 / g` at its fastest speed.
pub fn mu_ceiling(run: &Run) -> f64 {
    let fastest = fastest_rad_s(run);
    run.release_radius_m * fastest * fastest / G_M_S2
}

/// The run's fastest measured speed (its trace's, or the mean if higher), rad/s: no model is
/// given a faster one.
pub fn fastest_rad_s(run: &Run) -> f64 {
    run.trace.iter().map(|p| p.1).fold(run.mean_rad_s, f64::max)
}

/// The shortest residence time any candidate model can give the run at any resistance, s: a
/// measured time below it is not a release of this run (a slip of a unit, a gate fired twice).
///
/// The bound: the granule starts at rest relative to the bowl at `ri` and must travel at least
/// `R - ri` to reach the rim. Along its path (length `s`, speed `v = s'`) only these forces can
/// raise its speed, in every candidate (docs/model.md sections 2 and 9; the rolling model as the
/// fit runs it: equal motor speeds, no rod offset, a 3 mm sphere of radius `a`): gravity's
/// in-plane part (at most `g`), the centrifugal and Euler terms of the turning frame (at most
/// `omega^2 |p|` and `omega^2 |p| / 2` with `|p| <= ri + s + a`, since `w1 w2 <= omega^2 / 2`
/// for axes at most 90 degrees apart, paper Eq. 2), and for the rolling sphere the coupling to
/// its spin about the axis (at most `omega^2 s + omega^2 a / 2`, its spin starting at zero and
/// changing at most at `omega v`); `k2 <= 1` only scales these down. Friction and rolling
/// resistance act against the motion, and the Coriolis and gyroscopic terms are perpendicular
/// to it: they never speed it up. So `v' <= b + c s` with `c = 5/2 omega^2` and
/// `b = g + omega^2 (3/2 ri + 2 a)`, `omega` the run's fastest measured speed, and by comparison
/// (`s'' = b + c s` from rest) `s(t) <= (b / c)(cosh(sqrt(c) t) - 1)`: the rim is reached no
/// sooner than `acosh(1 + c (R - ri) / b) / sqrt(c)`. The paper's frictionless `r'' = omega^2 r`
/// is inside it (`acosh(R / ri) / omega` is longer); on the rig (7 rad/s, 0.05 m to 0.15 m) the
/// bound is 0.11 s against 0.30 s without friction.
pub fn shortest_residence_s(run: &Run) -> f64 {
    let fastest = fastest_rad_s(run);
    let a =
        RollingScene::equal_speeds(fastest, run.axes_angle_rad, run.rim_radius_m).particle_radius_m;
    let w2 = fastest * fastest;
    let c = 2.5 * w2;
    let b = G_M_S2 + w2 * (1.5 * run.release_radius_m + 2.0 * a);
    let distance = run.rim_radius_m - run.release_radius_m;
    if c > 0.0 {
        // acosh(1 + x), accurate for small x too.
        let x = c * distance / b;
        (x + (x * (x + 2.0)).sqrt()).ln_1p() / c.sqrt()
    } else {
        // Not turning: gravity alone.
        (2.0 * distance / b).sqrt()
    }
}
