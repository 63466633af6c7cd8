//! The numerical releases ([`super`]'s first member): one release integrated to the rim by the
//! project's integrators ([`crate::ode::system`]), and the sweep over the release azimuths.

use core::ops::ControlFlow;

use super::equations::{State, forces};
use super::{
    RollingError, RollingMethod, RollingOutcome, RollingReport, RollingScene, default_limits,
    release,
};
use crate::Real;
use crate::ode::system::{self, Ended, SystemLimits};

/// The rim in the state scaled by `1/R`: `|(x, y)|^2 - 1` and its derivative along `dy`.
fn rim_event<T: Real>(y: &State<T>, dy: &State<T>) -> (T, T) {
    (
        y[0] * y[0] + y[1] * y[1] - T::ONE,
        T::TWO * (y[0] * dy[0] + y[1] * dy[1]),
    )
}

/// One release at azimuth `beta_rad` (as `release` places it). Gives up after
/// [`HORIZON_S`](super::HORIZON_S) and [`MAX_STEPS`](super::MAX_STEPS).
pub fn residence<T: Real>(
    scene: &RollingScene<T>,
    beta_rad: T,
    method: RollingMethod<T>,
) -> Result<RollingReport<T>, RollingError> {
    residence_within(scene, beta_rad, method, default_limits())
}

/// [`residence`] within the caller's horizon and step cap (a fit that only needs to know that
/// a granule takes far longer than measured stops early; near the stick threshold a granule
/// that slows to rest and restarts can take many steps).
pub fn residence_within<T: Real>(
    scene: &RollingScene<T>,
    beta_rad: T,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
) -> Result<RollingReport<T>, RollingError> {
    let y0 = release(scene, beta_rad)?;
    // Lengths in units of R: the event is then |r|^2 - 1 = 0 with a fixed target.
    let rim = scene.rim_radius_m;
    let start = forces(scene, T::ZERO, &y0);
    if start.held && scene.stationary() {
        return Ok(RollingReport {
            outcome: RollingOutcome::Held,
            evaluations: 1,
            steps: 0,
        });
    }
    let mut max_ratio = T::ZERO;
    let mut first_slip = None;
    let mut watch = |t: T, y: &State<T>| -> ControlFlow<T> {
        let f = forces(scene, t, y);
        if f.normal_m_s2 <= T::ZERO {
            return ControlFlow::Break(t);
        }
        let ratio = f.friction_m_s2 / f.normal_m_s2;
        max_ratio = max_ratio.max(ratio);
        if first_slip.is_none() && ratio > scene.sliding_friction {
            first_slip = Some(t);
        }
        ControlFlow::Continue(())
    };
    let rhs = |t: T, y: &State<T>| forces(scene, t, y).derivative;
    // The integrators' event is a plain function: lengths are integrated in units of R so the
    // rim is the fixed |(x, y)| = 1.
    let scale = T::ONE / rim;
    let scaled = |y: &State<T>| -> State<T> { y.map(|v| v * scale) };
    let rhs_scaled = |t: T, y: &State<T>| -> State<T> {
        let unscaled = y.map(|v| v * rim);
        scaled(&rhs(t, &unscaled))
    };
    let watch_scaled = |t: T, y: &State<T>| watch(t, &y.map(|v| v * rim));
    let event: system::EventFn<T, 5> = rim_event;
    let run = match method {
        RollingMethod::Dp54 { rtol } => {
            let speed_scale = scene.combined_speed_rad_s().max(T::ONE);
            let atol = [
                rtol,
                rtol,
                rtol * speed_scale,
                rtol * speed_scale,
                rtol * speed_scale,
            ];
            let h0 = T::from_f64(1e-3) / speed_scale;
            system::dp54(
                rhs_scaled,
                T::ZERO,
                scaled(&y0),
                rtol,
                atol,
                h0,
                event,
                watch_scaled,
                limits,
            )
        }
        RollingMethod::Rk4 { step_s } => system::rk4(
            rhs_scaled,
            T::ZERO,
            scaled(&y0),
            step_s,
            event,
            watch_scaled,
            limits,
        ),
    }
    .map_err(RollingError::Integration)?;
    let outcome = match run.ended {
        Ended::Event { t, y } => RollingOutcome::Leaves {
            residence_time_s: t,
            exit_speed_m_s: (y[2] * y[2] + y[3] * y[3]).sqrt() * rim,
            max_friction_ratio: max_ratio,
            first_slip_s: first_slip,
        },
        Ended::Stopped { why, .. } => RollingOutcome::LiftsOff { time_s: why },
        Ended::Horizon { .. } => RollingOutcome::NotLeftBy {
            horizon_s: limits.horizon_s,
        },
    };
    Ok(RollingReport {
        outcome,
        evaluations: run.evaluations,
        steps: run.steps,
    })
}

