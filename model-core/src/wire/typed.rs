//! The commands as a person types them (`speed 1800 2100`, `set TELEM_HZ 20`):
//! [`Command::from_words`] judges the words by the command table ([`super::commands`]) as the
//! rig's decoder judges a line, and [`Refusal`] says what is wrong in words (what, which value,
//! the limit or the valid names, what to write instead). No heap: the words go to any
//! `core::fmt::Write` (`Display`).

use core::fmt;

use super::commands::{Command, CommandKind, FieldKind, FieldProblem, MAX_FIELDS};
use super::params::ParamId;
use super::types::Reason;

/// The unit of a parameter that is a switch (0 off, 1 on).
const SWITCH_UNIT: &str = "0/1";

impl Command {
    /// The command in the words a person types (`speed 1800 2100`, `set TELEM_HZ 20`; each
    /// word may also hold several, split at commas: `speed,1800,2100`), judged by the table:
    /// the command word, the number of values, each value against its field's range (a
    /// negative number is a value like any other, refused when its range starts at 0). What is
    /// wrong is said by the [`Refusal`], in words (`Display`).
    pub fn from_words<S: AsRef<str>>(words: &[S]) -> Result<Command, Refusal<'_>> {
        let mut words = split_words(words);
        let word = words.next().ok_or(Refusal::NoCommand)?;
        let kind = CommandKind::from_word(word).ok_or(Refusal::UnknownCommand { word })?;
        // Field by field, as the rig's decoder reads them, so both refuse a line for the same
        // reason: a wrong value before a missing or extra one.
        let fields = kind.fields();
        let given = words.clone().count();
        let mut values = [0i64; MAX_FIELDS];
        let mut param = None;
        for (index, (slot, field)) in values.iter_mut().zip(fields).enumerate() {
            let word = words.next().ok_or(Refusal::FieldCount { kind, given })?;
            *slot = field
                .parse(word.as_bytes(), &mut param, true)
                .map_err(|problem| Refusal::Field {
                    kind,
                    index,
                    word,
                    param,
                    problem,
                })?;
        }
        if words.next().is_some() {
            return Err(Refusal::FieldCount { kind, given });
        }
        // Every value passed its field, so it fits its type.
        Command::from_values(kind, &values).ok_or(Refusal::FieldCount { kind, given })
    }
}

/// The words of a command line, parted as the rig's console parts a typed line (at spaces and
/// Tabs), and also at commas, as a frame's fields are, and at any other ASCII white space
/// (`speed,1800,2100`; `"speed  1800 2100"` given as one argument; a script saved with CRLF
/// line ends passes `status\r`, and the CR, invisible, made `status` an unknown command). The
/// rig refuses a typed comma (`UNREADABLE`): only what is left of a damaged frame has one. Every reader of a command's words takes them from here, so the words the
/// refusal quotes by position are the words the command was judged by.
pub fn split_words<S: AsRef<str>>(words: &[S]) -> impl Iterator<Item = &str> + Clone {
    words
        .iter()
        .flat_map(|w| {
            w.as_ref()
                .split(|c: char| c == ',' || c.is_ascii_whitespace())
        })
        .filter(|w| !w.is_empty())
}

/// Why a command line typed by a person is refused before it is sent: `Display` says it in
/// words (what, which value, the limit or the valid names, what to write instead).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal<'a> {
    /// No word at all.
    NoCommand,
    /// The first word is not a command.
    UnknownCommand {
        /// The word.
        word: &'a str,
    },
    /// Too many or too few values after the command word.
    FieldCount {
        /// The command.
        kind: CommandKind,
        /// How many values were given.
        given: usize,
    },
    /// One value is wrong.
    Field {
        /// The command.
        kind: CommandKind,
        /// Which of its fields.
        index: usize,
        /// The value as typed.
        word: &'a str,
        /// The parameter named before it (for `SET`'s value).
        param: Option<ParamId>,
        /// What is wrong.
        problem: FieldProblem,
    },
}

impl Refusal<'_> {
    /// The reason the rig would give for the same line.
    pub const fn reason(&self) -> Reason {
        match self {
            Refusal::UnknownCommand { .. } => Reason::UnknownCommand,
            Refusal::NoCommand | Refusal::FieldCount { .. } => Reason::Malformed,
            Refusal::Field { problem, .. } => problem.reason(),
        }
    }
}

/// Writes `s` in lower case.
fn lower(f: &mut fmt::Formatter<'_>, s: &str) -> fmt::Result {
    s.chars().try_for_each(|c| {
        use fmt::Write;
        f.write_char(c.to_ascii_lowercase())
    })
}

