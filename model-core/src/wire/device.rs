//! The rig's side of the protocol: answer every command, pace the telemetry. No heap, no
//! hardware: the firmware and the virtual rig both drive a [`Device`] over their own [`Backend`]
//! (what the protocol needs from the controller).

use super::FRAME_START;
use super::commands::Command;
use super::console::ConsoleLine;
use super::decode::FrameError;
use super::encode::{EncodeError, encode};
use super::frame::Frame;
use super::params::{PARAM_COUNT, ParamId, ParamValues};
use super::stream::Decoder;
use super::types::{
    AxisModel, GateEvent, Hello, Injection, Reason, ResidenceModel, Status, Telemetry,
};
use super::{MAX_FRAME_LEN, max_telemetry_hz};

/// What RTIME chose: the model that answered and the motor setpoints, mrad/s.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ResidenceChoice {
    /// The model that answered.
    pub model: ResidenceModel,
    /// Precession setpoint, mrad/s.
    pub precession_mrad_s: i16,
    /// Spin setpoint, mrad/s.
    pub spin_mrad_s: i16,
}

/// What the protocol needs from the controller, in wire units. Every setter either applies the
/// whole change and returns `Ok`, or changes nothing and returns the reason.
pub trait Backend {
    /// The current values for a telemetry frame (the `seq` field is overwritten by [`Device`]).
    fn telemetry(&self) -> Telemetry;
    /// Why and how often the device has reset.
    fn reset_info(&self) -> Hello;
    /// Board conditions for STATUS (`status_flags` bits); none by default.
    fn status_flags(&self) -> u8 {
        0
    }
    /// New motor setpoints, mrad/s; [`Device`] has already checked each against 0..=its SPEED_MAX.
    fn set_speeds(&mut self, precession_mrad_s: i16, spin_mrad_s: i16) -> Result<(), Reason>;
    /// Choose the setpoints whose predicted residence time is `time_ms`; says which model
    /// answered and the setpoints it chose.
    fn set_residence(
        &mut self,
        model: ResidenceModel,
        time_ms: u32,
    ) -> Result<ResidenceChoice, Reason>;
    /// Run the motors towards the setpoints.
    fn start(&mut self) -> Result<(), Reason>;
    /// Ramp the motors down. Always possible.
    fn stop(&mut self);
    /// Leave the fault state (motors stay off).
    fn clear_fault(&mut self) -> Result<(), Reason>;
    /// Set one parameter (never [`ParamId::TelemetryHz`]: [`Device`] owns that one); the value
    /// is inside [`ParamId::range`].
    fn set_param(&mut self, id: ParamId, value: i32) -> Result<(), Reason>;
    /// The current value of a parameter (never asked for [`ParamId::TelemetryHz`]).
    fn param(&self, id: ParamId) -> i32;
    /// [`Device`] took a new telemetry rate (it owns the rate, but a backend that saves the
    /// parameters saves the rate with them, so it must hear of a change to it alone).
    fn telemetry_hz_set(&mut self, hz: u8) {
        let _ = hz;
    }
    /// The PC is there: called for every command that arrives intact (its CRC checks out),
    /// before it is answered, whatever the answer (a query, a refusal, a copy, PING). Feeds the
    /// host-silence watch (`LINK_TIMEOUT_MS`).
    fn heartbeat(&mut self) {}
    /// Start the motor identification routine.
    fn commission(&mut self) -> Result<(), Reason> {
        Err(Reason::Unsupported)
    }
    /// The motor models and loop gains in force, precession then spin (for MODELS).
    fn models(&self) -> Result<[AxisModel; 2], Reason> {
        Err(Reason::Unsupported)
    }
    /// Drop one granule (RELEASE). A rig without a release solenoid refuses it.
    fn release(&mut self) -> Result<(), Reason> {
        Err(Reason::Unsupported)
    }
    /// The oldest gate event not yet sent, if any (sent as an `E` frame).
    fn next_gate_event(&mut self) -> Option<GateEvent> {
        None
    }
    /// Make a simulated rig misbehave. Real hardware keeps the default: `Unsupported`.
    fn inject(&mut self, what: Injection) -> Result<(), Reason> {
        let _ = what;
        Err(Reason::Unsupported)
    }
}

