//! A command typed by a person at a plain serial console (picocom, tio, screen): the words
//! `bowl send` takes (`status`, `speed 1800 2100`, `set TELEM_HZ 0`), one line, no `$`, id or
//! CRC. The rig answers it with the usual frame, request id 0. Before, such a line got no
//! answer at all: a person at picocom could not tell a typo from a dead rig (a QA pass). ODrive's
//! ASCII protocol takes the same shortcut (its checksum is optional), for the same people.
//!
//! Every line that is not blank gets an answer: a line that is not words (an arrow key's
//! escape sequence, a `µ`, a Ctrl key, more than [`CONSOLE_LINE_MAX`] bytes) is refused
//! `UNREADABLE`. Words are parted by spaces or Tabs; Backspace and Delete erase the last
//! character, Ctrl-C and Ctrl-U the whole line, as in a shell.
//!
//! Why a line without a CRC is safe to carry out: the PC's tools send only `$` frames, and a
//! damaged frame cannot become a typed line. A frame's fragment keeps its commas or its `*`
//! (a typed line has neither: the fields are separated by spaces), which refuse the line, and
//! the line ends at the first `$`, which starts a frame. Only a person at the keyboard writes
//! words and spaces and Enter. Copies are not looked for (there are no ids): a person who
//! types `start` twice means it twice.

use super::commands::Command;
use super::decode::typed_command;
use super::types::Reason;
use super::{FRAME_END, LINE_END_CR};

/// The longest typed line read, bytes (`set RT_W_HI_MRAD_S 99999` is 24): longer is refused
/// ([`Reason::Unreadable`]).
pub const CONSOLE_LINE_MAX: usize = 64;

/// Ctrl-C and Ctrl-U: drop the line typed so far, as a shell does (a person's "start again").
const CANCEL_LINE: [u8; 2] = [0x03, 0x15];

/// The line being typed, between frames.
#[derive(Clone)]
pub struct ConsoleLine {
    buf: [u8; CONSOLE_LINE_MAX],
    /// Bytes typed and not erased, also past the buffer: Backspace erases what was never kept
    /// first, so a line brought back under the limit is read as the person sees it.
    len: usize,
}

impl Default for ConsoleLine {
    fn default() -> Self {
        Self::new()
    }
}

impl ConsoleLine {
    /// An empty line.
    pub const fn new() -> Self {
        Self {
            buf: [0; CONSOLE_LINE_MAX],
            len: 0,
        }
    }

    /// Starts again (a `$` began a frame).
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Feeds one byte received outside a frame. At a line end: the command the line names,
    /// or the reason the rig refuses it (`Malformed`, `UnknownCommand`, ... as for a frame;
    /// `Unreadable` for a line that is not words); `None` while the line goes on and for a
    /// blank line (the `\n` of every CRLF, a frame's too, ends one).
    pub fn push(&mut self, byte: u8) -> Option<Result<Command, Reason>> {
        match byte {
            LINE_END_CR | FRAME_END => {
                let answer = self.command();
                self.clear();
                return answer;
            }
            // Backspace and Delete (what a console sends for the key): the person's correction.
            0x08 | 0x7F => self.len = self.len.saturating_sub(1),
            b if CANCEL_LINE.contains(&b) => self.clear(),
            // The rest of a character beyond ASCII (UTF-8): one byte stands for it, so one
            // Backspace erases a typed `µ` as it does on the screen.
            0x80..=0xBF if self.last().is_some_and(|b| b >= 0x80) => {}
            // Tab parts words as a space does (as `bowl send` splits them). Any other byte is
            // kept as it came: one no command has (a control byte, an escape sequence's ESC,
            // beyond ASCII, a frame's `,` or `*`) refuses the line at its end unless erased.
            _ => {
                let byte = if byte == b'\t' { b' ' } else { byte };
                if let Some(slot) = self.buf.get_mut(self.len) {
                    *slot = byte;
                }
                self.len = self.len.saturating_add(1);
            }
        }
        None
    }

