//! The decoder of one line: a line to a [`Frame`] ([`parse_line`], [`parse_command_line`]),
//! checked (CRC, version, every field's range). The byte stream around it is
//! [`super::stream::Decoder`].

use super::commands::{Command, CommandKind, FieldProblem, MAX_FIELDS, parse_int};
use super::crc::crc32;
use super::frame::Frame;
use super::params::{PARAM_COUNT, ParamId, ParamValues};
use super::types::{
    AxisModel, DeviceState, FaultCode, GateEvent, GateKind, Hello, MODEL_FIELD_MAX, MotorTelemetry,
    Reason, ResetCause, Residence, ResidenceModel, Status, Telemetry,
};
use super::{FRAME_END, FRAME_START, LINE_END_CR, PROTOCOL_VERSION};

/// Why a line was not accepted as a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// The line did not end in `*` and 8 upper-case hex digits.
    BadTrailer,
    /// The CRC did not match: the line was damaged on the way.
    BadCrc,
    /// The CRC matched but the kind letter is not one of `T H E C A R S P M W`.
    UnknownKind,
    /// The CRC matched but the protocol version is not the one spoken here.
    UnsupportedVersion,
    /// The CRC matched but a field is missing, extra, not a canonical integer, or out of range.
    Malformed,
    /// A command whose CRC matched but whose content is wrong: the device answers
    /// `Reject { id, reason }` (id 0 if the id itself did not parse).
    BadCommand {
        /// The request id, or 0.
        id: u16,
        /// The rejection to send.
        reason: Reason,
    },
    /// The line grew past [`super::MAX_FRAME_LEN`] bytes without an end: dropped, decoder resynchronises.
    Oversize,
    /// A `$` or a byte that cannot appear in a frame (control character, non-ASCII) arrived
    /// before the end of the line: the partial frame was dropped.
    Truncated,
}

/// Error of one field: `Malformed` (not there, not a canonical integer or known token) or
/// `Range` (a well-formed number outside the field's range).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FieldError {
    Malformed,
    Range,
}

impl From<FieldError> for Reason {
    fn from(e: FieldError) -> Reason {
        match e {
            FieldError::Malformed => Reason::Malformed,
            FieldError::Range => Reason::Range,
        }
    }
}

/// The comma-separated fields of a payload.
struct Fields<'a> {
    rest: Option<&'a [u8]>,
}

impl<'a> Fields<'a> {
    fn next_token(&mut self) -> Result<&'a [u8], FieldError> {
        let rest = self.rest.ok_or(FieldError::Malformed)?;
        match rest.iter().position(|&b| b == b',') {
            Some(i) => {
                self.rest = rest.get(i + 1..);
                rest.get(..i).ok_or(FieldError::Malformed)
            }
            None => {
                self.rest = None;
                Ok(rest)
            }
        }
    }

    fn int(&mut self, lo: i64, hi: i64) -> Result<i64, FieldError> {
        let v = parse_int(self.next_token()?).ok_or(FieldError::Malformed)?;
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(FieldError::Range)
        }
    }

    fn end(&self) -> Result<(), FieldError> {
        match self.rest {
            None => Ok(()),
            Some(_) => Err(FieldError::Malformed),
        }
    }
}

fn hex_value(b: u8) -> Option<u32> {
    match b {
        b'0'..=b'9' => Some(u32::from(b - b'0')),
        b'A'..=b'F' => Some(u32::from(b - b'A' + 10)),
        _ => None,
    }
}

// The narrowing casts below follow a range check in `Fields::int`, so they are exact.
fn u16_field(f: &mut Fields<'_>) -> Result<u16, FieldError> {
    Ok(f.int(0, u16::MAX.into())? as u16)
}

fn i16_field(f: &mut Fields<'_>) -> Result<i16, FieldError> {
    Ok(f.int(i16::MIN.into(), i16::MAX.into())? as i16)
}

fn u32_field(f: &mut Fields<'_>) -> Result<u32, FieldError> {
    Ok(f.int(0, u32::MAX.into())? as u32)
}

fn motor(f: &mut Fields<'_>) -> Result<MotorTelemetry, FieldError> {
    Ok(MotorTelemetry {
        set_mrad_s: i16_field(f)?,
        measured_mrad_s: i16_field(f)?,
        duty_bp: f.int(-10_000, 10_000)? as i16,
        pulses: u16_field(f)?,
    })
}