/// The protocol state of the device: its command decoder, the telemetry sequence number and
/// the telemetry schedule.
pub struct Device {
    decoder: Decoder,
    /// A line typed at a plain console, between frames ([`super::console`]).
    console: ConsoleLine,
    seq: u16,
    telemetry_hz: u8,
    /// Frames sent since `schedule_start_ms`; frame k is due at start + k * 1000 / hz.
    frames_scheduled: u32,
    schedule_start_ms: Option<u32>,
    encode_failures: u32,
    /// The last [`RECENT_COMMANDS`] commands that change something, with their answers: a copy
    /// of one of them (a resend after a lost answer, or a late duplicate) is answered from here
    /// and never carried out again. A ring: `next_recent` is the slot the next one overwrites.
    recent: [Option<Recent>; RECENT_COMMANDS],
    next_recent: usize,
    /// The device time of the latest [`Device::poll_telemetry`] call, ms: the clock that ages
    /// the remembered commands.
    now_ms: u32,
}

/// How many recent commands (those that change something) the rig remembers with their
/// answers. The PC resends every 200 ms for at most 60 s, so in practice its copies find their
/// original here even when other tools send commands in between.
pub const RECENT_COMMANDS: usize = 16;

/// How long a remembered command answers its copies, ms of device time. A copy older than this
/// is taken for a new request: the PC's ids repeat (16 bits), and a new command that happens to
/// reuse an old id with the same words must still be carried out. `bowl` resends for at most
/// 60 s (`--timeout-ms` is capped there) and numbers its requests so that no id repeats within
/// this horizon.
pub const RESEND_HORIZON_MS: u32 = 60_000;

/// One remembered command: what it was and what the rig answered (the answers of commands that
/// change something: ack, reject or RTIME's choice; kept small, 16 of them live on the MCU).
#[derive(Clone, Copy)]
struct Recent {
    id: u16,
    command: Command,
    outcome: Outcome,
    at_ms: u32,
}

#[derive(Clone, Copy)]
enum Outcome {
    Ack,
    Reject(Reason),
    ResidenceSet(ResidenceChoice),
}

impl Outcome {
    fn of(answer: &Frame) -> Option<Outcome> {
        match *answer {
            Frame::Ack { .. } => Some(Outcome::Ack),
            Frame::Reject { reason, .. } => Some(Outcome::Reject(reason)),
            Frame::ResidenceSet {
                model,
                precession_mrad_s,
                spin_mrad_s,
                ..
            } => Some(Outcome::ResidenceSet(ResidenceChoice {
                model,
                precession_mrad_s,
                spin_mrad_s,
            })),
            _ => None,
        }
    }

    fn answer(self, id: u16) -> Frame {
        match self {
            Outcome::Ack => Frame::Ack { id },
            Outcome::Reject(reason) => Frame::Reject { id, reason },
            Outcome::ResidenceSet(c) => Frame::ResidenceSet {
                id,
                model: c.model,
                precession_mrad_s: c.precession_mrad_s,
                spin_mrad_s: c.spin_mrad_s,
            },
        }
    }
}

/// The default telemetry rate, frames per second.
pub const DEFAULT_TELEMETRY_HZ: u8 = ParamId::TelemetryHz.default_value() as u8;

impl Default for Device {
    fn default() -> Self {
        Self::new()
    }
}

impl Device {
    /// A device sending telemetry at [`DEFAULT_TELEMETRY_HZ`].
    pub const fn new() -> Self {
        Self {
            decoder: Decoder::new(),
            console: ConsoleLine::new(),
            seq: 0,
            telemetry_hz: DEFAULT_TELEMETRY_HZ,
            frames_scheduled: 0,
            schedule_start_ms: None,
            encode_failures: 0,
            recent: [None; RECENT_COMMANDS],
            next_recent: 0,
            now_ms: 0,
        }
    }

    /// The telemetry rate, frames per second.
    pub fn telemetry_hz(&self) -> u8 {
        self.telemetry_hz
    }

    /// Frames that could not be encoded (a controller value outside the wire range). A telemetry frame
    /// lost this way still uses up its sequence number, so the PC counts it as missing.
    pub fn encode_failures(&self) -> u32 {
        self.encode_failures
    }

    /// The counters of the command decoder.
    pub fn decoder(&self) -> &Decoder {
        &self.decoder
    }

    /// The boot announcement, to send once after reset.
    pub fn hello<B: Backend>(
        &mut self,
        backend: &B,
        out: &mut [u8; MAX_FRAME_LEN],
    ) -> Option<usize> {
        self.encoded(&Frame::Hello(backend.reset_info()), out)
    }

