//! Whether the terminal shows Unicode, and the monitor's screen in plain ASCII when it does not.
//!
//! Under a locale without UTF-8 (`LANG=C`, `LC_ALL=POSIX`, a serial console, an old ssh setup)
//! the terminal shows the braille of the charts and the box-drawing of the frames as garbage.
//! As htop does, the screen is then drawn in ASCII: frames of `-`, `|` and `+`, the charts'
//! lines as `.` (set) and `*` (measured), and any other glyph as its nearest ASCII character.

use std::ffi::OsStr;

use ratatui::buffer::Buffer;

/// Whether the locale the environment gives (the first set and non-empty of `LC_ALL`,
/// `LC_CTYPE`, `LANG`, as the C library takes them) encodes characters in UTF-8. None set is
/// the C locale (ASCII) on Unix; on Windows these are rarely set, and the console is written
/// in UTF-16 whatever the code page, so none set there keeps Unicode.
pub fn utf8_locale() -> bool {
    let var = |name| std::env::var_os(name);
    utf8(
        var("LC_ALL").as_deref(),
        var("LC_CTYPE").as_deref(),
        var("LANG").as_deref(),
        cfg!(windows),
    )
}

fn utf8(
    lc_all: Option<&OsStr>,
    lc_ctype: Option<&OsStr>,
    lang: Option<&OsStr>,
    windows: bool,
) -> bool {
    match [lc_all, lc_ctype, lang]
        .into_iter()
        .flatten()
        .find(|v| !v.is_empty())
    {
        // `en_US.UTF-8`, `C.utf8`, `de_DE.UTF-8@euro`: the codeset after the dot.
        Some(v) => {
            let v = v.to_string_lossy().to_ascii_lowercase();
            v.contains("utf-8") || v.contains("utf8")
        }
        None => windows,
    }
}

/// Replaces every cell that is not ASCII with its nearest ASCII character.
pub fn to_ascii(buffer: &mut Buffer) {
    for cell in &mut buffer.content {
        if !cell.symbol().is_ascii() {
            let c = cell.symbol().chars().next().map_or(' ', ascii);
            cell.set_char(c);
        }
    }
}

/// The nearest ASCII character to `c` (one cell wide, so the layout stays as drawn).
fn ascii(c: char) -> char {
    match c {
        c if c.is_ascii() => c,
        // Box drawing: the frames, the charts' axes.
        '─' | '━' | '═' | '┄' | '┅' | '┈' | '┉' | '╌' | '╍' | '╴' | '╶' | '╸' | '╺' => {
            '-'
        }
        '│' | '┃' | '║' | '┆' | '┇' | '┊' | '┋' | '╎' | '╏' | '╵' | '╷' | '╹' | '╻' => {
            '|'
        }
        '\u{2500}'..='\u{257f}' => '+',
        // The charts' markers in ASCII mode (see `speed_chart`): the set line is drawn in dots,
        // the measured line in blocks, so the two still differ without colour.
        '•' => '.',
        '\u{2580}'..='\u{259f}' | '\u{2800}'..='\u{28ff}' => '*',
        '·' => '|',
        '–' | '—' | '−' => '-',
        '→' | '≥' | '»' => '>',
        '←' | '≤' | '«' => '<',
        '≈' => '~',
        '×' => 'x',
        'µ' | 'μ' => 'u',
        '°' => 'o',
        '‘' | '’' => '\'',
        '“' | '”' => '"',
        '…' => '.',
        _ => '?',
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::layout::Rect;

    fn os(s: &str) -> Option<&OsStr> {
        Some(OsStr::new(s))
    }

    #[test]
    fn the_effective_locale_decides() {
        assert!(utf8(None, None, os("en_US.UTF-8"), false));
        assert!(utf8(None, None, os("C.utf8"), false));
        assert!(!utf8(None, None, os("C"), false));
        assert!(
            !utf8(None, None, None, false),
            "nothing set is the C locale"
        );
        assert!(
            utf8(None, None, None, true),
            "nothing set on Windows keeps Unicode"
        );
        assert!(
            !utf8(None, None, os("C"), true),
            "a locale set on Windows is taken"
        );
        // LC_ALL overrides LC_CTYPE, which overrides LANG; an empty one counts as unset.
        assert!(!utf8(os("C"), None, os("en_US.UTF-8"), false));
        assert!(!utf8(None, os("POSIX"), os("en_US.UTF-8"), false));
        assert!(utf8(os(""), os("de_DE.UTF-8@euro"), os("C"), false));
        assert!(!utf8(None, None, os("en_US.ISO-8859-1"), false));
    }

    #[test]
    fn a_drawn_screen_becomes_ascii_of_the_same_width() {
        let mut buffer = Buffer::empty(Rect::new(0, 0, 12, 1));
        buffer.set_string(0, 0, "┌─│└⣿•█· µé", ratatui::style::Style::default());
        to_ascii(&mut buffer);
        let row: String = buffer.content.iter().map(|c| c.symbol()).collect();
        assert_eq!(row, "+-|+*.*| u? ");
    }
}