fn coded<T>(f: &mut Fields<'_>, from: fn(i64) -> Option<T>) -> Result<T, FieldError> {
    from(f.int(0, 255)?).ok_or(FieldError::Range)
}

fn residence(f: &mut Fields<'_>) -> Result<Residence, FieldError> {
    Residence::from_wire(f.int(-2, 9_999_999)?).ok_or(FieldError::Range)
}

fn telemetry(f: &mut Fields<'_>) -> Result<Telemetry, FieldError> {
    Ok(Telemetry {
        time_ms: u32_field(f)?,
        seq: u16_field(f)?,
        state: coded(f, DeviceState::from_code)?,
        fault: coded(f, FaultCode::from_code)?,
        precession: motor(f)?,
        spin: motor(f)?,
        bowl_mrad_s: u16_field(f)?,
        residence_flat: residence(f)?,
        residence_coriolis: residence(f)?,
    })
}

fn status(f: &mut Fields<'_>) -> Result<Status, FieldError> {
    Ok(Status {
        state: coded(f, DeviceState::from_code)?,
        fault: coded(f, FaultCode::from_code)?,
        reset_cause: coded(f, ResetCause::from_code)?,
        reset_count: u16_field(f)?,
        uptime_ms: u32_field(f)?,
        telemetry_hz: param_value(f, ParamId::TelemetryHz)? as u8,
        flags: f.int(0, u8::MAX.into())? as u8,
    })
}

fn param_value(f: &mut Fields<'_>, id: ParamId) -> Result<i32, FieldError> {
    let (lo, hi) = id.range();
    Ok(f.int(lo.into(), hi.into())? as i32)
}

fn params(f: &mut Fields<'_>) -> Result<ParamValues, FieldError> {
    let mut values = [0i32; PARAM_COUNT];
    for (slot, &id) in values.iter_mut().zip(ParamId::ALL.iter()) {
        *slot = param_value(f, id)?;
    }
    Ok(values)
}

fn axis_model(f: &mut Fields<'_>) -> Result<AxisModel, FieldError> {
    let identified = f.int(0, 1)? == 1;
    let mut field = || f.int(0, i64::from(MODEL_FIELD_MAX)).map(|v| v as u32);
    Ok(AxisModel {
        identified,
        back_emf_uv_per_rad_s: field()?,
        friction_ppm: field()?,
        time_constant_us: field()?,
        kp_ppm_per_rad_s: field()?,
        ki_ppm_per_rad: field()?,
    })
}

fn token_of<T: Copy>(tok: &[u8], all: &[T], token: fn(T) -> &'static str) -> Option<T> {
    all.iter().copied().find(|&t| token(t).as_bytes() == tok)
}

/// Parses the command word and its fields, as the command table declares them. Unknown words
/// and parameters get their own reasons; a well-formed number outside its range is `Range`.
fn command(f: &mut Fields<'_>) -> Result<Command, Reason> {
    let kind = CommandKind::from_token(f.next_token()?).ok_or(Reason::UnknownCommand)?;
    let mut values = [0i64; MAX_FIELDS];
    let mut param = None;
    for (slot, field) in values.iter_mut().zip(kind.fields()) {
        *slot = field
            .parse(f.next_token()?, &mut param, false)
            .map_err(FieldProblem::reason)?;
    }
    f.end()?;
    Command::from_values(kind, &values).ok_or(Reason::Malformed)
}

/// A command's word and fields without the frame around them (`SPEED,1800,2100`): what a line
/// typed at a console becomes ([`super::console`]), read by the frame's own parser.
pub(crate) fn typed_command(fields: &[u8]) -> Result<Command, Reason> {
    command(&mut Fields { rest: Some(fields) })
}

impl From<FieldError> for FrameError {
    fn from(_: FieldError) -> FrameError {
        FrameError::Malformed
    }
}

/// Parses one line: the bytes after `$` and before `\n` (a trailing `\r` is allowed).
pub fn parse_line(line: &[u8]) -> Result<Frame, FrameError> {
    checked_payload(line).and_then(parse_payload)
}

/// Parses one line as the rig does: command frames only. Any other kind, CRC and version
/// valid, is [`FrameError::UnknownKind`] without its fields being read, so the rig's image
/// carries no parser for the frames it only ever sends.
pub fn parse_command_line(line: &[u8]) -> Result<Frame, FrameError> {
    checked_payload(line).and_then(|payload| {
        let mut f = Fields {
            rest: Some(payload),
        };
        match header(&mut f)? {
            b'C' => command_frame(&mut f),
            _ => Err(FrameError::UnknownKind),
        }
    })
}

