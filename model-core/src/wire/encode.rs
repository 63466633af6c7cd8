//! The encoder: a [`Frame`] to its text line `$K1,field,...*CRC32\n`, into a caller's buffer.

use super::commands::{Command, FieldKind};
use super::crc::crc32;
use super::frame::Frame;
use super::params::{PARAM_COUNT, ParamId};
use super::types::{
    AxisModel, DUTY_MAX_BP, MODEL_FIELD_MAX, MotorTelemetry, RESIDENCE_MAX_MS, Residence, Telemetry,
};
use super::{FRAME_END, FRAME_START, LINE_END_CR, MAX_FRAME_LEN, PROTOCOL_VERSION};

/// Why a frame could not be encoded. Nothing was written that could be mistaken for a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// The output buffer is shorter than the frame ([`MAX_FRAME_LEN`] always suffices).
    BufferTooSmall,
    /// A field is outside its wire range (a duty beyond 10 000 bp, a residence time beyond
    /// [`RESIDENCE_MAX_MS`], a parameter outside its range): the decoder would refuse it.
    FieldOutOfRange,
}

/// A bounded writer over a byte slice.
struct Out<'a> {
    buf: &'a mut [u8],
    len: usize,
    overflow: bool,
}

impl Out<'_> {
    fn byte(&mut self, b: u8) {
        match self.buf.get_mut(self.len) {
            Some(slot) => {
                *slot = b;
                self.len += 1;
            }
            None => self.overflow = true,
        }
    }

    fn bytes(&mut self, bs: &[u8]) {
        for &b in bs {
            self.byte(b);
        }
    }

    /// `,` then the token.
    fn token(&mut self, t: &str) {
        self.byte(b',');
        self.bytes(t.as_bytes());
    }

    /// `,` then the integer in canonical decimal (no `+`, no leading zeros, no `-0`).
    fn int(&mut self, v: i64) {
        self.byte(b',');
        if v < 0 {
            self.byte(b'-');
        }
        let mut wide = v.unsigned_abs();
        let mut digits = [0u8; 20];
        let mut n = 0;
        // Every wire value fits in 32 bits, which the MCU divides in hardware (a 64-bit
        // division is a library call, about 100 instructions a digit); a wider value's low
        // digits take the 64-bit way first.
        while wide > u64::from(u32::MAX) {
            digits[n] = b'0' + (wide % 10) as u8;
            n += 1;
            wide /= 10;
        }
        let mut mag = wide as u32;
        loop {
            digits[n] = b'0' + (mag % 10) as u8;
            n += 1;
            mag /= 10;
            if mag == 0 {
                break;
            }
        }
        for &d in digits[..n].iter().rev() {
            self.byte(d);
        }
    }
}

/// The fields of a MODELS answer after its id, in wire order.
#[inline(never)]
fn model_fields(axes: &[AxisModel; 2]) -> [u32; 12] {
    let mut v = [0u32; 12];
    for (chunk, a) in v.chunks_exact_mut(6).zip(axes) {
        chunk.copy_from_slice(&[
            u32::from(a.identified),
            a.back_emf_uv_per_rad_s,
            a.friction_ppm,
            a.time_constant_us,
            a.kp_ppm_per_rad_s,
            a.ki_ppm_per_rad,
        ]);
    }
    v
}

fn hex_upper(nibble: u32) -> u8 {
    b"0123456789ABCDEF"[(nibble & 0xF) as usize]
}

fn check_motor(m: &MotorTelemetry) -> bool {
    (-DUTY_MAX_BP..=DUTY_MAX_BP).contains(&m.duty_bp)
}

fn check_residence(r: Residence) -> bool {
    !matches!(r, Residence::Ms(ms) if ms > RESIDENCE_MAX_MS)
}

fn check_param(id: ParamId, v: i32) -> bool {
    let (lo, hi) = id.range();
    (lo..=hi).contains(&v)
}

fn fields_in_range(frame: &Frame) -> bool {
    match frame {
        Frame::Telemetry(t) => telemetry_in_range(t),
        Frame::Command { command, .. } => command.in_range(),
        Frame::Params { values, .. } => ParamId::ALL
            .iter()
            .zip(values.iter())
            .all(|(&id, &v)| check_param(id, v)),
        Frame::Status { status, .. } => {
            check_param(ParamId::TelemetryHz, i32::from(status.telemetry_hz))
        }
        Frame::Models { axes, .. } => model_fields(axes).iter().all(|&v| v <= MODEL_FIELD_MAX),
        _ => true,
    }
}

fn telemetry_in_range(t: &Telemetry) -> bool {
    check_motor(&t.precession)
        && check_motor(&t.spin)
        && check_residence(t.residence_flat)
        && check_residence(t.residence_coriolis)
}