/// Writes `items` as `a, b, c or d` (`last`: the word before the last one).
fn list<T: Copy>(
    f: &mut fmt::Formatter<'_>,
    items: &[T],
    last: &str,
    mut item: impl FnMut(&mut fmt::Formatter<'_>, T) -> fmt::Result,
) -> fmt::Result {
    for (i, &t) in items.iter().enumerate() {
        match i {
            0 => {}
            i if i + 1 == items.len() => write!(f, " {last} ")?,
            _ => f.write_str(", ")?,
        }
        item(f, t)?;
    }
    Ok(())
}

/// Every command word, lower case: `speed, rtime, ...`.
fn command_words(f: &mut fmt::Formatter<'_>) -> fmt::Result {
    list(f, &CommandKind::ALL, "and", |f, k| lower(f, k.token()))
}

/// How a command is typed: `speed PRECESSION_MRAD_S SPIN_MRAD_S: ...`, each field with its
/// range, and the row's example.
fn usage(f: &mut fmt::Formatter<'_>, kind: CommandKind) -> fmt::Result {
    lower(f, kind.token())?;
    if kind.fields().is_empty() {
        return f.write_str(" takes nothing after its word");
    }
    for field in kind.fields() {
        f.write_str(" ")?;
        field.name.chars().try_for_each(|c| {
            use fmt::Write;
            f.write_char(c.to_ascii_uppercase())
        })?;
    }
    f.write_str(":")?;
    for (i, field) in kind.fields().iter().enumerate() {
        f.write_str(if i == 0 { " " } else { "; " })?;
        f.write_str(field.what)?;
        match field.kind {
            FieldKind::Int { min, max, limit } => {
                write!(f, ", {min}..={max} {}", field.unit)?;
                if let Some(p) = limit {
                    write!(f, " and at most the rig's {}", p.token())?;
                }
            }
            FieldKind::Choice(tokens) => {
                f.write_str(": ")?;
                list(f, tokens, "or", lower)?;
            }
            FieldKind::ParamName => f.write_str(" (docs/protocol.md)")?,
            FieldKind::ParamValue => {
                f.write_str(", an integer in the parameter's unit and range")?
            }
        }
    }
    write!(f, " (e.g. `{}`)", kind.example())
}

impl fmt::Display for Refusal<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Refusal::NoCommand => {
                f.write_str("no command given; the commands: ")?;
                command_words(f)
            }
            Refusal::UnknownCommand { word } => {
                write!(f, "`{word}` is not a command; the commands: ")?;
                command_words(f)
            }
            Refusal::FieldCount { kind, given } => {
                let n = kind.fields().len();
                f.write_str("`")?;
                lower(f, kind.token())?;
                write!(
                    f,
                    "` takes {n} value{} after it, got {given}: ",
                    if n == 1 { "" } else { "s" }
                )?;
                usage(f, kind)
            }
            Refusal::Field {
                kind,
                index,
                word,
                param,
                problem,
            } => {
                let Some(field) = kind.fields().get(index) else {
                    return usage(f, kind);
                };
                // SET's value is named by its parameter, in its unit.
                let (what, unit) = match (field.kind, param) {
                    (FieldKind::ParamValue, Some(p)) => (p.token(), p.unit()),
                    _ => (field.what, field.unit),
                };
                let (lo, hi) = field.range(param);
                match problem {
                    // A switch (unit `0/1`) is named as one, not given a unit.
                    FieldProblem::OutOfRange(v) if unit == SWITCH_UNIT => {
                        write!(f, "{what} is a switch: 0 (off) or 1 (on), not {v}")
                    }
                    FieldProblem::NotAnInteger if unit == SWITCH_UNIT => {
                        write!(f, "{what} is a switch: 0 (off) or 1 (on), not `{word}`")
                    }
                    FieldProblem::NotAnInteger => write!(
                        f,
                        "{what}: `{word}` is not an integer (a whole number of {unit}, {lo}..={hi})"
                    ),
                    FieldProblem::NotCanonical(v) => write!(
                        f,
                        "{what}: write `{word}` as `{v}` (the rig reads integers without `+` or \
                         leading zeros)"
                    ),
                    FieldProblem::OutOfRange(v) => {
                        match field.kind {
                            FieldKind::Int { limit: Some(p), .. } if v < lo => write!(
                                f,
                                "{what} {v} {unit} is below {lo}: it takes {lo}..={hi} {unit}, \
                                 and at most the rig's {}",
                                p.token()
                            )?,
                            _ => write!(
                                f,
                                "{what} {v} {unit} is outside its range {lo}..={hi} {unit}"
                            )?,
                        }
                        if v < 0 {
                            f.write_str(" (a negative number is a value here, not an option)")?;
                        }
                        Ok(())
                    }
                    FieldProblem::UnknownChoice => {
                        write!(f, "`{word}` is not {what}: ")?;
                        if let FieldKind::Choice(tokens) = field.kind {
                            list(f, tokens, "or", lower)?;
                        }
                        Ok(())
                    }
                    FieldProblem::UnknownParam => {
                        write!(f, "`{word}` is not a parameter; the parameters: ")?;
                        list(f, &ParamId::ALL, "and", |f, p| f.write_str(p.token()))?;
                        f.write_str(" (docs/protocol.md)")
                    }
                }
            }
        }
    }
}