/// Residence times over the release azimuths `beta = 0, 30, ..., 330` degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AzimuthSummary<T> {
    /// Mean over the releases that leave, s (`None` if none does).
    pub mean_s: Option<T>,
    /// Shortest, s.
    pub min_s: Option<T>,
    /// Longest, s.
    pub max_s: Option<T>,
    /// How many of the 12 releases leave.
    pub left: u32,
    /// How many of those slid on the way (rolling needed more friction than there is).
    pub slid: u32,
    /// How many lifted off the bottom (the normal force reached zero): the model ends there.
    pub lifted: u32,
    /// The largest friction ratio `|f_t| / N` rolling needed over the releases that left.
    pub max_friction_ratio: T,
    /// Right-hand-side evaluations of all 12.
    pub evaluations: u32,
}

/// The release azimuths of [`residence_over_azimuths`], degrees.
pub const AZIMUTHS_DEG: [f64; 12] = [
    0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0, 210.0, 240.0, 270.0, 300.0, 330.0,
];

/// [`residence`] at every azimuth of [`AZIMUTHS_DEG`].
pub fn residence_over_azimuths<T: Real>(
    scene: &RollingScene<T>,
    method: RollingMethod<T>,
) -> Result<AzimuthSummary<T>, RollingError> {
    over_azimuths_within(scene, method, default_limits())
}

/// [`residence_over_azimuths`] within the caller's horizon and step cap per release.
pub fn over_azimuths_within<T: Real>(
    scene: &RollingScene<T>,
    method: RollingMethod<T>,
    limits: SystemLimits<T>,
) -> Result<AzimuthSummary<T>, RollingError> {
    let mut tally = AzimuthTally::new();
    for deg in AZIMUTHS_DEG {
        let beta = T::from_f64(deg.to_radians());
        tally.add(&residence_within(scene, beta, method, limits)?);
    }
    Ok(tally.summary())
}

/// The summary of releases taken one report at a time: [`over_azimuths_within`]'s over the
/// twelve azimuths, and the PC's over any list of them (one summary, whichever releases).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AzimuthTally<T> {
    sum: T,
    min_s: Option<T>,
    max_s: Option<T>,
    left: u32,
    slid: u32,
    lifted: u32,
    max_ratio: T,
    evaluations: u32,
}

impl<T: Real> Default for AzimuthTally<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Real> AzimuthTally<T> {
    /// No releases yet.
    pub fn new() -> Self {
        Self {
            sum: T::ZERO,
            min_s: None,
            max_s: None,
            left: 0,
            slid: 0,
            lifted: 0,
            max_ratio: T::ZERO,
            evaluations: 0,
        }
    }

    /// One more release.
    pub fn add(&mut self, report: &RollingReport<T>) {
        self.evaluations = self.evaluations.saturating_add(report.evaluations);
        self.lifted += u32::from(matches!(report.outcome, RollingOutcome::LiftsOff { .. }));
        if let RollingOutcome::Leaves {
            residence_time_s: t,
            first_slip_s,
            max_friction_ratio,
            ..
        } = report.outcome
        {
            self.max_ratio = self.max_ratio.max(max_friction_ratio);
            self.sum += t;
            self.left += 1;
            self.slid += u32::from(first_slip_s.is_some());
            self.min_s = Some(self.min_s.map_or(t, |m| m.min(t)));
            self.max_s = Some(self.max_s.map_or(t, |m| m.max(t)));
        }
    }

    /// The summary of the releases added.
    pub fn summary(&self) -> AzimuthSummary<T> {
        AzimuthSummary {
            mean_s: (self.left > 0).then(|| self.sum / T::from_f64(f64::from(self.left))),
            min_s: self.min_s,
            max_s: self.max_s,
            left: self.left,
            slid: self.slid,
            lifted: self.lifted,
            max_friction_ratio: self.max_ratio,
            evaluations: self.evaluations,
        }
    }
}
