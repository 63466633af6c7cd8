//! Wire parameters to the controller's configuration and the particle scene.
//!
//! Each parameter's row in [`crate::wire::params`] gives its token, unit, range and default;
//! [`ParamRole::of`] says what it configures:
//! - `RIM_UM`, `START_UM`, `MU_PPM`, `K2_PPM`: the particle scene ([`scene_from_params`]) for
//!   `RTIME` and the predicted residence times (paper Eq. 6/7 flat, Eq. 10/11 with the
//!   corrected coefficients of docs/model.md) at the controller's combined bowl speed (paper
//!   Eq. 2);
//! - `AXES_MDEG`: `axes_angle_rad` (paper Eq. 2); `RATIO_PPM`: `spin_per_precession`;
//! - per axis n: `BWn_MRAD_S` `bandwidth_rad_s`, `PER_PULSEn_MILLI` `per_pulse_bandwidth`
//!   (both changeable while running, bumpless), `SPEED_MAXn_MRAD_S` `max_speed_rad_s` (the
//!   over-speed fault limit follows at [`OVERSPEED_PER_MAX`] times it), `ACCELn_MRAD_S2`
//!   `accel_limit_rad_s2`, `DUTY_MAXn_BP` `duty_limit`, `TEETHn` `pulses_per_rev` (these only
//!   while idle or faulted);
//! - `TELEM_HZ`: the protocol device's telemetry rate (the device owns it);
//! - `RT_W_LO_MRAD_S`, `RT_W_HI_MRAD_S`, `RT_T1_US`..`RT_T8_US`: the residence-time table the PC
//!   computed with the chosen model ([`table_from_params`], `RTIME TABLE`), any time.
//! - `CUR_SENSE`: whether the board passes its current samples to the controller (idle or
//!   faulted: the current watch learns its offset at zero duty).

use super::AXES;
use crate::Real;
use crate::control::{AxisConfig, ControllerConfig, MotorModel};
use crate::particle::Scene;
use crate::particle::speed_table::{SPEED_TABLE_LEN, SpeedTable};
use crate::wire::{ParamId, ParamValues, Reason};

/// Over-speed fault limit as a multiple of `SPEED_MAX` (the nominal 5.5 / 4.0 rad/s).
pub const OVERSPEED_PER_MAX: f32 = 1.375;

/// The parameter values a new board starts with (wire units, wire order): the table's
/// defaults.
pub fn default_params() -> ParamValues {
    ParamId::defaults()
}

/// One setting of a motor axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisSetting {
    /// `bandwidth_rad_s`, from mrad/s.
    Bandwidth,
    /// `per_pulse_bandwidth`, from 1/1000.
    PerPulseBandwidth,
    /// `max_speed_rad_s` (and the over-speed limit), from mrad/s.
    MaxSpeed,
    /// `accel_limit_rad_s2`, from mrad/s^2.
    AccelLimit,
    /// `duty_limit`, from basis points.
    DutyLimit,
    /// `pulses_per_rev`, from teeth.
    PulsesPerRev,
}

/// What a parameter configures, and so when it may change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamRole {
    /// The particle scene: feeds RTIME and the predictions only, so any time.
    Scene,
    /// The angle between the axes (paper Eq. 2): rebuilds the controller (idle or faulted).
    AxesAngle,
    /// The spin per precession split ratio: rebuilds the controller (idle or faulted).
    SplitRatio,
    /// A motor axis's setting: loop tuning changes while running (bumpless), the rest
    /// rebuilds the controller (idle or faulted).
    Axis(usize, AxisSetting),
    /// The telemetry rate: the protocol device's, never the controller's.
    TelemetryRate,
    /// The host link silence timeout: rebuilds the controller (idle or faulted).
    LinkTimeout,
    /// The residence-time table (`RTIME TABLE`): like the scene, any time.
    ResidenceTable,
    /// Whether the board's current samples reach the controller (idle or faulted).
    CurrentSense,
}

impl ParamRole {
    /// Whether SET may change it while the motors run (the scene, the residence-time table,
    /// the telemetry rate and the loop tuning); the rest rebuilds the controller, so idle or
    /// faulted only.
    pub const fn changes_while_running(self) -> bool {
        matches!(
            self,
            ParamRole::Scene
                | ParamRole::TelemetryRate
                | ParamRole::ResidenceTable
                | ParamRole::Axis(_, AxisSetting::Bandwidth | AxisSetting::PerPulseBandwidth)
        )
    }

