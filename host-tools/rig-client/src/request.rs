//! The one request loop: a command sent with its request id, its answer matched by id and kind,
//! sent again with the same id until the answer comes; every other frame that arrives meanwhile
//! handed to the caller. `bowl send`, the refusal's questions, commissioning, the experiment's
//! rig ([`crate::rig::Rig`]), the monitor's command line and the demo all send through it
//! ([`Request`] is its state: the monitor and the demo, which never block, drive it themselves).

use std::time::{Duration, Instant};

use model_core::wire::{Command, Decoder, Frame, MAX_FRAME_LEN, Reason, decode_frame, encode};

use crate::link::Link;
use crate::serial::ReadOutcome;
use crate::unreadable::{LineTap, UnreadableAnswer};

mod ids;
pub use ids::{fresh_id, next_id};

/// Whether `frame` is the kind of answer `command` gets, as the command table says (`S` to
/// STATUS, `P` to PARAMS, `M` to MODELS, `W` to RTIME, `A` to the rest), or `R` (anything can
/// be refused).
pub fn answers_kind(command: &Command, frame: &Frame) -> bool {
    matches!(frame, Frame::Reject { .. })
        || model_core::wire::encode::kind_letter(frame) == command.kind().answer().letter()
}

/// How long one attempt waits before the command is sent again with the same id (the rig carries
/// a resend out once). The rig answers within a few ms; a damaged answer is never repaired.
pub const RESEND_EVERY: Duration = Duration::from_millis(200);

/// What came from the rig while a command waited in vain for its answer: enough to say whether
/// the line is dead, noisy, or alive but not answering.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Unanswered {
    /// Frames that arrived intact (telemetry, other tools' answers).
    pub frames_ok: u64,
    /// Frames that arrived damaged.
    pub frames_corrupt: u64,
    /// How many times the command was sent (the first time and the resends).
    pub sent: u32,
    /// Of the intact frames, the rig's answers to lines it could not read
    /// ([`crate::lines::unread_by_rig`]): a command of ours that lost its `$` on the way.
    pub unread_by_rig: u64,
}

impl Unanswered {
    /// What to try, in words.
    pub fn advice(&self) -> String {
        let mut seen = format!(
            "sent {} times; meanwhile {} frames arrived intact and {} damaged",
            self.sent, self.frames_ok, self.frames_corrupt
        );
        let todo = if self.unread_by_rig > 0 {
            // The rig said so itself: the way to it garbles lines (the way back may be clean).
            seen += &format!(
                ", and the rig could not read {} of the lines it got",
                self.unread_by_rig
            );
            "the line to the rig is noisy: give it longer (`--timeout-ms 5000` resends every \
             200 ms until then), check the cable, its ground and the baud rate (`--baud`)"
        } else if self.frames_corrupt > 0 {
            "the line is noisy: give it longer (`--timeout-ms 5000` resends every 200 ms until \
             then), check the cable, its ground and the baud rate (`--baud`); `bowl monitor PORT` \
             shows the frame counters"
        } else if self.frames_ok == 0 {
            "nothing came from the port at all: is the rig powered, is this its port (`bowl \
             ports`), is the baud rate right (`--baud`)?"
        } else {
            "the rig is sending but did not answer: give it longer (`--timeout-ms 5000`); \
             `bowl monitor PORT` shows its state and the frame counters"
        };
        format!("{seen}; {todo}")
    }
}

/// The decoder of a connection and the raw line beside it (to show an answer it cannot read):
/// kept for as long as the connection, so no frame is cut at a request's edge.
#[derive(Default)]
pub struct Reader {
    /// The shared decoder (its counters are the link's).
    pub decoder: Decoder,
    tap: LineTap,
}

/// What one byte completed: a frame, or an intact answer this bowl cannot read, or a damaged
/// line (counted by the decoder).
pub enum Arrival {
    /// An intact frame.
    Frame(Frame),
    /// An intact answer this bowl cannot read.
    Unreadable(UnreadableAnswer),
    /// A damaged line.
    Damaged,
}

impl Reader {
    /// Takes one byte; what it completed, if anything.
    pub fn push(&mut self, byte: u8) -> Option<Arrival> {
        self.tap.push(byte);
        match self.decoder.push(byte)? {
            Ok(frame) => Some(Arrival::Frame(frame)),
            Err(e) => Some(match self.tap.unreadable_answer(e) {
                Some(u) => Arrival::Unreadable(u),
                None => Arrival::Damaged,
            }),
        }
    }
}

/// One command on its way to the rig: encoded once, sent again with the same id every
/// [`RESEND_EVERY`] until its answer (the frame with its id and the kind it gets) comes.
#[derive(Debug, Clone)]
pub struct Request {
    id: u16,
    command: Command,
    line: Vec<u8>,
    sent_at: Option<Instant>,
    sends: u32,
}

impl Request {
    /// A typed command with request `id`; refused here (as the rig would refuse it whatever its
    /// settings) when it cannot be right: a speed below 0 (`RANGE`).
    pub fn new(id: u16, command: Command) -> Result<Self, Reason> {
        if let Command::SetSpeeds {
            precession_mrad_s,
            spin_mrad_s,
        } = command
            && (precession_mrad_s < 0 || spin_mrad_s < 0)
        {
            return Err(Reason::Range);
        }
        let mut buf = [0u8; MAX_FRAME_LEN];
        let n = encode(&Frame::Command { id, command }, &mut buf).map_err(|_| Reason::Malformed)?;
        Ok(Self::sent_as(id, command, buf[..n].to_vec()))
    }

