//! `bowl send PORT COMMAND ...`: send one command, print the rig's answer. Exit status as in
//! `exit_code`: 0 done, 1 refused (by the rig or the local check), 3 link problem, 4 no answer.

use std::time::Duration;

use anyhow::Result;
use model_core::wire::{Command, Frame, MAX_FRAME_LEN, ParamId, Reason, encode};

use crate::command_words;
use crate::exit_code;
use crate::link::{Link, transact};
use crate::refusal;
use crate::words;

/// Flags of `bowl send`.
#[derive(clap::Args)]
pub struct Args {
    /// The serial port or pseudo-terminal of the rig.
    port: String,
    /// The command and its arguments, e.g. `speed 1800 2100`, `rtime cori 2500`, `start`, `stop`,
    /// `clear`, `set MU_PPM 29000`, `status`, `params`, `models`, `commission`, `inject sensor2`
    /// (see docs/protocol.md). A negative number is a value, judged by the protocol's rules.
    #[arg(required = true, num_args = 1.., allow_negative_numbers = true)]
    command: Vec<String>,
    /// Baud rate.
    #[arg(long, default_value_t = 115_200, value_parser = clap::value_parser!(u32).range(50..=12_000_000))]
    baud: u32,
    /// Request id echoed by the rig (default: derived from the clock).
    #[arg(long)]
    id: Option<u16>,
    /// How long to wait for the answer, ms (1..=60000: the rig remembers a command for 60 s to
    /// know its copies, so resends must end before that).
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u64).range(1..=60_000))]
    timeout_ms: u64,
}

/// Builds the command line `$C1,id,WORD,fields...*CRC\r\n` from the words a person typed,
/// judged by the command table (`Command::from_words`), so a command the rig would refuse as
/// malformed or out of range whatever its settings never leaves the PC (a speed below 0: every
/// SPEED_MAX is at least 0). The words of the refusal: [`command_words::local_refusal`].
pub fn command_line(id: u16, words: &[String]) -> Result<Vec<u8>, Reason> {
    let command = Command::from_words(words).map_err(|r| r.reason())?;
    let mut buf = [0u8; MAX_FRAME_LEN];
    // Every field passed its range: the frame encodes (CRLF, as every frame ends).
    let n = encode(&Frame::Command { id, command }, &mut buf).map_err(|_| Reason::Malformed)?;
    Ok(buf[..n].to_vec())
}

/// What a rejection reason means, for people.
pub fn explain(reason: Reason) -> &'static str {
    match reason {
        Reason::Malformed => {
            "the fields did not parse (values are integers in the units of docs/protocol.md, e.g. mrad/s, ms)"
        }
        Reason::UnknownCommand => "unknown command word",
        Reason::UnknownParam => "unknown parameter name",
        Reason::Range => "a value was outside its range (nothing was clamped or changed)",
        Reason::State => "not allowed in the rig's current state",
        Reason::Infeasible => "the target cannot be reached within the limits",
        Reason::Unsupported => "this rig does not support that command",
        Reason::Version => "the rig speaks another protocol version",
        Reason::Internal => "the rig could not build its answer (a bug)",
    }
}

/// The STATUS flags in words, each after "; " (empty when none is set).
fn status_flag_words(flags: u8) -> String {
    use model_core::wire::status_flags as f;
    [
        (
            f::PARAMS_DEFAULTS,
            "booted on default parameters: no valid record in flash",
        ),
        (f::PARAMS_SAVE_FAILED, "the last parameter save failed"),
        (
            f::CLOCK_FALLBACK,
            "running on the internal oscillator: the crystal did not start",
        ),
    ]
    .iter()
    .filter(|(bit, _)| flags & bit != 0)
    .map(|(_, w)| format!("; {w}"))
    .collect()
}

