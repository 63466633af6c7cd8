//! Text for the monitor's screen in lines no wider than the terminal: wrapped at spaces,
//! never cut at the right edge (the end of a fault line says what to do).

use ratatui::text::{Line, Span};

/// `text` in lines of at most `width` characters, broken at spaces where there are any (a word
/// longer than the width is cut into pieces): nothing is lost past the right edge.
pub fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split(' ') {
        let mut word = word.to_string();
        loop {
            let room = width - line.chars().count();
            let need = word.chars().count() + usize::from(!line.is_empty());
            if need <= room {
                if !line.is_empty() {
                    line.push(' ');
                }
                line.push_str(&word);
                break;
            }
            if !line.is_empty() {
                lines.push(std::mem::take(&mut line));
                continue;
            }
            // A word wider than a whole line.
            let cut: String = word.chars().take(width).collect();
            word = word.chars().skip(width).collect();
            lines.push(cut);
        }
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

/// `text` in at most `max` characters (at least 3): whole when it fits, else its start and its
/// end with `…` between (a port's path differs from another's at its end, and its start says
/// where it lives).
pub fn shorten(text: &str, max: usize) -> String {
    let len = text.chars().count();
    let max = max.max(3);
    if len <= max {
        return text.to_string();
    }
    let head = (max - 1) / 3;
    let tail = max - 1 - head;
    let start: String = text.chars().take(head).collect();
    let end: String = text.chars().skip(len - tail).collect();
    format!("{start}…{end}")
}

/// Styled pieces in lines of at most `width` characters: a piece goes on the next line when it
/// does not fit, and a piece wider than a line is wrapped itself (never cut at the edge).
pub fn pack(spans: Vec<Span<'_>>, width: usize) -> Vec<Line<'_>> {
    let mut lines: Vec<Vec<Span>> = vec![Vec::new()];
    let mut used = 0;
    for span in spans {
        let len = span.content.chars().count();
        if used + len > width && used > 0 {
            lines.push(Vec::new());
            used = 0;
        }
        if len <= width {
            used += len;
            if let Some(l) = lines.last_mut() {
                l.push(span);
            }
            continue;
        }
        for piece in wrap(&span.content, width) {
            if used > 0 {
                lines.push(Vec::new());
            }
            used = piece.chars().count();
            if let Some(l) = lines.last_mut() {
                l.push(Span::styled(piece, span.style));
            }
        }
    }
    lines.into_iter().map(Line::from).collect()
}

#[cfg(test)]
mod tests {
    use super::{pack, shorten, wrap};

    #[test]
    fn a_long_name_keeps_its_start_and_end() {
        assert_eq!(shorten("/dev/ttyUSB0", 40), "/dev/ttyUSB0");
        let long = format!("/tmp/{}/rig_port_link", "lab-bench-".repeat(18));
        let short = shorten(&long, 30);
        assert_eq!(short.chars().count(), 30);
        assert_eq!(short, "/tmp/lab-…bench-/rig_port_link");
    }
    use ratatui::text::Span;

    #[test]
    fn wrapping_keeps_every_word_and_no_line_is_wider_than_the_screen() {
        let text = " FAULT 2: the rig stopped the motors. The spin sensor gave no pulses. Type \
                    `:clear` once the cause is fixed";
        for width in [20, 40, 57, 120] {
            let lines = wrap(text, width);
            assert!(
                lines.iter().all(|l| l.chars().count() <= width),
                "{lines:?}"
            );
            assert_eq!(
                lines.join(" ").split_whitespace().collect::<Vec<_>>(),
                text.split_whitespace().collect::<Vec<_>>()
            );
        }
        assert_eq!(
            wrap(&"x".repeat(45), 20),
            ["x".repeat(20), "x".repeat(20), "x".repeat(5)]
        );
        assert_eq!(wrap("", 20), [""]);
    }

    #[test]
    fn banner_pieces_go_to_the_next_line_instead_of_past_the_edge() {
        let spans = vec![
            Span::raw(" bowl monitor /dev/ttyUSB0 "),
            Span::raw(" no telemetry for 12 s - the values below are old "),
            Span::raw("  3 tool(s) connected"),
        ];
        assert_eq!(pack(spans.clone(), 80).len(), 2);
        let lines = pack(spans.clone(), 60);
        assert_eq!(lines.len(), 3);
        assert!(lines.iter().all(|l| l.width() <= 60));
        let text = |lines: &[ratatui::text::Line]| -> String {
            lines
                .iter()
                .flat_map(|l| l.spans.iter().map(|s| s.content.to_string()))
                .collect()
        };
        let all: String = spans.iter().map(|s| s.content.to_string()).collect();
        assert_eq!(text(&lines), all, "nothing lost");
        assert_eq!(pack(spans.clone(), 200).len(), 1);
        // Narrower than one piece: that piece is wrapped too.
        let narrow = pack(spans, 20);
        assert!(narrow.iter().all(|l| l.width() <= 20), "{narrow:?}");
    }
}