/// The payload of a line whose trailer and CRC check out (the `\r` of a `\r\n` line end, if
/// the caller left it on, is not part of the line).
fn checked_payload(line: &[u8]) -> Result<&[u8], FrameError> {
    let line = match line.split_last() {
        Some((b'\r', rest)) => rest,
        _ => line,
    };
    // Kind letter, version digit, `*`, 8 hex digits at least.
    if line.len() < 11 {
        return Err(FrameError::BadTrailer);
    }
    let star = line.len() - 9;
    let (payload, trailer) = line.split_at(star);
    if trailer[0] != b'*' {
        return Err(FrameError::BadTrailer);
    }
    let mut sent = 0u32;
    for &h in &trailer[1..] {
        sent = (sent << 4) | hex_value(h).ok_or(FrameError::BadTrailer)?;
    }
    if crc32(payload) != sent {
        return Err(FrameError::BadCrc);
    }
    Ok(payload)
}

/// Reads the kind letter and checks the version; a command of another version is answered
/// (`VERSION`), any other frame of another version is dropped.
fn header(f: &mut Fields<'_>) -> Result<u8, FrameError> {
    let head = f.next_token()?;
    let (&kind, version) = head.split_first().ok_or(FrameError::Malformed)?;
    if version != [b'0' + PROTOCOL_VERSION] {
        if kind == b'C' {
            let id = u16_field(f).unwrap_or(0);
            return Err(FrameError::BadCommand {
                id,
                reason: Reason::Version,
            });
        }
        return Err(FrameError::UnsupportedVersion);
    }
    Ok(kind)
}

/// A command frame's id and command (after the header).
fn command_frame(f: &mut Fields<'_>) -> Result<Frame, FrameError> {
    let id = u16_field(f).map_err(|_| FrameError::BadCommand {
        id: 0,
        reason: Reason::Malformed,
    })?;
    let command = command(f).map_err(|reason| FrameError::BadCommand { id, reason })?;
    Ok(Frame::Command { id, command })
}

/// Parses a payload whose CRC has been checked.
fn parse_payload(payload: &[u8]) -> Result<Frame, FrameError> {
    let mut f = Fields {
        rest: Some(payload),
    };
    let frame = match header(&mut f)? {
        b'T' => Frame::Telemetry(telemetry(&mut f)?),
        b'H' => Frame::Hello(Hello {
            reset_cause: coded(&mut f, ResetCause::from_code)?,
            reset_count: u16_field(&mut f)?,
        }),
        b'E' => Frame::Event(GateEvent {
            kind: coded(&mut f, GateKind::from_code)?,
            time_us: u32_field(&mut f)?,
            boot: u16_field(&mut f)?,
        }),
        b'C' => return command_frame(&mut f),
        b'A' => Frame::Ack {
            id: u16_field(&mut f)?,
        },
        b'R' => Frame::Reject {
            id: u16_field(&mut f)?,
            reason: Reason::from_token(f.next_token()?).ok_or(FrameError::Malformed)?,
        },
        b'S' => Frame::Status {
            id: u16_field(&mut f)?,
            status: status(&mut f)?,
        },
        b'P' => Frame::Params {
            id: u16_field(&mut f)?,
            values: params(&mut f)?,
        },
        b'W' => Frame::ResidenceSet {
            id: u16_field(&mut f)?,
            model: token_of(f.next_token()?, &ResidenceModel::ALL, ResidenceModel::token)
                .ok_or(FrameError::Malformed)?,
            precession_mrad_s: i16_field(&mut f)?,
            spin_mrad_s: i16_field(&mut f)?,
        },
        b'M' => Frame::Models {
            id: u16_field(&mut f)?,
            axes: [axis_model(&mut f)?, axis_model(&mut f)?],
        },
        _ => return Err(FrameError::UnknownKind),
    };
    f.end()?;
    Ok(frame)
}

/// Decodes one complete frame `$...` ending in `\r\n`, `\n` or `\r` (for tests and one-shot
/// use).
pub fn decode_frame(bytes: &[u8]) -> Result<Frame, FrameError> {
    match bytes {
        [FRAME_START, line @ .., FRAME_END | LINE_END_CR] => parse_line(line),
        _ => Err(FrameError::BadTrailer),
    }
}