    /// Feeds received bytes; `send` gets every answer as one complete frame.
    pub fn receive<B: Backend>(
        &mut self,
        backend: &mut B,
        bytes: &[u8],
        mut send: impl FnMut(&[u8]),
    ) {
        let mut out = [0u8; MAX_FRAME_LEN];
        for &b in bytes {
            // Bytes outside every frame may be a line typed at a console (answered as id 0);
            // a `$` starts a frame and ends any typing.
            let typed = if self.decoder.in_frame() || b == FRAME_START {
                self.console.clear();
                None
            } else {
                self.console.push(b)
            };
            let answer = match (self.decoder.push_command(b), typed) {
                (Some(Ok(Frame::Command { id, command })), _) => {
                    backend.heartbeat();
                    self.answer(backend, id, command)
                }
                (Some(Err(FrameError::BadCommand { id, reason })), _) => {
                    backend.heartbeat();
                    Frame::Reject { id, reason }
                }
                // A line that is not words: answered (a person who pressed an arrow key must not
                // meet silence), but no sign of the host, since line noise or a damaged frame's
                // remains look the same and must not keep the host-silence watch fed.
                (_, Some(Err(Reason::Unreadable))) => Frame::Reject {
                    id: 0,
                    reason: Reason::Unreadable,
                },
                // Typed by a person: carried out as typed (no copies to look for without ids).
                (_, Some(typed)) => {
                    backend.heartbeat();
                    match typed {
                        Ok(command) => self.execute(backend, 0, command),
                        Err(reason) => Frame::Reject { id: 0, reason },
                    }
                }
                // Not a command, or damaged beyond reading an id: the PC times out and retries.
                _ => continue,
            };
            let n = match encode(&answer, &mut out) {
                Ok(n) => n,
                Err(_) => {
                    self.encode_failures = self.encode_failures.saturating_add(1);
                    let reject = Frame::Reject {
                        id: answer.answer_id().unwrap_or(0),
                        reason: Reason::Internal,
                    };
                    // A reject always fits and is in range.
                    encode(&reject, &mut out).unwrap_or(0)
                }
            };
            if let Some(frame) = out.get(..n) {
                send(frame);
            }
        }
    }

    /// The answer to a command from the PC: carried out once per request id. A command with the
    /// id and the words of one of the last [`RECENT_COMMANDS`] (sent within
    /// [`RESEND_HORIZON_MS`]) is a copy of it: a resend after a lost answer, or a late duplicate
    /// that arrives after newer commands. It gets the original answer again and is never carried
    /// out a second time, so a late copy cannot undo what came after it. Queries (the rows of
    /// the command table that change nothing: STATUS, PARAMS, MODELS, PING) are always answered
    /// afresh.
    pub fn answer<B: Backend>(&mut self, backend: &mut B, id: u16, command: Command) -> Frame {
        if !command.kind().changes() {
            return self.execute(backend, id, command);
        }
        let now = self.now_ms;
        let copy_of = self.recent.iter().flatten().find(|r| {
            r.id == id && r.command == command && now.wrapping_sub(r.at_ms) <= RESEND_HORIZON_MS
        });
        if let Some(original) = copy_of {
            return original.outcome.answer(id);
        }
        let answer = self.execute(backend, id, command);
        if let Some(outcome) = Outcome::of(&answer) {
            // The same id with other words is a new request that reused an id: it replaces the
            // old entry, so one id never stands for two answers.
            let slot = match self
                .recent
                .iter()
                .position(|r| r.is_some_and(|r| r.id == id))
            {
                Some(i) => i,
                None => {
                    let i = self.next_recent;
                    self.next_recent = (i + 1) % RECENT_COMMANDS;
                    i
                }
            };
            if let Some(entry) = self.recent.get_mut(slot) {
                *entry = Some(Recent {
                    id,
                    command,
                    outcome,
                    at_ms: now,
                });
            }
        }
        answer
    }

