//! Line numbers of CSV records as a person sees them in an editor, whatever ends the lines: the
//! csv reader's own line count is one short for every row after the first of a CRLF file (the
//! ending a spreadsheet writes on Windows), so errors named the line above the bad one. Records
//! are placed by their byte offset instead.

/// Where each line of a text starts.
pub struct Lines {
    bytes_len: usize,
    starts: Vec<u64>,
}

impl Lines {
    /// The lines of `bytes`: LF, CRLF and lone CR each end one line.
    pub fn of(bytes: &[u8]) -> Self {
        let mut starts = vec![0];
        let mut i = 0;
        while i < bytes.len() {
            match bytes[i] {
                b'\r' if bytes.get(i + 1) == Some(&b'\n') => {
                    i += 1;
                    starts.push(i as u64 + 1);
                }
                b'\r' | b'\n' => starts.push(i as u64 + 1),
                _ => {}
            }
            i += 1;
        }
        Lines {
            bytes_len: bytes.len(),
            starts,
        }
    }

    /// The line (from 1) of the record the csv reader placed at byte `offset` of `bytes` (the
    /// text these lines were made of): its position can sit on the line end before the record
    /// (the LF of a CRLF) or on blank lines it skips.
    pub fn record_line(&self, bytes: &[u8], offset: u64) -> usize {
        debug_assert_eq!(bytes.len(), self.bytes_len);
        let skipped = bytes
            .iter()
            .skip(offset as usize)
            .take_while(|b| matches!(b, b'\r' | b'\n'))
            .count();
        self.line_of(offset + skipped as u64)
    }

    /// The line (from 1) holding byte `offset`.
    fn line_of(&self, offset: u64) -> usize {
        self.starts.partition_point(|&s| s <= offset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_end_at_lf_crlf_and_cr() {
        for text in ["a\nb\nc\n", "a\r\nb\r\nc\r\n", "a\rb\rc\r"] {
            let lines = Lines::of(text.as_bytes());
            let c = text.find('c').unwrap() as u64;
            assert_eq!(lines.line_of(0), 1, "{text:?}");
            assert_eq!(lines.line_of(c), 3, "{text:?}");
            // From just after b's first line end (a CRLF's LF, or a blank line) to c.
            let after_b = text.find('b').unwrap() as u64 + 2;
            assert_eq!(lines.record_line(text.as_bytes(), after_b), 3);
        }
    }
}
