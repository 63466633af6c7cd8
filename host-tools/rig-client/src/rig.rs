//! The rig as the PC sees it: one method per command, typed arguments, typed answers (never
//! strings), all through the one request loop ([`crate::request`]). Frames that are not an
//! answer (telemetry, gate events, other tools' answers) are kept in [`Rig::arrived`] for the
//! caller.

use std::collections::VecDeque;
use std::time::Duration;

use model_core::wire::{
    AxisModel, Command, Frame, Injection, ParamId, ParamValues, Reason, ResidenceModel, Status,
};

use crate::lines::describe;
use crate::link::Link;
use crate::request::{Reader, Request, Unanswered, fresh_id, next_id, request};
use crate::serial::{LinkError, ReadOutcome};

/// What the rig said to a command it answered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reply<T> {
    /// Done, with what the answer carries.
    Done(T),
    /// Refused, and why.
    Refused(Reason),
}

/// No answer came in time (with what came instead).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NoAnswer {
    /// The command that was not answered.
    pub command: Command,
    /// What came meanwhile.
    pub unanswered: Unanswered,
}

impl std::fmt::Display for NoAnswer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "no answer to {} ({})",
            self.command.kind().token(),
            self.unanswered.advice()
        )
    }
}

impl std::error::Error for NoAnswer {}

/// A rig on a link, with the decoder of that link.
pub struct Rig {
    link: Link,
    reader: Reader,
    next_id: u16,
    timeout: Duration,
    /// Frames that arrived and were no answer of ours, oldest first.
    pub arrived: VecDeque<Frame>,
}

impl Rig {
    /// The rig on `link`; each command waits at most `timeout` for its answer.
    pub fn new(link: Link, timeout: Duration) -> Self {
        Self {
            link,
            reader: Reader::default(),
            next_id: fresh_id(),
            timeout,
            arrived: VecDeque::new(),
        }
    }

    /// Opens the rig's port (or the monitor's socket that shares it).
    pub fn open(port: &str, baud: u32, timeout: Duration) -> Result<Self, LinkError> {
        Link::open(port, baud).map(|link| Self::new(link, timeout))
    }

    /// Sends `command` and waits for its answer frame.
    pub fn command(&mut self, command: Command) -> anyhow::Result<Frame> {
        self.next_id = next_id(self.next_id);
        let mut req = Request::new(self.next_id, command).map_err(|r| {
            anyhow::anyhow!(
                "{} refused here: {}",
                command.kind().token(),
                crate::lines::explain(r)
            )
        })?;
        let arrived = &mut self.arrived;
        match request(
            &mut self.link,
            &mut self.reader,
            &mut req,
            self.timeout,
            &mut |f| arrived.push_back(f),
        )? {
            Ok(frame) => Ok(frame),
            Err(unanswered) => Err(NoAnswer {
                command,
                unanswered,
            }
            .into()),
        }
    }

    /// The device restarts seen on this link so far (a Hello frame, or the device clock
    /// starting again: the decoder's count), so a caller can tell that the rig reset meanwhile.
    pub fn restarts(&self) -> u64 {
        self.reader.decoder.stats().restarts
    }

    /// The particulars of the rig's refusal of `words` (the command as `bowl send` takes it),
    /// asking the rig what they need ([`crate::refusal::particulars`]); `None` when the
    /// reason's own words say it all.
    pub fn refusal_particulars(&mut self, words: &[&str], reason: Reason) -> Option<String> {
        self.next_id = next_id(self.next_id);
        let words: Vec<String> = words.iter().map(|w| (*w).to_string()).collect();
        crate::refusal::particulars(
            Some(&mut self.link),
            self.next_id,
            &words,
            reason,
            self.timeout,
        )
    }

    /// Reads for `wait`; what arrives goes to [`Rig::arrived`].
    pub fn listen(&mut self, wait: Duration) -> anyhow::Result<()> {
        let mut buf = [0u8; 4096];
        match self.link.read(&mut buf, wait)? {
            ReadOutcome::Data(n) => {
                for &b in &buf[..n] {
                    if let Some(crate::request::Arrival::Frame(f)) = self.reader.push(b) {
                        self.arrived.push_back(f);
                    }
                }
                Ok(())
            }
            ReadOutcome::Timeout => Ok(()),
            ReadOutcome::Gone => Err(self.link.gone().into()),
        }
    }