/// A one-line description of an answer frame.
pub fn describe(frame: &Frame) -> String {
    match frame {
        Frame::Ack { id } => format!("ok (id {id})"),
        Frame::Reject { id, reason } => {
            format!(
                "rejected (id {id}): {} - {}",
                reason.token(),
                explain(*reason)
            )
        }
        Frame::Status { id, status: s } => format!(
            "status (id {id}): state={} fault={} reset_cause={} reset_count={} uptime_ms={} telemetry_hz={} flags={} ({}; {}; last reset: {}{})",
            words::state_token(s.state),
            words::fault_token(s.fault),
            words::reset_cause_token(s.reset_cause),
            s.reset_count,
            s.uptime_ms,
            s.telemetry_hz,
            s.flags,
            words::state(s.state),
            words::fault(s.fault),
            words::reset_cause(s.reset_cause),
            status_flag_words(s.flags),
        ),
        Frame::Params { id, values } => {
            let mut out = format!("params (id {id}):");
            for (p, v) in ParamId::ALL.iter().zip(values.iter()) {
                out.push_str(&format!(" {}={v}", p.token()));
            }
            out
        }
        Frame::Models { id, axes } => {
            let mut out = format!("models (id {id}):");
            for (name, a) in ["precession", "spin"].iter().zip(axes.iter()) {
                out.push_str(&format!(
                    " {name}: identified={} back_emf_uv_per_rad_s={} friction_ppm={} \
                     time_constant_us={} kp_ppm_per_rad_s={} ki_ppm_per_rad={};",
                    u8::from(a.identified),
                    a.back_emf_uv_per_rad_s,
                    a.friction_ppm,
                    a.time_constant_us,
                    a.kp_ppm_per_rad_s,
                    a.ki_ppm_per_rad
                ));
            }
            out.pop();
            out
        }
        Frame::Event(e) => format!("gate event: {}", crate::telemetry_csv::gate_event_text(e)),
        Frame::ResidenceSet {
            id,
            model,
            precession_mrad_s,
            spin_mrad_s,
        } => format!(
            "ok (id {id}): the {} model answered: precession {:.3} rad/s, spin {:.3} rad/s",
            match model {
                model_core::wire::ResidenceModel::Flat => "flat",
                model_core::wire::ResidenceModel::Coriolis => "Coriolis",
            },
            f64::from(*precession_mrad_s) * 1e-3,
            f64::from(*spin_mrad_s) * 1e-3
        ),
        // Frames that are never an answer, should one be shown in an answer's place.
        Frame::Telemetry(t) => format!(
            "telemetry (not an answer): t={:.3} s, {}",
            f64::from(t.time_ms) / 1000.0,
            words::state(t.state)
        ),
        Frame::Hello(_) => "the rig's hello (it has just started; not an answer)".into(),
        Frame::Command { id, .. } => {
            format!("a command line (id {id}), not an answer: is the line echoing what was sent?")
        }
    }
}

/// Runs `bowl send`; returns the process exit status.
pub fn run(args: &Args) -> Result<i32> {
    let id = args.id.unwrap_or_else(crate::link::fresh_id);
    let line = match command_line(id, &args.command) {
        Ok(line) => line,
        Err(reason) => {
            // A command line that cannot be right on any rig: a usage error, said in words.
            println!(
                "rejected locally: {} - {} (not sent)",
                reason.token(),
                explain(reason)
            );
            println!("  {}", command_words::local_refusal(&args.command, reason));
            return Ok(exit_code::USAGE);
        }
    };
    let mut link = Link::open(&args.port, args.baud)?;
    let timeout = Duration::from_millis(args.timeout_ms);
    match transact(&mut link, id, &line, timeout)? {
        Ok(frame) => {
            println!("{}", describe(&frame));
            if let Frame::Reject { reason, .. } = frame
                && let Some(why) =
                    refusal::particulars(Some(&mut link), id, &args.command, reason, timeout)
            {
                println!("  {why}");
            }
            Ok(if matches!(frame, Frame::Reject { .. }) {
                exit_code::REFUSED
            } else {
                exit_code::OK
            })
        }
        Err(unanswered) => {
            println!(
                "timeout: no answer to id {id} within {} ms ({})",
                args.timeout_ms,
                unanswered.advice()
            );
            Ok(exit_code::TIMEOUT)
        }
    }
}