    /// The role of `id`. A new parameter needs its line here (the match is exhaustive).
    pub const fn of(id: ParamId) -> Self {
        use AxisSetting as S;
        use ParamId as P;
        match id {
            P::RimUm | P::StartUm | P::MuPpm | P::K2Ppm => ParamRole::Scene,
            P::AxesMdeg => ParamRole::AxesAngle,
            P::RatioPpm => ParamRole::SplitRatio,
            P::Bandwidth1MradS => ParamRole::Axis(0, S::Bandwidth),
            P::Bandwidth2MradS => ParamRole::Axis(1, S::Bandwidth),
            P::PerPulse1Milli => ParamRole::Axis(0, S::PerPulseBandwidth),
            P::PerPulse2Milli => ParamRole::Axis(1, S::PerPulseBandwidth),
            P::SpeedMax1MradS => ParamRole::Axis(0, S::MaxSpeed),
            P::SpeedMax2MradS => ParamRole::Axis(1, S::MaxSpeed),
            P::Accel1MradS2 => ParamRole::Axis(0, S::AccelLimit),
            P::Accel2MradS2 => ParamRole::Axis(1, S::AccelLimit),
            P::DutyMax1Bp => ParamRole::Axis(0, S::DutyLimit),
            P::DutyMax2Bp => ParamRole::Axis(1, S::DutyLimit),
            P::Teeth1 => ParamRole::Axis(0, S::PulsesPerRev),
            P::Teeth2 => ParamRole::Axis(1, S::PulsesPerRev),
            P::TelemetryHz => ParamRole::TelemetryRate,
            P::LinkTimeoutMs => ParamRole::LinkTimeout,
            P::RtSpeedLoMradS
            | P::RtSpeedHiMradS
            | P::RtTime1Us
            | P::RtTime2Us
            | P::RtTime3Us
            | P::RtTime4Us
            | P::RtTime5Us
            | P::RtTime6Us
            | P::RtTime7Us
            | P::RtTime8Us => ParamRole::ResidenceTable,
            P::CurrentSense => ParamRole::CurrentSense,
        }
    }
}

/// The particle scene of a set of wire parameters (`omega_rad_s` 0: the bowl speed is the
/// controller's), or [`Reason::Range`] if the scene is invalid or the start radius is not
/// inside the rim. Gravity is the particle model's default scene's. The one mapping from wire
/// parameters to a scene: the rig's predictions and the host's re-checks both use it.
pub fn scene_from_params<R: Real>(params: &ParamValues) -> Result<Scene<R>, Reason> {
    let p = |id: ParamId| R::from_f64(f64::from(params[id.index()]));
    let micro = R::from_f64(1e-6);
    let scene = Scene {
        omega_rad_s: R::ZERO,
        mu: p(ParamId::MuPpm) * micro,
        g_m_s2: Scene::<R>::default().g_m_s2,
        k2: p(ParamId::K2Ppm) * micro,
        ri_m: p(ParamId::StartUm) * micro,
        rim_radius_m: p(ParamId::RimUm) * micro,
    };
    if scene.validate_except_omega().is_err() || scene.ri_m >= scene.rim_radius_m {
        return Err(Reason::Range);
    }
    Ok(scene)
}

fn apply_axis(a: &mut AxisConfig, setting: AxisSetting, value: i32) -> Result<(), Reason> {
    // Divided, not multiplied by 1e-3: the quotient is the f32 nearest the decimal, the same
    // as the controller's limit literals, so a range's end (10 mrad/s^2 = 0.01, 500 bp =
    // 0.05) passes the controller's check instead of falling a rounding short of it.
    let x = value as f32;
    let milli = x / 1000.0;
    match setting {
        AxisSetting::Bandwidth => a.bandwidth_rad_s = milli,
        AxisSetting::PerPulseBandwidth => a.per_pulse_bandwidth = milli,
        AxisSetting::MaxSpeed => {
            a.max_speed_rad_s = milli;
            a.overspeed_rad_s = a.max_speed_rad_s * OVERSPEED_PER_MAX;
        }
        AxisSetting::AccelLimit => a.accel_limit_rad_s2 = milli,
        AxisSetting::DutyLimit => a.duty_limit = x / 10_000.0,
        AxisSetting::PulsesPerRev => {
            a.pulses_per_rev = u16::try_from(value).map_err(|_| Reason::Range)?
        }
    }
    Ok(())
}

/// The controller configuration for a set of wire parameters: `base` supplies what the wire
/// does not carry (tick rate, timer, supervisor limits, motor models), or why they do not fit.
pub fn config_from_params(
    base: &ControllerConfig,
    params: &ParamValues,
) -> Result<ControllerConfig, Reason> {
    let mut cfg = *base;
    for id in ParamId::ALL {
        let value = params[id.index()];
        match ParamRole::of(id) {
            ParamRole::Scene
            | ParamRole::TelemetryRate
            | ParamRole::ResidenceTable
            | ParamRole::CurrentSense => {}
            ParamRole::AxesAngle => cfg.axes_angle_rad = (value as f32 * 1e-3).to_radians(),
            ParamRole::SplitRatio => cfg.spin_per_precession = value as f32 * 1e-6,
            ParamRole::LinkTimeout => cfg.host_timeout_s = value as f32 / 1000.0,
            ParamRole::Axis(axis, setting) => {
                let a = cfg.axes.get_mut(axis).ok_or(Reason::Internal)?;
                apply_axis(a, setting, value)?;
            }
        }
    }
    cfg.validate().map_err(|_| Reason::Range)?;
    Ok(cfg)
}

