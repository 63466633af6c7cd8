//! Lines from the rig that arrive intact but that this `bowl` cannot read (another protocol
//! version, a kind of frame or a word it does not know): kept as they came, so they are
//! reported as what they are, never as silence.

use model_core::wire::{FRAME_START, FrameError, MAX_FRAME_LEN, PROTOCOL_VERSION};

/// An answer to our request that arrived intact (its CRC checks out) but that this `bowl`
/// cannot read: another protocol version, a kind of frame or a word it does not know. Reported
/// as what it is, with its text, never as "no answer".
#[derive(Debug)]
pub struct UnreadableAnswer {
    /// The request id it answers.
    pub id: u16,
    /// The line as it came, without its line end.
    pub line: String,
    /// What the decoder found wrong with it.
    pub why: FrameError,
}

impl std::fmt::Display for UnreadableAnswer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (id, line) = (self.id, &self.line);
        let what = match self.why {
            FrameError::UnsupportedVersion => format!(
                "in protocol version {} (this bowl speaks version {PROTOCOL_VERSION})",
                line.chars().nth(2).unwrap_or('?')
            ),
            FrameError::UnknownKind => format!(
                "with a kind of frame this bowl does not know ('{}')",
                line.chars().nth(1).unwrap_or('?')
            ),
            _ => "with a word or a field this bowl does not know".to_string(),
        };
        write!(
            f,
            "the rig answered request {id} {what}: `{line}` (it arrived intact; the rig's \
             firmware and bowl differ: update whichever is older)"
        )
    }
}

impl std::error::Error for UnreadableAnswer {}

/// The raw text of the line a [`Decoder`] is reading, kept beside it (fed the same bytes), so a
/// line the decoder refuses can still be shown as it came.
#[derive(Default)]
pub struct LineTap {
    line: Vec<u8>,
}

impl LineTap {
    /// Feeds the byte the decoder gets.
    pub fn push(&mut self, byte: u8) {
        if byte == FRAME_START {
            self.line.clear();
        }
        if self.line.len() < MAX_FRAME_LEN {
            self.line.push(byte);
        }
    }

    /// The text of the line that just ended (or is being read), without its line end.
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.line).trim_end().to_string()
    }

    /// The line that just ended with `error`, if it is an intact answer this bowl cannot read
    /// (its CRC matched: only its version, kind or fields are unknown here; a telemetry, hello,
    /// event or command line is not an answer).
    pub fn unreadable_answer(&self, error: FrameError) -> Option<UnreadableAnswer> {
        if !matches!(
            error,
            FrameError::UnsupportedVersion | FrameError::UnknownKind | FrameError::Malformed
        ) {
            return None;
        }
        let text = std::str::from_utf8(&self.line).ok()?.trim_end();
        let body = text.strip_prefix('$')?;
        if matches!(body.as_bytes().first(), Some(b'T' | b'H' | b'E' | b'C')) {
            return None;
        }
        let id = body.split([',', '*']).nth(1)?.parse().ok()?;
        Some(UnreadableAnswer {
            id,
            line: text.to_string(),
            why: error,
        })
    }
}