    /// A command answered by an acknowledgement.
    fn acked(&mut self, command: Command) -> anyhow::Result<Reply<()>> {
        match self.command(command)? {
            Frame::Reject { reason, .. } => Ok(Reply::Refused(reason)),
            Frame::Ack { .. } => Ok(Reply::Done(())),
            other => anyhow::bail!("{} answered {}", command.kind().token(), describe(&other)),
        }
    }

    /// SPEED: both motor setpoints, mrad/s.
    pub fn speed(&mut self, precession_mrad_s: i16, spin_mrad_s: i16) -> anyhow::Result<Reply<()>> {
        self.acked(Command::SetSpeeds {
            precession_mrad_s,
            spin_mrad_s,
        })
    }

    /// RTIME: the bowl speed for a residence time; the motor speeds the rig chose, mrad/s.
    pub fn rtime(
        &mut self,
        model: ResidenceModel,
        time_ms: u32,
    ) -> anyhow::Result<Reply<[i16; 2]>> {
        let command = Command::SetResidence { model, time_ms };
        match self.command(command)? {
            Frame::Reject { reason, .. } => Ok(Reply::Refused(reason)),
            Frame::ResidenceSet {
                precession_mrad_s,
                spin_mrad_s,
                ..
            } => Ok(Reply::Done([precession_mrad_s, spin_mrad_s])),
            other => anyhow::bail!("RTIME answered {}", describe(&other)),
        }
    }

    /// START.
    pub fn start(&mut self) -> anyhow::Result<Reply<()>> {
        self.acked(Command::Start)
    }

    /// STOP.
    pub fn stop(&mut self) -> anyhow::Result<Reply<()>> {
        self.acked(Command::Stop)
    }

    /// CLEAR: clear a fault.
    pub fn clear(&mut self) -> anyhow::Result<Reply<()>> {
        self.acked(Command::ClearFault)
    }

    /// SET: one parameter.
    pub fn set(&mut self, id: ParamId, value: i32) -> anyhow::Result<Reply<()>> {
        self.acked(Command::SetParam { id, value })
    }

    /// PING: the heartbeat.
    pub fn ping(&mut self) -> anyhow::Result<Reply<()>> {
        self.acked(Command::Ping)
    }

    /// RELEASE: drop one granule.
    pub fn release(&mut self) -> anyhow::Result<Reply<()>> {
        self.acked(Command::Release)
    }

    /// INJECT: make a simulated rig misbehave.
    pub fn inject(&mut self, what: Injection) -> anyhow::Result<Reply<()>> {
        self.acked(Command::Inject { what })
    }

    /// COMMISSION: start the motor identification.
    pub fn commission(&mut self) -> anyhow::Result<Reply<()>> {
        self.acked(Command::Commission)
    }

    /// STATUS.
    pub fn status(&mut self) -> anyhow::Result<Reply<Status>> {
        match self.command(Command::GetStatus)? {
            Frame::Reject { reason, .. } => Ok(Reply::Refused(reason)),
            Frame::Status { status, .. } => Ok(Reply::Done(status)),
            other => anyhow::bail!("STATUS answered {}", describe(&other)),
        }
    }

    /// PARAMS: every parameter's value.
    pub fn params(&mut self) -> anyhow::Result<Reply<ParamValues>> {
        match self.command(Command::GetParams)? {
            Frame::Reject { reason, .. } => Ok(Reply::Refused(reason)),
            Frame::Params { values, .. } => Ok(Reply::Done(values)),
            other => anyhow::bail!("PARAMS answered {}", describe(&other)),
        }
    }

    /// MODELS: the motor models and loop gains in force, per axis.
    pub fn models(&mut self) -> anyhow::Result<Reply<[AxisModel; 2]>> {
        match self.command(Command::GetModels)? {
            Frame::Reject { reason, .. } => Ok(Reply::Refused(reason)),
            Frame::Models { axes, .. } => Ok(Reply::Done(axes)),
            other => anyhow::bail!("MODELS answered {}", describe(&other)),
        }
    }
}