/// `base` with these motor models.
pub(crate) fn with_models(
    base: &ControllerConfig,
    models: &[MotorModel; AXES],
) -> ControllerConfig {
    let mut cfg = *base;
    for (a, m) in cfg.axes.iter_mut().zip(models) {
        a.model = *m;
    }
    cfg
}

/// The residence-time table's parameters in wire order: the two speeds, then the eight times.
pub const TABLE_PARAMS: [ParamId; 2 + SPEED_TABLE_LEN] = [
    ParamId::RtSpeedLoMradS,
    ParamId::RtSpeedHiMradS,
    ParamId::RtTime1Us,
    ParamId::RtTime2Us,
    ParamId::RtTime3Us,
    ParamId::RtTime4Us,
    ParamId::RtTime5Us,
    ParamId::RtTime6Us,
    ParamId::RtTime7Us,
    ParamId::RtTime8Us,
];

/// The residence-time table the parameters hold: `Ok(None)` while it is off
/// (`RT_W_HI_MRAD_S` not above `RT_W_LO_MRAD_S`, so a PC writing a table sets the fastest
/// speed last), [`Reason::Range`] when it is on and a time is 0.
pub fn table_from_params(params: &ParamValues) -> Result<Option<SpeedTable>, Reason> {
    let p = |id: ParamId| params[id.index()];
    let (lo, hi) = (p(ParamId::RtSpeedLoMradS), p(ParamId::RtSpeedHiMradS));
    if hi <= lo {
        return Ok(None);
    }
    let mut times = [0.0f32; SPEED_TABLE_LEN];
    for (slot, id) in times.iter_mut().zip(&TABLE_PARAMS[2..]) {
        *slot = p(*id) as f32 * 1e-6;
    }
    SpeedTable::new(lo as f32 * 1e-3, hi as f32 * 1e-3, times)
        .map(Some)
        .map_err(|_| Reason::Range)
}

/// The wire values of a table (speeds rounded to mrad/s, times to us), in [`TABLE_PARAMS`]
/// order, or [`Reason::Range`] if one is outside its parameter's range (a time over 8 s).
pub fn table_to_params(table: &SpeedTable) -> Result<[i32; 2 + SPEED_TABLE_LEN], Reason> {
    let (lo, hi) = table.speed_range_rad_s();
    let mut out = [0i32; 2 + SPEED_TABLE_LEN];
    let values = [lo * 1e3, hi * 1e3]
        .into_iter()
        .chain(table.residence_s().iter().map(|t| t * 1e6));
    for ((slot, id), x) in out.iter_mut().zip(TABLE_PARAMS).zip(values) {
        let (min, max) = id.range();
        let v = libm::roundf(x);
        if !(v >= min as f32 && v <= max as f32) {
            return Err(Reason::Range);
        }
        *slot = v as i32;
    }
    Ok(out)
}