    /// The last byte kept, if the line is not past the buffer.
    fn last(&self) -> Option<u8> {
        self.buf.get(self.len.checked_sub(1)?).copied()
    }

    /// The line as a frame's fields (`speed  1800 2100` is `SPEED,1800,2100`: words upper
    /// case, one comma between them), read by the frame's parser (the image carries no second
    /// one); `None` for a blank line.
    fn command(&mut self) -> Option<Result<Command, Reason>> {
        // A line that is not words is answered, never dropped: an arrow key or a `µ` typed by
        // a person met silence before, as if the rig were dead. What is left of a frame that
        // lost its `$` (its `,` or `*`) is refused here too, so it is never carried out.
        let line = self.buf.get(..self.len);
        let words = |l: &[u8]| {
            l.iter()
                .all(|&b| matches!(b, 0x20..=0x7E) && b != b',' && b != b'*')
        };
        if !line.is_some_and(words) {
            return Some(Err(Reason::Unreadable));
        }
        let mut out = 0;
        let mut gap = false;
        for i in 0..self.len {
            let b = self.buf.get(i).copied().unwrap_or(b' ');
            if b == b' ' {
                gap = out > 0;
                continue;
            }
            // The fields are written over the line's own bytes: never ahead of the reading.
            if gap {
                *self.buf.get_mut(out)? = b',';
                out += 1;
                gap = false;
            }
            *self.buf.get_mut(out)? = b.to_ascii_uppercase();
            out += 1;
        }
        (out > 0).then(|| typed_command(self.buf.get(..out).unwrap_or(&[])))
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::{vec, vec::Vec};

    use super::*;

    fn typed(line: &[u8]) -> Option<Result<Command, Reason>> {
        let mut c = ConsoleLine::new();
        let mut out = None;
        for &b in line {
            if let Some(r) = c.push(b) {
                assert!(out.is_none(), "one answer per line");
                out = Some(r);
            }
        }
        out
    }

    #[test]
    fn a_typed_line_is_the_command_bowl_send_takes() {
        assert_eq!(typed(b"status\r"), Some(Ok(Command::GetStatus)));
        assert_eq!(
            typed(b"speed 1800 2100\r\n"),
            Some(Ok(Command::SetSpeeds {
                precession_mrad_s: 1800,
                spin_mrad_s: 2100
            }))
        );
        assert_eq!(
            typed(b"  set TELEM_HZ   0\n"),
            Some(Ok(Command::SetParam {
                id: super::super::ParamId::TelemetryHz,
                value: 0
            }))
        );
        // Backspace corrects the line, as the person sees it.
        assert_eq!(typed(b"statx\x08us\r"), Some(Ok(Command::GetStatus)));
        assert_eq!(typed(b"stopp\x7f\r"), Some(Ok(Command::Stop)));
    }

    #[test]
    fn a_typo_is_refused_with_the_frames_reason() {
        assert_eq!(typed(b"statsu\r"), Some(Err(Reason::UnknownCommand)));
        assert_eq!(typed(b"speed 1800\r"), Some(Err(Reason::Malformed)));
        assert_eq!(typed(b"speed 1800 99999\r"), Some(Err(Reason::Range)));
        assert_eq!(typed(b"set NOPE 1\r"), Some(Err(Reason::UnknownParam)));
        assert_eq!(typed(b"status now\r"), Some(Err(Reason::Malformed)));
        assert_eq!(typed(b"speed 1800 2100 5\r"), Some(Err(Reason::Malformed)));
        // Lower case is the person's; the fields are read as in a frame (canonical integers).
        assert_eq!(
            typed(b"rtime cori 2500\r"),
            Some(Ok(Command::SetResidence {
                model: super::super::ResidenceModel::Coriolis,
                time_ms: 2500
            }))
        );
        assert_eq!(typed(b"speed +1800 2100\r"), Some(Err(Reason::Malformed)));
    }

    const UNREADABLE: Option<Result<Command, Reason>> = Some(Err(Reason::Unreadable));

    #[test]
    fn blank_lines_get_no_answer_and_every_line_end_is_one() {
        for blank in [&b"\r"[..], b"\n", b"\r\n", b"   \r", b" \t \n"] {
            assert_eq!(typed(blank), None, "{blank:?}");
        }
        // CR, LF and CRLF end a line once each (`typed` checks one answer per line).
        for line in [&b"stop\r"[..], b"stop\n", b"stop\r\n"] {
            assert_eq!(typed(line), Some(Ok(Command::Stop)), "{line:?}");
        }
    }

    /// A person's keys: before, a Tab or an arrow key dropped the line without an answer, as
    /// if the rig were dead.
    #[test]
    fn tab_parts_words_and_a_key_that_types_no_word_is_answered() {
        assert_eq!(
            typed(b"speed\t1800\t 2100\r"),
            Some(Ok(Command::SetSpeeds {
                precession_mrad_s: 1800,
                spin_mrad_s: 2100
            }))
        );
        // An arrow key (ESC [ A), alone or after a command; a Ctrl key; a typed `µ` (UTF-8).
        assert_eq!(typed(b"\x1b[A\r"), UNREADABLE);
        assert_eq!(typed(b"status\x1b[D\r"), UNREADABLE);
        assert_eq!(typed(b"st\x01op\r"), UNREADABLE);
        assert_eq!(typed("rtime cori 800µs\r".as_bytes()), UNREADABLE);
        // One Backspace erases the `µ`, as it does on the screen.
        assert_eq!(typed("stopµ\x7f\r".as_bytes()), Some(Ok(Command::Stop)));
        assert_eq!(
            typed("stop\u{2191}\x08\r".as_bytes()),
            Some(Ok(Command::Stop))
        );
    }

    #[test]
    fn ctrl_c_and_ctrl_u_drop_the_line_typed_so_far() {
        assert_eq!(typed(b"speed 1800 2100\x03stop\r"), Some(Ok(Command::Stop)));
        assert_eq!(typed(b"start\x15stop\r"), Some(Ok(Command::Stop)));
        // Also a line that could not be read, and one past the buffer.
        assert_eq!(typed(b"sp,e\x1b\x15stop\r"), Some(Ok(Command::Stop)));
        let mut long = vec![b'x'; CONSOLE_LINE_MAX + 9];
        long.extend(b"\x03stop\r");
        assert_eq!(typed(&long), Some(Ok(Command::Stop)));
        // Ctrl-C alone ends nothing: no answer until Enter, and a blank line then.
        assert_eq!(typed(b"stop\x03\r"), None);
    }

    #[test]
    fn a_line_past_the_buffer_is_answered_and_backspace_brings_it_back() {
        let mut line = b"status".to_vec();
        line.resize(CONSOLE_LINE_MAX, b' ');
        let mut exact = line.clone();
        exact.push(b'\r');
        assert_eq!(typed(&exact), Some(Ok(Command::GetStatus)));
        let mut over = line.clone();
        over.extend(b"x\r");
        assert_eq!(typed(&over), UNREADABLE);
        // Typed past the end, then erased back under it: read as the person sees it.
        line.extend(b"xxxxx\x7f\x7f\x7f\x7f\x7f\r");
        assert_eq!(typed(&line), Some(Ok(Command::GetStatus)));
    }

    #[test]
    fn frame_fragments_are_refused_not_carried_out() {
        // A frame whose `$` was lost: commas and `*`, never a typed line.
        assert_eq!(typed(b"C1,12,STOP*A1B2C3D4\r\n"), UNREADABLE);
        assert_eq!(typed(b"C1,12,STOP\r\n"), UNREADABLE);
        assert_eq!(typed(b"stop*\r"), UNREADABLE);
        assert_eq!(typed(b"speed,1800,2100\r"), UNREADABLE);
        // The line after a refused one is read afresh.
        let mut c = ConsoleLine::new();
        let answers: Vec<_> = b"x,y\rstop\r".iter().filter_map(|&b| c.push(b)).collect();
        assert_eq!(answers, [Err(Reason::Unreadable), Ok(Command::Stop)]);
    }
}