    /// Carries out one command and returns the answer frame (no resend check: see
    /// [`Device::answer`]).
    pub fn execute<B: Backend>(&mut self, backend: &mut B, id: u16, command: Command) -> Frame {
        let done = match command {
            Command::SetSpeeds {
                precession_mrad_s,
                spin_mrad_s,
            } => {
                let ok =
                    |v: i16, limit: ParamId| (0..=backend.param(limit)).contains(&i32::from(v));
                if ok(precession_mrad_s, ParamId::SpeedMax1MradS)
                    && ok(spin_mrad_s, ParamId::SpeedMax2MradS)
                {
                    backend.set_speeds(precession_mrad_s, spin_mrad_s)
                } else {
                    Err(Reason::Range)
                }
            }
            Command::SetResidence { model, time_ms } => {
                match backend.set_residence(model, time_ms) {
                    Ok(c) => {
                        return Frame::ResidenceSet {
                            id,
                            model: c.model,
                            precession_mrad_s: c.precession_mrad_s,
                            spin_mrad_s: c.spin_mrad_s,
                        };
                    }
                    Err(reason) => Err(reason),
                }
            }
            Command::Start => backend.start(),
            Command::Stop => {
                backend.stop();
                Ok(())
            }
            Command::ClearFault => backend.clear_fault(),
            Command::SetParam {
                id: ParamId::TelemetryHz,
                value,
            } => self.set_telemetry_hz(value).map(|()| {
                backend.telemetry_hz_set(self.telemetry_hz);
            }),
            Command::SetParam { id: param, value } => backend.set_param(param, value),
            Command::GetStatus => {
                let t = backend.telemetry();
                let reset = backend.reset_info();
                return Frame::Status {
                    id,
                    status: Status {
                        state: t.state,
                        fault: t.fault,
                        reset_cause: reset.reset_cause,
                        reset_count: reset.reset_count,
                        uptime_ms: t.time_ms,
                        telemetry_hz: self.telemetry_hz,
                        flags: backend.status_flags(),
                    },
                };
            }
            Command::GetParams => {
                return Frame::Params {
                    id,
                    values: self.params(backend),
                };
            }
            Command::Inject { what } => backend.inject(what),
            // The host was heard when the command arrived (`receive`).
            Command::Ping => Ok(()),
            Command::Commission => backend.commission(),
            Command::Release => backend.release(),
            Command::GetModels => match backend.models() {
                Ok(axes) => return Frame::Models { id, axes },
                Err(reason) => Err(reason),
            },
        };
        match done {
            Ok(()) => Frame::Ack { id },
            Err(reason) => Frame::Reject { id, reason },
        }
    }

    /// Every parameter value, in wire order.
    pub fn params<B: Backend>(&self, backend: &B) -> ParamValues {
        let mut values = [0i32; PARAM_COUNT];
        for (slot, &p) in values.iter_mut().zip(ParamId::ALL.iter()) {
            *slot = match p {
                ParamId::TelemetryHz => i32::from(self.telemetry_hz),
                _ => backend.param(p),
            };
        }
        values
    }

    fn set_telemetry_hz(&mut self, hz: i32) -> Result<(), Reason> {
        let max = max_telemetry_hz(super::DEFAULT_BAUD) as i32;
        match u8::try_from(hz) {
            Ok(hz) if i32::from(hz) <= max => {
                self.telemetry_hz = hz;
                // A new schedule: its clock and its frame count start again together (the old
                // count against a fresh clock would hold telemetry back for as long as the rig
                // had been sending).
                self.schedule_start_ms = None;
                self.frames_scheduled = 0;
                Ok(())
            }
            _ => Err(Reason::Range),
        }
    }

    /// Builds the telemetry frame if one is due at `now_ms`. Call it at least once per period,
    /// and also while telemetry is off: `now_ms` is the device's clock for the window of recent
    /// commands too.
    pub fn poll_telemetry<B: Backend>(
        &mut self,
        backend: &B,
        now_ms: u32,
        out: &mut [u8; MAX_FRAME_LEN],
    ) -> Option<usize> {
        self.now_ms = now_ms;
        if self.telemetry_hz == 0 {
            return None;
        }
        let start = *self.schedule_start_ms.get_or_insert(now_ms);
        let hz = u64::from(self.telemetry_hz);
        let elapsed_ms = now_ms.wrapping_sub(start);
        // The frame due now; if polls were late, skip the missed slots instead of bursting.
        let due_now = u64::from(elapsed_ms) * hz / 1000;
        if due_now < u64::from(self.frames_scheduled) {
            return None;
        }
        // due_now <= (2^32 - 1) * 50 / 1000 fits in u32.
        self.frames_scheduled = (due_now + 1) as u32;
        if elapsed_ms >= 1_000_000 {
            // Move the origin by 1000 s (a whole number of periods) to keep the numbers small.
            self.schedule_start_ms = Some(start.wrapping_add(1_000_000));
            self.frames_scheduled -= (hz * 1000) as u32;
        }
        let mut t = backend.telemetry();
        t.seq = self.seq;
        self.seq = self.seq.wrapping_add(1);
        self.encoded(&Frame::Telemetry(t), out)
    }

    /// The next gate event as an `E` frame, if the backend has one (call after each step; each
    /// event is sent once, as soon as it is known).
    pub fn poll_gate_event<B: Backend>(
        &mut self,
        backend: &mut B,
        out: &mut [u8; MAX_FRAME_LEN],
    ) -> Option<usize> {
        let event = backend.next_gate_event()?;
        self.encoded(&Frame::Event(event), out)
    }

    fn encoded(&mut self, frame: &Frame, out: &mut [u8; MAX_FRAME_LEN]) -> Option<usize> {
        match encode(frame, out) {
            Ok(n) => Some(n),
            Err(EncodeError::BufferTooSmall | EncodeError::FieldOutOfRange) => {
                self.encode_failures = self.encode_failures.saturating_add(1);
                None
            }
        }
    }
}
