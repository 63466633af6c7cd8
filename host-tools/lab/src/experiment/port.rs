//! `bowl experiment PLAN --port PORT`: the plan on a rig over its serial line (the real rig, the
//! virtual rig of `bowl serve --pty`, an emulated board). The same steps as on the simulated rig,
//! through the protocol: SPEED and START, wait until both measured speeds are within 2 % for a
//! second of device time and `settle_s` more, RELEASE, and the residence time from the rig's own
//! gate events (`E` frames: the exit's device time minus the release's, in the same boot). The
//! speed trace is the telemetry's measured combined bowl speed from the release on.
//!
//! Every frame is read by one decoder loop: a command's answer is waited for there, so no gate
//! event or telemetry frame that arrives meanwhile is lost.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow, bail};
use model_core::wire::{
    Decoder, DeviceState, Frame, GateEvent, GateKind, ParamId, ParamValues, Reason, Telemetry,
};

use super::ReleaseRig;
use super::simulated::Release;
use rig_client::lines::command_line;
use rig_client::link::{LineTap, Link, RESEND_EVERY, answers_kind};
use rig_client::serial::ReadOutcome;

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
    link: Link,
    decoder: Decoder,
    /// The raw line beside the decoder, to show an answer it cannot read.
    tap: LineTap,
    next_id: u16,
    latest: Option<Telemetry>,
    /// Telemetry since the last [`PortRig::take_telemetry`].
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
        let link = Link::open(port, baud).map_err(|e| anyhow!("{port}: {}", e.0))?;
        let mut rig = Self {
            link,
            decoder: Decoder::new(),
            tap: LineTap::default(),
            next_id: rig_client::link::fresh_id(),
            latest: None,
            fresh: Vec::new(),
            events: VecDeque::new(),
            last_ping: Instant::now(),
            params: [0; model_core::wire::PARAM_COUNT],
        };
        match rig.command(&["params"])? {
            Frame::Params { values, .. } => rig.params = values,
            other => bail!(
                "{port}: PARAMS answered {}",
                rig_client::lines::describe(&other)
            ),
        }
        // A faulted rig refuses every speed: say so once, before the plan starts.
        if let Frame::Status { status, .. } = rig.command(&["status"])?
            && status.state == model_core::wire::DeviceState::Faulted
        {
            bail!(
                "{port}: the rig is stopped by a fault ({}); check the rig, clear it with \
                 `bowl send {port} clear` and run the plan again",
                rig_client::words::fault(status.fault)
            );
        }
        Ok(rig)
    }

    /// Reads what the rig sent within `wait`: telemetry and gate events are kept; returns the
    /// answer to `id` of the kind `command` gets, if it came.
    fn pump(&mut self, wait: Duration, want: Option<(u16, &Frame)>) -> Result<Option<Frame>> {
        let mut buf = [0u8; 4096];
        let n = match self.link.read(&mut buf, wait).map_err(|e| anyhow!(e.0))? {
            ReadOutcome::Data(n) => n,
            ReadOutcome::Timeout => return Ok(None),
            ReadOutcome::Gone => bail!("the rig's port went away"),
        };
        let mut answer = None;
        for &b in &buf[..n] {
            self.tap.push(b);
            match self.decoder.push(b) {
                Some(Ok(Frame::Telemetry(t))) => {
                    self.latest = Some(t);
                    self.fresh.push(t);
                }
                Some(Ok(Frame::Event(e))) => self.events.push_back(e),
                Some(Ok(frame)) => {
                    if let Some((id, Frame::Command { command, .. })) = want
                        && frame.answer_id() == Some(id)
                        && answers_kind(command, &frame)
                    {
                        answer = Some(frame);
                    }
                }
                // Our answer, intact but unreadable here: said as it is, not waited out.
                Some(Err(e)) => {
                    if let (Some(u), Some((id, _))) = (self.tap.unreadable_answer(e), want)
                        && u.id == id
                    {
                        return Err(u.into());
                    }
                }
                None => {}
            }
        }
        Ok(answer)
    }

    /// Sends one command and waits for its answer (sent again every 200 ms with the same id,
    /// which the rig carries out once), reading everything else that arrives meanwhile.
    fn command(&mut self, words: &[&str]) -> Result<Frame> {
        self.next_id = self.next_id.wrapping_add(1);
        let id = self.next_id;
        let words: Vec<String> = words.iter().map(|w| w.to_string()).collect();
        let line = command_line(id, &words)
            .map_err(|r| anyhow!("{} refused locally ({})", words.join(" "), r.token()))?;
        let sent = match model_core::wire::decode_frame(&line) {
            Ok(f) => f,
            Err(_) => bail!("{} is not a command line (a bug in bowl)", words.join(" ")),
        };
        let end = Instant::now() + ANSWER_TIMEOUT;
        while Instant::now() < end {
            self.link.write_all(&line).map_err(|e| anyhow!(e.0))?;
            let resend = Instant::now() + RESEND_EVERY;
            while let Some(left) = resend.checked_duration_since(Instant::now()) {
                if let Some(answer) =
                    self.pump(left.min(Duration::from_millis(20)), Some((id, &sent)))?
                {
                    return Ok(answer);
                }
            }
        }
        bail!(
            "no answer to {} within {} s",
            words.join(" "),
            ANSWER_TIMEOUT.as_secs()
        )
    }

    /// Reads for `wait`, keeping the link alive.
    fn listen(&mut self, wait: Duration) -> Result<()> {
        if self.last_ping.elapsed() >= PING_EVERY {
            self.last_ping = Instant::now();
            self.command(&["ping"])?;
        }
        self.pump(wait, None)?;
        Ok(())
    }

    /// A fault the rig reports, in words (and cleared, so the next release may run).
    fn fault(&mut self) -> Result<Option<String>> {
        match self.latest {
            Some(t) if t.state == DeviceState::Faulted => {
                let words = rig_client::words::fault(t.fault).to_string();
                self.command(&["clear"])?;
                self.latest = None;
                Ok(Some(words))
            }
            _ => Ok(None),
        }
    }

    fn settle_inner(&mut self, targets: [f64; 2], settle_s: f64) -> Result<Result<(), Release>> {
        let mrad = |w: f64| format!("{}", (w * 1000.0).round() as i64);
        let (p, s) = (mrad(targets[0]), mrad(targets[1]));
        if let Frame::Reject { reason, .. } = self.command(&["speed", &p, &s])? {
            return Ok(Err(Release::MotorFault(format!(
                "speeds {:.3}, {:.3} rad/s refused: {}",
                targets[0],
                targets[1],
                rig_client::lines::explain(reason)
            ))));
        }
        if self.latest.is_none_or(|t| t.state != DeviceState::Running)
            && let Frame::Reject { reason, .. } = self.command(&["start"])?
        {
            return Ok(Err(Release::MotorFault(format!(
                "START refused: {}",
                rig_client::lines::explain(reason)
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
        if let Frame::Reject { reason, .. } = self.command(&["release"])? {
            let why = match reason {
                Reason::Unsupported => "the rig has no release solenoid".to_string(),
                other => rig_client::lines::explain(other).to_string(),
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
                        let residence_s = f64::from(e.time_us.wrapping_sub(r.time_us)) * 1e-6;
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
        let angle = param(&self.params, ParamId::AxesMdeg) * 1e-3 * std::f64::consts::PI / 180.0;
        let ratio = param(&self.params, ParamId::RatioPpm) * 1e-6;
        let s = model_core::control::planner::split_combined(
            bowl_rad_s as f32,
            angle.cos() as f32,
            angle.sin() as f32,
            ratio as f32,
        )
        .ok_or_else(|| anyhow!("bowl speed {bowl_rad_s} rad/s cannot be split"))?;
        Ok([f64::from(s[0]), f64::from(s[1])])
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
        let _ = self.command(&["stop"]);
    }
}