fn motor(out: &mut Out<'_>, m: &MotorTelemetry) {
    out.int(m.set_mrad_s.into());
    out.int(m.measured_mrad_s.into());
    out.int(m.duty_bp.into());
    out.int(m.pulses.into());
}

fn body(out: &mut Out<'_>, frame: &Frame) {
    match frame {
        Frame::Telemetry(t) => {
            out.int(t.time_ms.into());
            out.int(t.seq.into());
            out.int(t.state.code().into());
            out.int(t.fault.code().into());
            motor(out, &t.precession);
            motor(out, &t.spin);
            out.int(t.bowl_mrad_s.into());
            out.int(t.residence_flat.to_wire());
            out.int(t.residence_coriolis.to_wire());
        }
        Frame::Hello(h) => {
            out.int(h.reset_cause.code().into());
            out.int(h.reset_count.into());
        }
        Frame::Event(e) => {
            out.int(e.kind.code().into());
            out.int(e.time_us.into());
            out.int(e.boot.into());
        }
        Frame::Command { id, command } => {
            out.int((*id).into());
            command_body(out, command);
        }
        Frame::Ack { id } => out.int((*id).into()),
        Frame::Reject { id, reason } => {
            out.int((*id).into());
            out.token(reason.token());
        }
        Frame::Status { id, status } => {
            out.int((*id).into());
            out.int(status.state.code().into());
            out.int(status.fault.code().into());
            out.int(status.reset_cause.code().into());
            out.int(status.reset_count.into());
            out.int(status.uptime_ms.into());
            out.int(status.telemetry_hz.into());
            out.int(status.flags.into());
        }
        Frame::Params { id, values } => {
            out.int((*id).into());
            for v in values.iter().take(PARAM_COUNT) {
                out.int((*v).into());
            }
        }
        Frame::Models { id, axes } => {
            out.int((*id).into());
            for v in model_fields(axes) {
                out.int(v.into());
            }
        }
        Frame::ResidenceSet {
            id,
            model,
            precession_mrad_s,
            spin_mrad_s,
        } => {
            out.int((*id).into());
            out.token(model.token());
            out.int((*precession_mrad_s).into());
            out.int((*spin_mrad_s).into());
        }
    }
}

/// The command's word and fields, as the command table declares them.
fn command_body(out: &mut Out<'_>, command: &Command) {
    let kind = command.kind();
    out.token(kind.token());
    for (field, v) in kind.fields().iter().zip(command.values()) {
        match field.kind {
            FieldKind::Int { .. } | FieldKind::ParamValue => out.int(v),
            FieldKind::Choice(tokens) => out.token(
                usize::try_from(v)
                    .ok()
                    .and_then(|i| tokens.get(i))
                    .unwrap_or(&""),
            ),
            FieldKind::ParamName => out.token(
                usize::try_from(v)
                    .ok()
                    .and_then(|i| ParamId::ALL.get(i))
                    .map_or("", |p| p.token()),
            ),
        }
    }
}

/// The kind letter of a frame.
pub fn kind_letter(frame: &Frame) -> u8 {
    match frame {
        Frame::Telemetry(_) => b'T',
        Frame::Hello(_) => b'H',
        Frame::Event(_) => b'E',
        Frame::Command { .. } => b'C',
        Frame::Ack { .. } => b'A',
        Frame::Reject { .. } => b'R',
        Frame::Status { .. } => b'S',
        Frame::Params { .. } => b'P',
        Frame::Models { .. } => b'M',
        Frame::ResidenceSet { .. } => b'W',
    }
}

/// Writes `frame` as one line into `buf` and returns its length in bytes.
///
/// The line is `$`, the kind letter, the protocol version, the fields (each after a `,`),
/// `*`, the CRC-32 of everything between `$` and `*` as 8 upper-case hex digits, and `\r\n`.
pub fn encode(frame: &Frame, buf: &mut [u8]) -> Result<usize, EncodeError> {
    if !fields_in_range(frame) {
        return Err(EncodeError::FieldOutOfRange);
    }
    let mut out = Out {
        buf,
        len: 0,
        overflow: false,
    };
    out.byte(FRAME_START);
    out.byte(kind_letter(frame));
    out.byte(b'0' + PROTOCOL_VERSION);
    body(&mut out, frame);
    let crc = crc32(out.buf.get(1..out.len).unwrap_or(&[]));
    out.byte(b'*');
    for shift in (0..8).rev() {
        out.byte(hex_upper(crc >> (shift * 4)));
    }
    out.byte(LINE_END_CR);
    out.byte(FRAME_END);
    if out.overflow || out.len > MAX_FRAME_LEN {
        return Err(EncodeError::BufferTooSmall);
    }
    Ok(out.len)
}