/// Controller configuration and scene for a set of wire parameters, or why they do not fit
/// (the residence-time table too, when it is on).
pub(crate) fn derive(
    base: &ControllerConfig,
    params: &ParamValues,
) -> Result<(ControllerConfig, Scene<f32>), Reason> {
    let scene = scene_from_params(params)?;
    table_from_params(params)?;
    Ok((config_from_params(base, params)?, scene))
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use crate::wire::device::DEFAULT_TELEMETRY_HZ;

    /// SET's meaning (the command table, rendered into docs/protocol.md and the refusals'
    /// reader) names every parameter a running rig takes, by name or as its group (`BWn_MRAD_S`,
    /// `RT_*`): it left the residence-time table out, so it read as idle-only.
    #[test]
    fn set_names_every_parameter_it_takes_while_running() {
        use std::string::String;
        let meaning = crate::wire::CommandKind::SetParam.meaning();
        for id in ParamId::ALL {
            if !ParamRole::of(id).changes_while_running() {
                continue;
            }
            let token = id.token();
            let group: String = token
                .chars()
                .map(|c| if c.is_ascii_digit() { 'n' } else { c })
                .collect();
            let named = meaning.contains(token)
                || meaning.contains(&group)
                || (token.starts_with("RT_") && meaning.contains("`RT_*`"));
            assert!(named, "{token} not named in SET's meaning: {meaning}");
        }
    }

    /// The table's defaults are the controller's nominal configuration and the particle
    /// model's default scene in wire units (computed here from those, independently).
    #[test]
    fn table_defaults_are_the_nominal_configuration_and_default_scene() {
        let cfg = ControllerConfig::nominal();
        let scene = Scene::<f32>::default();
        let milli = |x: f32| libm::roundf(x * 1000.0) as i32;
        let micro = |x: f32| libm::roundf(x * 1e6) as i32;
        let (a, b) = (&cfg.axes[0], &cfg.axes[1]);
        let expected = [
            micro(scene.rim_radius_m),
            micro(scene.ri_m),
            micro(scene.mu),
            micro(scene.k2),
            milli(cfg.axes_angle_rad.to_degrees()),
            milli(a.bandwidth_rad_s),
            milli(b.bandwidth_rad_s),
            milli(a.per_pulse_bandwidth),
            milli(b.per_pulse_bandwidth),
            milli(a.max_speed_rad_s),
            milli(b.max_speed_rad_s),
            milli(a.accel_limit_rad_s2),
            milli(b.accel_limit_rad_s2),
            libm::roundf(a.duty_limit * 10_000.0) as i32,
            libm::roundf(b.duty_limit * 10_000.0) as i32,
            i32::from(a.pulses_per_rev),
            i32::from(b.pulses_per_rev),
            micro(cfg.spin_per_precession),
            i32::from(DEFAULT_TELEMETRY_HZ),
            // The rig's link-loss timeout is on (3 s) by default; the controller's own
            // default is off so the closed-loop simulations need no heartbeat.
            3_000,
            // No residence-time table: speeds 0, times 0.
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            0,
            // Pulses only until the board is said to measure its currents.
            0,
        ];
        assert_eq!(default_params(), expected);
        let derived = config_from_params(&cfg, &default_params()).expect("defaults pass");
        assert_eq!(derived.axes[0].overspeed_rad_s, cfg.axes[0].overspeed_rad_s);
        assert_eq!(derived.axes[1].pulses_per_rev, cfg.axes[1].pulses_per_rev);
        assert_eq!(derived.host_timeout_s, 3.0);
    }

    /// One scene mapping for f32 (the rig) and f64 (the host's re-check): the same scene to
    /// f32 precision, gravity the default scene's.
    #[test]
    fn scene_from_params_agrees_in_f32_and_f64_and_refuses_a_start_beyond_the_rim() {
        let mut p = default_params();
        let s32: Scene<f32> = scene_from_params(&p).unwrap();
        let s64: Scene<f64> = scene_from_params(&p).unwrap();
        assert_eq!(s64.g_m_s2, 9.81);
        assert_eq!(s32.g_m_s2, 9.81f32);
        assert!((f64::from(s32.mu) - s64.mu).abs() <= 1e-7 * s64.mu);
        assert!((s64.rim_radius_m - 0.1).abs() < 1e-15);
        assert!((s64.ri_m - 0.05).abs() < 1e-15);
        assert!((s64.k2 - 0.714_286).abs() < 1e-15);
        p[ParamId::StartUm.index()] = p[ParamId::RimUm.index()];
        assert_eq!(scene_from_params::<f64>(&p), Err(Reason::Range));
        p[ParamId::StartUm.index()] = 0;
        p[ParamId::K2Ppm.index()] = 0;
        assert_eq!(scene_from_params::<f32>(&p), Err(Reason::Range));
    }

    /// The wire range of every controller parameter is what the controller accepts: both ends
    /// of each range pass (with the others at their defaults), and the speed limit's lower
    /// end is tight (one step below it the controller refuses). A QA pass found SPEED_MAX 200,
    /// ACCEL 1..9 and DUTY_MAX 500 inside their wire ranges yet refused, with no limit to show.
    #[test]
    fn every_controller_parameters_wire_range_is_what_the_controller_accepts() {
        let cfg = ControllerConfig::nominal();
        for id in ParamId::ALL {
            if matches!(
                ParamRole::of(id),
                ParamRole::Scene | ParamRole::TelemetryRate | ParamRole::ResidenceTable
            ) {
                continue;
            }
            let (lo, hi) = id.range();
            for value in [lo, hi] {
                let mut p = default_params();
                p[id.index()] = value;
                assert!(
                    config_from_params(&cfg, &p).is_ok(),
                    "{} = {value} is inside its wire range but refused",
                    id.token()
                );
            }
        }
        for id in [ParamId::SpeedMax1MradS, ParamId::SpeedMax2MradS] {
            let mut p = default_params();
            p[id.index()] = id.range().0 - 1;
            assert_eq!(config_from_params(&cfg, &p), Err(Reason::Range));
        }
    }
}
