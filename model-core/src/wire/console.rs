//! A command typed by a person at a plain serial console (picocom, tio, screen): the words
//! `bowl send` takes (`status`, `speed 1800 2100`, `set TELEM_HZ 0`), one line, no `$`, id or
//! CRC. The rig answers it with the usual frame, request id 0. Before, such a line got no
//! answer at all: a person at picocom could not tell a typo from a dead rig (a QA pass). ODrive's
//! ASCII protocol takes the same shortcut (its checksum is optional), for the same people.
//!
//! Why a line without a CRC is safe to carry out: the PC's tools send only `$` frames, and a
//! damaged frame cannot become a typed line. A frame's fragment keeps its commas or its `*`
//! (a typed line has neither: the fields are separated by spaces), and the line ends at the
//! first `$`, which starts a frame. Only a person at the keyboard writes words and spaces and
//! Enter. Copies are not looked for (there are no ids): a person who types `start` twice means
//! it twice.

use super::commands::Command;
use super::decode::typed_command;
use super::types::Reason;
use super::{FRAME_END, LINE_END_CR};

/// The longest typed line kept, bytes (`set RT_W_HI_MRAD_S 99999` is 24): longer is dropped.
pub const CONSOLE_LINE_MAX: usize = 64;

/// The line being typed, between frames.
#[derive(Clone)]
pub struct ConsoleLine {
    buf: [u8; CONSOLE_LINE_MAX],
    len: usize,
    /// A byte no typed command has (a frame's `,` or `*`, a control byte, an overflow): the
    /// line is dropped at its end without an answer.
    spoiled: bool,
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
            spoiled: false,
        }
    }

    /// Starts again (a `$` began a frame).
    pub fn clear(&mut self) {
        self.len = 0;
        self.spoiled = false;
    }

    /// Feeds one byte received outside a frame. At a line end: the command the line names,
    /// or the reason the rig refuses it (`Malformed`, `UnknownCommand`, ... as for a frame);
    /// `None` while the line goes on, for a blank line and for one that was not typed.
    pub fn push(&mut self, byte: u8) -> Option<Result<Command, Reason>> {
        match byte {
            LINE_END_CR | FRAME_END => {
                let answer = if self.spoiled { None } else { self.command() };
                self.clear();
                answer
            }
            // Backspace and Delete (what a console sends for the key): the person's correction.
            0x08 | 0x7F => {
                self.len = self.len.saturating_sub(1);
                None
            }
            b',' | b'*' => {
                self.spoiled = true;
                None
            }
            0x20..=0x7E => {
                match self.buf.get_mut(self.len) {
                    Some(slot) => {
                        *slot = byte;
                        self.len += 1;
                    }
                    None => self.spoiled = true,
                }
                None
            }
            _ => {
                self.spoiled = true;
                None
            }
        }
    }

    /// The line as a frame's fields (`speed  1800 2100` is `SPEED,1800,2100`: words upper
    /// case, one comma between them), read by the frame's parser (the image carries no second
    /// one); `None` for a blank line.
    fn command(&mut self) -> Option<Result<Command, Reason>> {
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

    #[test]
    fn blank_lines_and_frame_fragments_get_no_answer() {
        assert_eq!(typed(b"\r\n"), None);
        assert_eq!(typed(b"   \r"), None);
        // A frame whose `$` was lost: commas and `*`, never a typed line.
        assert_eq!(typed(b"C1,12,STOP*A1B2C3D4\r\n"), None);
        assert_eq!(typed(b"C1,12,STOP\r\n"), None);
        assert_eq!(typed(b"stop*\r"), None);
        // Control bytes (line noise) spoil the line; an overlong line is dropped.
        assert_eq!(typed(b"st\x01op\r"), None);
        let mut long = [b' '; CONSOLE_LINE_MAX + 2];
        long[0] = b's';
        long[CONSOLE_LINE_MAX + 1] = b'\r';
        assert_eq!(typed(&long), None);
        // The line after a dropped one is read afresh.
        let mut c = ConsoleLine::new();
        for &b in b"x,y\r" {
            assert_eq!(c.push(b), None);
        }
        let mut out = None;
        for &b in b"stop\r" {
            out = c.push(b).or(out);
        }
        assert_eq!(out, Some(Ok(Command::Stop)));
    }
}
