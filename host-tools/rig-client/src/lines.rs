//! Command lines out, answers described: the line `$C1,id,WORDS...*CRC` built from a command's
//! words by the command table, a rejection reason and an answer frame in words.

use model_core::wire::{Command, Frame, MAX_FRAME_LEN, ParamId, Reason, encode};

/// Builds the command line `$C1,id,WORD,fields...*CRC\r\n` from the words a person typed,
/// judged by the command table (`Command::from_words`), so a command the rig would refuse as
/// malformed or out of range whatever its settings never leaves the PC (a speed below 0: every
/// SPEED_MAX is at least 0). The words of the refusal: [`crate::command_words::local_refusal`].
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
        Reason::Unreadable => {
            "a line typed at the rig's console was not read: it held a key that types no word \
             (an arrow, Ctrl, a letter beyond ASCII such as µ, a `,` or `*`) or was over 64 \
             characters; type it again in letters, digits and spaces"
        }
    }
}

/// What the monitor and a command left unanswered say of [`unread_by_rig`].
pub const UNREAD_BY_RIG: &str = "the rig could not read a line it got (line noise on the link?)";

/// Whether `frame` is the rig's answer to a line it got outside a frame and could not read
/// (`$R1,0,UNREADABLE`). A person's typing gets it too, but no one types at the rig while a
/// tool holds the port, and the tools' ids skip 0 ([`crate::request::next_id`]): it is one of
/// their frames that lost its `$` on the way. No tool takes it for its answer, so it is said
/// on its own, never dropped as another tool's.
pub fn unread_by_rig(frame: &Frame) -> bool {
    matches!(
        frame,
        Frame::Reject {
            id: 0,
            reason: Reason::Unreadable
        }
    )
}

/// The STATUS flags in words, joined by "; " (`None` when none is set): also the monitor's
/// banner.
pub fn status_flag_words(flags: u8) -> Option<String> {
    use model_core::wire::status_flags as f;
    let words: Vec<&str> = [
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
    .map(|(_, w)| *w)
    .collect();
    (!words.is_empty()).then(|| words.join("; "))
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
            s.state.token(),
            s.fault.token(),
            s.reset_cause.token(),
            s.reset_count,
            s.uptime_ms,
            s.telemetry_hz,
            s.flags,
            s.state.words(),
            s.fault.words(),
            s.reset_cause.words(),
            status_flag_words(s.flags)
                .map(|w| format!("; {w}"))
                .unwrap_or_default(),
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
                model_core::wire::ResidenceModel::Table => "stored table's",
            },
            f64::from(*precession_mrad_s) * 1e-3,
            f64::from(*spin_mrad_s) * 1e-3
        ),
        // Frames that are never an answer, should one be shown in an answer's place.
        Frame::Telemetry(t) => format!(
            "telemetry (not an answer): t={:.3} s, {}",
            f64::from(t.time_ms) / 1000.0,
            t.state.words()
        ),
        Frame::Hello(_) => "the rig's hello (it has just started; not an answer)".into(),
        Frame::Command { id, .. } => {
            format!("a command line (id {id}), not an answer: is the line echoing what was sent?")
        }
    }
}
