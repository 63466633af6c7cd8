//! `bowl experiment PLAN --port PORT`: the plan on a rig over its serial line (the real rig, the
//! virtual rig of `bowl serve --pty`, an emulated board). The same steps as on the simulated rig,
//! through the protocol: SPEED and START, wait until both measured speeds are within 2 % for a
//! second of device time and `settle_s` more, RELEASE, and the residence time from the rig's own
//! gate events (`E` frames: the exit's device time minus the release's, in the same boot). The
//! speed trace is the telemetry's measured combined bowl speed from the release on.
//!
//! Every command goes through the rig client's typed [`Rig`] and its one request loop; the gate
//! events and telemetry frames that arrive while a command waits are kept, none is lost.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow, bail};
use model_core::wire::{
    DeviceState, Frame, GateEvent, GateKind, ParamId, ParamValues, Reason, Telemetry,
};
use rig_client::lines::explain;
use rig_client::rig::{Reply, Rig};

use super::ReleaseRig;
use super::simulated::Release;

/// A speed counts as settled within this fraction of its target (or 0.02 rad/s)...
const SETTLED_BAND: f64 = 0.02;
/// ...held for this long of device time, ms.
const SETTLED_HOLD_MS: u32 = 1000;
/// Give up waiting for the speeds after this long.
const SETTLE_TIMEOUT: Duration = Duration::from_secs(30);
/// Give up on a granule after this long in the bowl.
const RESIDENCE_TIMEOUT: Duration = Duration::from_secs(60);
/// Give up on an answer after this long.
const ANSWER_TIMEOUT: Duration = Duration::from_secs(3);
/// Heartbeat period (well inside the rig's default link-loss timeout).
const PING_EVERY: Duration = Duration::from_secs(1);

/// A rig on a serial line.
pub struct PortRig {
    rig: Rig,
    latest: Option<Telemetry>,
    /// Telemetry since it was last taken.
    fresh: Vec<Telemetry>,
    events: VecDeque<GateEvent>,
    last_ping: Instant,
    params: ParamValues,
}

fn param(p: &ParamValues, id: ParamId) -> f64 {
    f64::from(p[id.index()])
}

impl PortRig {
    /// Opens the port and reads the rig's parameters (the geometry and the speed split).
    pub fn open(port: &str, baud: u32) -> Result<Self> {
        let rig = Rig::open(port, baud, ANSWER_TIMEOUT).map_err(|e| anyhow!("{port}: {}", e.0))?;
        let mut rig = Self {
            rig,
            latest: None,
            fresh: Vec::new(),
            events: VecDeque::new(),
            last_ping: Instant::now(),
            params: [0; model_core::wire::PARAM_COUNT],
        };
        match rig.command(Rig::params)? {
            Reply::Done(values) => rig.params = values,
            Reply::Refused(reason) => bail!("{port}: PARAMS refused: {}", explain(reason)),
        }
        // A faulted rig refuses every speed: say so once, before the plan starts.
        if let Reply::Done(status) = rig.command(Rig::status)?
            && status.state == DeviceState::Faulted
        {
            bail!(
                "{port}: the rig is stopped by a fault ({}); check the rig, clear it with \
                 `bowl send {port} clear` and run the plan again",
                status.fault.words()
            );
        }
        Ok(rig)
    }

    /// One command through the rig client's request loop (sent again every 200 ms with the
    /// same id, which the rig carries out once); the telemetry and gate events that arrived
    /// meanwhile are kept.
    fn command<T>(
        &mut self,
        command: impl FnOnce(&mut Rig) -> Result<Reply<T>>,
    ) -> Result<Reply<T>> {
        let reply = command(&mut self.rig);
        self.sort_arrived();
        reply
    }

    /// Telemetry and gate events from what arrived; other frames are not ours.
    fn sort_arrived(&mut self) {
        while let Some(frame) = self.rig.arrived.pop_front() {
            match frame {
                Frame::Telemetry(t) => {
                    self.latest = Some(t);
                    self.fresh.push(t);
                }
                Frame::Event(e) => self.events.push_back(e),
                _ => {}
            }
        }
    }

    /// Reads for `wait`, keeping the link alive.
    fn listen(&mut self, wait: Duration) -> Result<()> {
        if self.last_ping.elapsed() >= PING_EVERY {
            self.last_ping = Instant::now();
            self.command(Rig::ping)?;
        }
        self.rig.listen(wait)?;
        self.sort_arrived();
        Ok(())
    }

    /// A fault the rig reports, in words (and cleared, so the next release may run).
    fn fault(&mut self) -> Result<Option<String>> {
        let Some(words) = self
            .latest
            .and_then(|t| super::reported_fault(t.state, t.fault))
        else {
            return Ok(None);
        };
        self.command(Rig::clear)?;
        self.latest = None;
        Ok(Some(words))
    }

