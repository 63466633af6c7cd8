//! The streaming [`Decoder`]: finds lines in a byte stream, resynchronises after garbage, hands
//! each line to [`super::decode`] and keeps the statistics (frames good, corrupt, missing).

use super::decode::{FrameError, parse_command_line, parse_line};
use super::frame::Frame;
use super::{FRAME_END, FRAME_START, LINE_END_CR, MAX_FRAME_LEN};

/// Counters of a [`Decoder`]. Every byte fed is either in a good frame or in `bytes_skipped`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DecodeStats {
    /// Bytes fed.
    pub bytes: u64,
    /// Frames accepted.
    pub frames_ok: u64,
    /// Frame candidates (a `$` followed by bytes) that were dropped: the sum of the four
    /// counters below. One damaged frame can count twice (a `$` hit inside it splits it).
    pub frames_corrupt: u64,
    /// Telemetry frames that never arrived in any form: the gaps between accepted telemetry
    /// frames (by sequence number, with the device clock deciding how often the 16-bit number
    /// wrapped), less the corrupt candidates seen in each gap, which are counted there. So
    /// `frames_ok + frames_corrupt + frames_missing` is the number of frames sent (more only
    /// where a `$` hit split a frame). Frames lost before the first or after the last accepted
    /// one cannot be seen.
    pub frames_missing: u64,
    /// Bytes not part of an accepted frame: line noise plus the bytes of dropped frames.
    pub bytes_skipped: u64,
    /// Dropped: CRC mismatch.
    pub bad_crc: u64,
    /// Dropped: bad trailer, unknown kind or version, malformed fields (CRC matched or absent).
    pub malformed: u64,
    /// Dropped: longer than [`MAX_FRAME_LEN`].
    pub oversize: u64,
    /// Dropped: cut by a `$` or a byte that cannot be in a frame.
    pub truncated: u64,
    /// Telemetry frames that repeated the previous sequence number and device time.
    pub duplicates: u64,
    /// Telemetry frames that came late (up to [`REORDER_FRAMES`] behind the newest): counted
    /// here and no longer as missing.
    pub reordered: u64,
    /// Device restarts seen (a Hello frame, or telemetry time going back further than a late
    /// frame could): the sequence gap across a restart is not counted as missing. A wrap of
    /// the 32-bit device clock is not a restart.
    pub restarts: u64,
}

/// How far behind the newest telemetry frame a frame may arrive and count as late rather than
/// as a device restart, in frames.
pub const REORDER_FRAMES: u16 = 16;

