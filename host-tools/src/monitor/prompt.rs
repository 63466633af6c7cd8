//! The monitor's bottom row, fitted to the terminal's width: what is typed stays visible up to
//! its cursor however long the line or narrow the screen (its start gives way, marked `…`), and
//! a hint is shown whole or in a shorter form, never cut mid-word at the right edge.

use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};

use super::line_edit::LineEdit;

const PROMPT: &str = "command> ";

/// The hints while no command is typed, longest first: the first that fits is shown.
const IDLE_HINTS: [&str; 4] = [
    ": command (e.g. status, speed 1800 2100, start, stop) · p pause · q quit",
    ": command · p pause · q quit",
    ": command · q quit",
    ":",
];

/// The hints while a command is typed, longest first (each with its leading gap).
const TYPING_HINTS: [&str; 3] = [
    "   Enter send · Esc cancel · Up/Down earlier · Tab complete",
    "   Enter send · Esc cancel",
    "",
];

/// The bottom row for a terminal `width` columns wide: the command line being typed
/// (`input`), or the keys' hint.
pub fn line(input: Option<&LineEdit>, width: usize) -> Line<'static> {
    let hint = Style::default().fg(Color::DarkGray);
    let Some(edit) = input else {
        let text = IDLE_HINTS
            .iter()
            .find(|h| h.chars().count() <= width)
            .unwrap_or(&":");
        return Line::from(Span::styled(*text, hint));
    };
    // The prompt and the cursor take their columns first; the text shows its end.
    let room = width.saturating_sub(PROMPT.len() + 1);
    let len = edit.text.chars().count();
    let typed = if len <= room {
        edit.text.clone()
    } else {
        let tail: String = edit.text.chars().skip(len + 1 - room.max(1)).collect();
        format!("…{tail}")
    };
    let used = PROMPT.len() + typed.chars().count() + 1;
    let left = width.saturating_sub(used);
    let after = if edit.candidates.is_empty() {
        TYPING_HINTS
            .iter()
            .find(|h| h.chars().count() <= left)
            .map_or(String::new(), |h| h.to_string())
    } else {
        candidates(&edit.candidates, left)
    };
    Line::from(vec![
        Span::styled(PROMPT, Style::default().fg(Color::Yellow)),
        Span::raw(typed),
        Span::styled("_", Style::default().add_modifier(Modifier::SLOW_BLINK)),
        Span::styled(after, hint),
    ])
}

/// Tab's candidates in at most `room` columns: as many whole as fit, then how many more there
/// are (a parameter list is longer than any screen is wide).
fn candidates(all: &[String], room: usize) -> String {
    let mut text = String::from("   Tab:");
    for (i, c) in all.iter().enumerate() {
        let more = all.len() - i;
        let tail = if more > 1 {
            format!(" … (+{} more)", more - 1)
        } else {
            String::new()
        };
        let len = text.chars().count() + 1 + c.chars().count();
        if len + tail.chars().count() > room && more > 1 || len > room {
            let rest = format!(" … (+{more} more)");
            if text.chars().count() + rest.chars().count() <= room {
                text.push_str(&rest);
            }
            return text;
        }
        text.push(' ');
        text.push_str(c);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::{LineEdit, line};

    fn text(l: &ratatui::text::Line) -> String {
        l.spans.iter().map(|s| s.content.as_ref()).collect()
    }

    #[test]
    fn the_bottom_row_fits_and_shows_what_is_typed_up_to_the_cursor() {
        let mut edit = LineEdit::default();
        edit.open();
        for c in "speed 1800 2100 then a long tail of words".chars() {
            edit.push(c);
        }
        for width in 16..130 {
            let l = text(&line(Some(&edit), width));
            assert!(l.chars().count() <= width, "{width}: {l}");
            assert!(
                l.contains("words_"),
                "the cursor's end of the line: {width}: {l}"
            );
            let idle = text(&line(None, width));
            assert!(idle.chars().count() <= width, "{width}: {idle}");
            assert!(idle.starts_with(':'), "{width}: {idle}");
        }
        assert_eq!(text(&line(Some(&edit), 24)), "command> …tail of words_");
        assert_eq!(text(&line(None, 40)), ": command · p pause · q quit");
    }

    #[test]
    fn tab_candidates_that_do_not_fit_are_counted() {
        let mut edit = LineEdit::default();
        edit.open();
        edit.candidates = ["SPEED_MAX1_MRAD_S", "SPEED_MAX2_MRAD_S", "SLEW1", "SLEW2"]
            .map(String::from)
            .to_vec();
        let l = text(&line(Some(&edit), 60));
        assert_eq!(l, "command> _   Tab: SPEED_MAX1_MRAD_S … (+3 more)");
        let l = text(&line(Some(&edit), 200));
        assert!(l.ends_with("SLEW1 SLEW2"), "{l}");
    }
}