    fn settle_inner(&mut self, targets: [f64; 2], settle_s: f64) -> Result<Result<(), Release>> {
        let mrad = |w: f64| i16::try_from((w * 1000.0).round() as i64);
        let refused = |reason: Reason| {
            Release::MotorFault(format!(
                "speeds {:.3}, {:.3} rad/s refused: {}",
                targets[0],
                targets[1],
                explain(reason)
            ))
        };
        let (Ok(p), Ok(s)) = (mrad(targets[0]), mrad(targets[1])) else {
            return Ok(Err(refused(Reason::Range)));
        };
        if let Reply::Refused(reason) = self.command(|rig| rig.speed(p, s))? {
            return Ok(Err(refused(reason)));
        }
        if self.latest.is_none_or(|t| t.state != DeviceState::Running)
            && let Reply::Refused(reason) = self.command(Rig::start)?
        {
            return Ok(Err(Release::MotorFault(format!(
                "START refused: {}",
                explain(reason)
            ))));
        }
        let started = Instant::now();
        let mut held_since: Option<u32> = None;
        loop {
            self.listen(Duration::from_millis(20))?;
            if let Some(f) = self.fault()? {
                return Ok(Err(Release::MotorFault(f)));
            }
            for t in std::mem::take(&mut self.fresh) {
                let within = |measured: i16, target: f64| {
                    (f64::from(measured) * 1e-3 - target).abs()
                        <= (SETTLED_BAND * target.abs()).max(0.02)
                };
                let ok = within(t.precession.measured_mrad_s, targets[0])
                    && within(t.spin.measured_mrad_s, targets[1]);
                held_since = if ok {
                    held_since.or(Some(t.time_ms))
                } else {
                    None
                };
                if held_since.is_some_and(|at| t.time_ms.wrapping_sub(at) >= SETTLED_HOLD_MS) {
                    let until = Instant::now() + Duration::from_secs_f64(settle_s.max(0.0));
                    while Instant::now() < until {
                        self.listen(Duration::from_millis(20))?;
                    }
                    return Ok(Ok(()));
                }
            }
            if started.elapsed() > SETTLE_TIMEOUT {
                return Ok(Err(Release::NotSettled));
            }
        }
    }

    fn release_inner(&mut self) -> Result<Release> {
        self.events.clear();
        self.fresh.clear();
        if let Reply::Refused(reason) = self.command(Rig::release)? {
            let why = match reason {
                Reason::Unsupported => "the rig has no release solenoid".to_string(),
                other => explain(other).to_string(),
            };
            return Ok(Release::MotorFault(format!("RELEASE refused: {why}")));
        }
        let started = Instant::now();
        let mut released: Option<GateEvent> = None;
        let mut samples: Vec<Telemetry> = Vec::new();
        let trace = |samples: &[Telemetry], at: &GateEvent| -> Vec<(f64, f64)> {
            samples
                .iter()
                .map(|t| {
                    let t_s = (f64::from(t.time_ms) * 1e3 - f64::from(at.time_us)) * 1e-6;
                    (t_s, f64::from(t.bowl_mrad_s) * 1e-3)
                })
                .filter(|(t_s, _)| *t_s >= -0.02)
                .collect()
        };
        while started.elapsed() < RESIDENCE_TIMEOUT {
            self.listen(Duration::from_millis(20))?;
            samples.append(&mut self.fresh);
            if let Some(f) = self.fault()? {
                return Ok(Release::MotorFault(f));
            }
            while let Some(e) = self.events.pop_front() {
                match (e.kind, released) {
                    (GateKind::Release, _) => released = Some(e),
                    (GateKind::Exit, Some(r)) if r.boot == e.boot => {
                        let residence_s = f64::from(e.time_us.wrapping_sub(r.time_us)) / 1e6;
                        return Ok(Release::Left(residence_s, trace(&samples, &r)));
                    }
                    // An exit without a release before it in this boot: not this granule.
                    (GateKind::Exit, _) => {}
                }
            }
        }
        Ok(Release::NeverLeft(
            released.map_or(Vec::new(), |r| trace(&samples, &r)),
        ))
    }
}

impl ReleaseRig for PortRig {
    fn geometry(&self) -> (f64, f64, f64) {
        (
            // Divided, not multiplied by 1e-6: 50000 um is 0.05 m, not 0.049999999999999996.
            param(&self.params, ParamId::StartUm) / 1e6,
            param(&self.params, ParamId::RimUm) / 1e6,
            param(&self.params, ParamId::K2Ppm) / 1e6,
        )
    }

    fn split(&self, bowl_rad_s: f64) -> Result<[f64; 2]> {
        let angle = self.axes_angle_rad();
        let ratio = param(&self.params, ParamId::RatioPpm) * 1e-6;
        let s = model_core::control::planner::split_combined(
            bowl_rad_s as f32,
            angle.cos() as f32,
            angle.sin() as f32,
            ratio as f32,
        )
        .ok_or_else(|| anyhow!("bowl speed {bowl_rad_s} rad/s cannot be split"))?;
        Ok(s.map(crate::number::from_f32))
    }

    fn settle(&mut self, targets: [f64; 2], settle_s: f64) -> Result<(), Release> {
        self.settle_inner(targets, settle_s)
            .unwrap_or_else(|e| Err(Release::MotorFault(format!("link: {e:#}"))))
    }

    fn release(&mut self) -> Release {
        self.release_inner()
            .unwrap_or_else(|e| Release::MotorFault(format!("link: {e:#}")))
    }

    fn stop(&mut self) {
        let _ = self.command(Rig::stop);
    }

    /// The limits the rig's parameters configure (as the speed range reads them).
    fn max_speeds_rad_s(&self) -> Option<[f64; 2]> {
        let cfg = model_core::binding::config_from_params(
            &model_core::control::ControllerConfig::default(),
            &self.params,
        )
        .ok()?;
        Some([0, 1].map(|i| f64::from(cfg.axes[i].max_speed_rad_s)))
    }

    /// The rig's AXES_MDEG parameter.
    fn axes_angle_rad(&self) -> f64 {
        super::axes_angle_rad(param(&self.params, ParamId::AxesMdeg))
    }
}