/// A streaming decoder with a fixed [`MAX_FRAME_LEN`]-byte buffer: feed it bytes as they come.
///
/// Resynchronisation: a frame starts at every `$`. A `$` inside a frame drops the partial frame
/// and starts a new one, so a damaged end-of-line costs only its own frame, never the next.
///
/// Line ends: `\r`, `\n` or `\r\n` end a line (the rig sends `\r\n` so any serial console shows
/// one line per frame; a console sends `\r` on Enter). The `\n` of a `\r\n` belongs to the line
/// it ends: it is neither a second line end nor noise.
#[derive(Clone)]
pub struct Decoder {
    buf: [u8; MAX_FRAME_LEN],
    len: usize,
    in_frame: bool,
    stats: DecodeStats,
    /// Sequence number and device time of the newest accepted telemetry frame.
    last: Option<(u16, u32)>,
    /// Device time between two consecutive telemetry frames, ms (0 until seen).
    period_ms: u32,
    /// Corrupt candidates since the newest accepted telemetry frame.
    corrupt_in_gap: u64,
    /// The last line ended at a `\r` (and was accepted: `Some(true)`): a `\n` right after it
    /// completes that line end.
    cr_ended: Option<bool>,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    /// A decoder waiting for the first `$`.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_FRAME_LEN],
            len: 0,
            in_frame: false,
            stats: DecodeStats {
                bytes: 0,
                frames_ok: 0,
                frames_corrupt: 0,
                frames_missing: 0,
                bytes_skipped: 0,
                bad_crc: 0,
                malformed: 0,
                oversize: 0,
                truncated: 0,
                duplicates: 0,
                reordered: 0,
                restarts: 0,
            },
            last: None,
            period_ms: 0,
            corrupt_in_gap: 0,
            cr_ended: None,
        }
    }

    /// Whether a frame has begun (its `$` came) and not yet ended.
    pub fn in_frame(&self) -> bool {
        self.in_frame
    }

    /// The counters so far.
    pub fn stats(&self) -> &DecodeStats {
        &self.stats
    }

    /// Feeds one byte; returns a frame or an error when a line ends or is dropped.
    pub fn push(&mut self, byte: u8) -> Option<Result<Frame, FrameError>> {
        self.push_with(byte, parse_line)
    }

    /// Feeds one byte on the rig's side: like [`Decoder::push`], but complete lines are parsed
    /// with [`parse_command_line`] (frames other than commands are counted as malformed).
    pub fn push_command(&mut self, byte: u8) -> Option<Result<Frame, FrameError>> {
        self.push_with(byte, parse_command_line)
    }

    #[inline(always)]
    fn push_with(
        &mut self,
        byte: u8,
        parse: impl FnOnce(&[u8]) -> Result<Frame, FrameError>,
    ) -> Option<Result<Frame, FrameError>> {
        if let Some(accepted) = self.cr_ended.take()
            && byte == FRAME_END
        {
            // The `\n` of a `\r\n`: a byte of the line it ends (skipped if that line was).
            self.stats.bytes += 1;
            if !accepted {
                self.stats.bytes_skipped += 1;
            }
            return None;
        }
        self.stats.bytes += 1;
        if !self.in_frame {
            if byte == FRAME_START {
                self.in_frame = true;
                self.len = 0;
            } else {
                self.stats.bytes_skipped += 1;
            }
            return None;
        }
        match byte {
            FRAME_END | LINE_END_CR => {
                self.in_frame = false;
                let result = parse(self.buf.get(..self.len).unwrap_or(&[]));
                let result = self.account(result);
                if byte == LINE_END_CR {
                    self.cr_ended = Some(result.is_ok());
                }
                Some(result)
            }
            FRAME_START => {
                // Drop the partial frame (its `$` and body), start again at this `$`.
                self.drop_partial(FrameError::Truncated, 1 + self.len as u64);
                self.in_frame = true;
                self.len = 0;
                Some(Err(FrameError::Truncated))
            }
            0x20..=0x7E => {
                if let Some(slot) = self.buf.get_mut(self.len) {
                    *slot = byte;
                    self.len += 1;
                    None
                } else {
                    self.in_frame = false;
                    self.drop_partial(FrameError::Oversize, 2 + self.len as u64);
                    Some(Err(FrameError::Oversize))
                }
            }
            _ => {
                self.in_frame = false;
                self.drop_partial(FrameError::Truncated, 2 + self.len as u64);
                Some(Err(FrameError::Truncated))
            }
        }
    }

    /// Ends the stream (end of a capture file): a partial frame still waiting for its `\n` is
    /// dropped and counted as truncated, so every byte fed is accounted for.
    pub fn finish(&mut self) -> Option<FrameError> {
        if !self.in_frame {
            return None;
        }
        self.in_frame = false;
        self.drop_partial(FrameError::Truncated, 1 + self.len as u64);
        Some(FrameError::Truncated)
    }

    /// Feeds a slice, calling `on_frame` for every line that ended or was dropped (with the
    /// counters as they are right after it). Same result as [`Decoder::push`] byte by byte,
    /// but runs of ordinary bytes are scanned and copied in bulk (the host's replay speed).
    pub fn push_slice(
        &mut self,
        mut bytes: &[u8],
        mut on_frame: impl FnMut(Result<Frame, FrameError>, &DecodeStats),
    ) {
        while !bytes.is_empty() {
            if self.cr_ended.is_some() {
                // The byte after a `\r` line end: only the byte-wise path knows a `\n` there.
            } else if !self.in_frame {
                // Line noise: skip to the next `$`.
                let noise = bytes
                    .iter()
                    .position(|&b| b == FRAME_START)
                    .unwrap_or(bytes.len());
                self.stats.bytes += noise as u64;
                self.stats.bytes_skipped += noise as u64;
                bytes = bytes.get(noise..).unwrap_or(&[]);
            } else {
                // Frame body: take the printable run that fits in the buffer.
                let room = self.buf.len().saturating_sub(self.len);
                let limit = bytes.len().min(room);
                let head = bytes.get(..limit).unwrap_or(&[]);
                let plain = head
                    .iter()
                    .position(|&b| !(0x20..=0x7E).contains(&b) || b == FRAME_START)
                    .unwrap_or(limit);
                if let (Some(dst), Some(src)) = (
                    self.buf.get_mut(self.len..self.len + plain),
                    bytes.get(..plain),
                ) {
                    dst.copy_from_slice(src);
                    self.len += plain;
                    self.stats.bytes += plain as u64;
                }
                bytes = bytes.get(plain..).unwrap_or(&[]);
            }
            // The next byte is a delimiter, a control byte or an overflow: the byte-wise path.
            if let Some((&b, rest)) = bytes.split_first() {
                bytes = rest;
                if let Some(r) = self.push(b) {
                    on_frame(r, &self.stats);
                }
            }
        }
    }

    fn drop_partial(&mut self, error: FrameError, bytes: u64) {
        self.stats.bytes_skipped += bytes;
        self.count_error(error);
    }

    fn count_error(&mut self, error: FrameError) {
        self.stats.frames_corrupt += 1;
        self.corrupt_in_gap += 1;
        match error {
            FrameError::BadCrc => self.stats.bad_crc += 1,
            FrameError::Oversize => self.stats.oversize += 1,
            FrameError::Truncated => self.stats.truncated += 1,
            _ => self.stats.malformed += 1,
        }
    }

    fn account(&mut self, result: Result<Frame, FrameError>) -> Result<Frame, FrameError> {
        // `$`, body, `\n`.
        let frame_bytes = self.len as u64 + 2;
        match &result {
            Ok(frame) => {
                self.stats.frames_ok += 1;
                self.track_sequence(frame);
            }
            Err(e) => {
                self.stats.bytes_skipped += frame_bytes;
                self.count_error(*e);
            }
        }
        result
    }

    fn track_sequence(&mut self, frame: &Frame) {
        match frame {
            Frame::Hello(_) => {
                self.stats.restarts += 1;
                self.last = None;
                self.corrupt_in_gap = 0;
            }
            Frame::Telemetry(t) => self.track_telemetry(t.seq, t.time_ms),
            _ => {}
        }
    }

    fn track_telemetry(&mut self, seq: u16, time_ms: u32) {
        let corrupt = core::mem::take(&mut self.corrupt_in_gap);
        let Some((last_seq, last_ms)) = self.last else {
            self.last = Some((seq, time_ms));
            return;
        };
        // Wrapping differences: a wrap of the 32-bit clock or the 16-bit sequence is a step
        // forward like any other.
        let dt_ms = time_ms.wrapping_sub(last_ms);
        let dseq = seq.wrapping_sub(last_seq);
        if dt_ms > u32::MAX / 2 {
            // Earlier than the newest frame: a late frame, or a device that started again.
            let behind = last_seq.wrapping_sub(seq);
            if (1..=REORDER_FRAMES).contains(&behind) {
                self.stats.reordered += 1;
                self.stats.frames_missing = self.stats.frames_missing.saturating_sub(1);
                // The newest frame stays the reference.
                self.corrupt_in_gap = corrupt;
                return;
            }
            self.stats.restarts += 1;
        } else {
            match self.sequence_advance(dseq, dt_ms) {
                0 => self.stats.duplicates += 1,
                advance => {
                    self.stats.frames_missing += (advance - 1).saturating_sub(corrupt);
                    if advance == 1 && dt_ms > 0 {
                        self.period_ms = dt_ms;
                    }
                }
            }
        }
        self.last = Some((seq, time_ms));
    }

    /// Frames sent from the newest to this one (0: the same frame again): the sequence
    /// difference plus as many whole 16-bit wraps as the device clock says went by, once the
    /// telemetry period is known (a 30-minute outage at 50 Hz is 90,000 frames, not 90,000
    /// mod 65,536).
    fn sequence_advance(&self, dseq: u16, dt_ms: u32) -> u64 {
        const WRAP: u64 = 1 << 16;
        let dseq = u64::from(dseq);
        if self.period_ms == 0 {
            return dseq;
        }
        let period = u64::from(self.period_ms);
        let by_time = (u64::from(dt_ms) + period / 2) / period;
        let wraps = (by_time.saturating_sub(dseq) + WRAP / 2) / WRAP;
        dseq + wraps * WRAP
    }
}
