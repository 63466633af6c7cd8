//! The streaming [`Decoder`]: finds lines in a byte stream, resynchronises after garbage, hands
//! each line to [`super::decode`] and keeps the statistics (frames good, corrupt, missing).

use super::decode::{FrameError, parse_command_line, parse_line};
use super::{FRAME_END, FRAME_START, Frame, MAX_FRAME_LEN};

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
    /// Telemetry frames lost: the sum of the sequence-number gaps between accepted telemetry
    /// frames (frames lost before the first or after the last accepted one cannot be seen).
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
    /// Telemetry frames that repeated the previous sequence number.
    pub duplicates: u64,
    /// Device restarts seen (a Hello frame, or telemetry time going backwards): the sequence
    /// gap across a restart is not counted as missing.
    pub restarts: u64,
}

/// A streaming decoder with a fixed [`MAX_FRAME_LEN`]-byte buffer: feed it bytes as they come.
///
/// Resynchronisation: a frame starts at every `$`. A `$` inside a frame drops the partial frame
/// and starts a new one, so a damaged end-of-line costs only its own frame, never the next.
#[derive(Clone)]
pub struct Decoder {
    buf: [u8; MAX_FRAME_LEN],
    len: usize,
    in_frame: bool,
    stats: DecodeStats,
    last_seq: Option<u16>,
    last_time_ms: u32,
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
                restarts: 0,
            },
            last_seq: None,
            last_time_ms: 0,
        }
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
            FRAME_END => {
                self.in_frame = false;
                let result = parse(self.buf.get(..self.len).unwrap_or(&[]));
                Some(self.account(result))
            }
            FRAME_START => {
                // Drop the partial frame (its `$` and body), start again at this `$`.
                self.drop_partial(FrameError::Truncated, 1 + self.len as u64);
                self.in_frame = true;
                self.len = 0;
                Some(Err(FrameError::Truncated))
            }
            b'\r' | 0x20..=0x7E => {
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
            if !self.in_frame {
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
                self.last_seq = None;
            }
            Frame::Telemetry(t) => {
                match self.last_seq {
                    Some(_) if t.time_ms < self.last_time_ms => self.stats.restarts += 1,
                    Some(last) if t.seq == last => self.stats.duplicates += 1,
                    Some(last) => {
                        self.stats.frames_missing += u64::from(t.seq.wrapping_sub(last) - 1)
                    }
                    None => {}
                }
                self.last_seq = Some(t.seq);
                self.last_time_ms = t.time_ms;
            }
            _ => {}
        }
    }
}