    /// A command line already built and checked (`lines::command_line`, from typed words).
    pub fn from_line(line: Vec<u8>) -> Option<Self> {
        match decode_frame(&line) {
            Ok(Frame::Command { id, command }) => Some(Self::sent_as(id, command, line)),
            _ => None,
        }
    }

    fn sent_as(id: u16, command: Command, line: Vec<u8>) -> Self {
        Self {
            id,
            command,
            line,
            sent_at: None,
            sends: 0,
        }
    }

    /// The request id.
    pub fn id(&self) -> u16 {
        self.id
    }

    /// The command.
    pub fn command(&self) -> &Command {
        &self.command
    }

    /// How many times it was sent so far.
    pub fn sends(&self) -> u32 {
        self.sends
    }

    /// The line to send at `now`, if one is due: the first time, and again when
    /// [`RESEND_EVERY`] has passed without the answer.
    pub fn due(&mut self, now: Instant) -> Option<&[u8]> {
        if self
            .sent_at
            .is_some_and(|t| now.duration_since(t) < RESEND_EVERY)
        {
            return None;
        }
        self.sent_at = Some(now);
        self.sends += 1;
        Some(&self.line)
    }

    /// When the next resend is due; `None` before the first send (due at once).
    pub fn next_due(&self) -> Option<Instant> {
        self.sent_at.map(|t| t + RESEND_EVERY)
    }

    /// Whether `frame` is this request's answer.
    pub fn answered_by(&self, frame: &Frame) -> bool {
        frame.answer_id() == Some(self.id) && answers_kind(&self.command, frame)
    }
}

/// The one request loop: sends `request` on `link` and waits for its answer, sending it again
/// every [`RESEND_EVERY`] until `timeout` has passed. Before each send, what already arrived is
/// read out (before the first send it cannot be this request's answer). Every other frame that
/// arrives meanwhile goes to `other` (telemetry, gate events, other tools' answers), so nothing
/// is lost while a command waits. `Ok(Err(..))` when nothing answered (with what came
/// instead); an error when the link failed ([`LinkError`]) or the answer could not be read
/// ([`UnreadableAnswer`]).
pub fn request(
    link: &mut Link,
    reader: &mut Reader,
    request: &mut Request,
    timeout: Duration,
    other: &mut dyn FnMut(Frame),
) -> anyhow::Result<Result<Frame, Unanswered>> {
    let end = Instant::now() + timeout;
    let mut buf = [0u8; 4096];
    let mut unanswered = Unanswered::default();
    let mut answer = None;
    loop {
        let now = Instant::now();
        if now >= end {
            return Ok(Err(unanswered));
        }
        if request.next_due().is_none_or(|t| t <= now) {
            // What came before this attempt: handed on (an answer only once it was sent).
            while let ReadOutcome::Data(n) = link.read(&mut buf, Duration::from_millis(1))? {
                for &b in &buf[..n] {
                    match reader.push(b) {
                        Some(Arrival::Frame(f))
                            if request.sends() > 0 && request.answered_by(&f) =>
                        {
                            answer = Some(f);
                        }
                        Some(Arrival::Frame(f)) => other(f),
                        _ => {}
                    }
                }
            }
            if let Some(f) = answer {
                return Ok(Ok(f));
            }
            if let Some(line) = request.due(Instant::now()) {
                link.write_all(line)?;
                unanswered.sent += 1;
            }
        }
        let wait = request
            .next_due()
            .map_or(end, |t| t.min(end))
            .saturating_duration_since(Instant::now())
            .min(Duration::from_millis(50));
        match link.read(&mut buf, wait)? {
            ReadOutcome::Data(n) => {
                // The whole read is taken in: frames after the answer are handed on too.
                for &b in &buf[..n] {
                    match reader.push(b) {
                        Some(Arrival::Frame(f)) if answer.is_none() && request.answered_by(&f) => {
                            answer = Some(f);
                        }
                        Some(Arrival::Frame(f)) => {
                            unanswered.frames_ok += 1;
                            if crate::lines::unread_by_rig(&f) {
                                unanswered.unread_by_rig += 1;
                            }
                            other(f);
                        }
                        Some(Arrival::Unreadable(u)) if u.id == request.id() => {
                            return Err(u.into());
                        }
                        Some(Arrival::Unreadable(_) | Arrival::Damaged) => {
                            unanswered.frames_corrupt += 1;
                        }
                        None => {}
                    }
                }
                if let Some(f) = answer {
                    return Ok(Ok(f));
                }
            }
            ReadOutcome::Timeout => {}
            ReadOutcome::Gone => return Err(link.gone().into()),
        }
    }
}

/// Sends the command `line` (request `id`, built by `lines::command_line`) and waits for its
/// answer through the one request loop ([`request`]); the frames that come meanwhile are
/// counted, not kept.
pub fn transact(
    link: &mut Link,
    id: u16,
    line: &[u8],
    timeout: Duration,
) -> anyhow::Result<Result<Frame, Unanswered>> {
    let Some(mut req) = Request::from_line(line.to_vec()).filter(|r| r.id() == id) else {
        anyhow::bail!("not a command line (a bug in bowl)");
    };
    request(link, &mut Reader::default(), &mut req, timeout, &mut |_| {})
}

#[cfg(all(test, unix))]
mod tests;
