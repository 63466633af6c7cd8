//! Reading commands from text: the command a token names, one field's value from its token,
//! and the range checks the decoder and the encoder share (the table is [`super`]'s).

use crate::wire::commands::{Command, CommandKind, Field, FieldKind};
use crate::wire::params::ParamId;
use crate::wire::types::Reason;

impl CommandKind {
    /// The command with this wire token (exact, upper case).
    pub fn from_token(token: &[u8]) -> Option<CommandKind> {
        CommandKind::ALL
            .into_iter()
            .find(|k| k.token().as_bytes() == token)
    }

    /// The command a person named (any case).
    pub fn from_word(word: &str) -> Option<CommandKind> {
        CommandKind::ALL
            .into_iter()
            .find(|k| k.token().eq_ignore_ascii_case(word))
    }
}

/// Canonical decimal: optional `-`, 1 to 18 digits, no leading zero, no `-0`; `None` otherwise.
pub fn parse_int(tok: &[u8]) -> Option<i64> {
    let (neg, digits) = match tok.split_first() {
        Some((b'-', d)) => (true, d),
        _ => (false, tok),
    };
    if digits.is_empty() || digits.len() > 18 || (digits.len() > 1 && digits[0] == b'0') {
        return None;
    }
    let mut v: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        // 18 digits < 9.2e18: no overflow.
        v = v * 10 + i64::from(d - b'0');
    }
    match (neg, v) {
        (true, 0) => None,
        (true, v) => Some(-v),
        (false, v) => Some(v),
    }
}

/// What is wrong with one field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldProblem {
    /// Not an integer at all.
    NotAnInteger,
    /// An integer, but not written as the rig reads them (`+`, leading zeros, `-0`): this one.
    NotCanonical(i64),
    /// An integer outside the field's range: this one.
    OutOfRange(i64),
    /// Not one of the field's tokens.
    UnknownChoice,
    /// Not a parameter's name.
    UnknownParam,
}

impl FieldProblem {
    /// The reason the rig gives for it.
    pub const fn reason(self) -> Reason {
        match self {
            FieldProblem::OutOfRange(_) => Reason::Range,
            FieldProblem::UnknownParam => Reason::UnknownParam,
            _ => Reason::Malformed,
        }
    }
}

impl Field {
    /// The range of the field's integers (`param`: the parameter named before a
    /// [`FieldKind::ParamValue`]).
    pub fn range(&self, param: Option<ParamId>) -> (i64, i64) {
        match self.kind {
            FieldKind::Int { min, max, .. } => (min, max),
            FieldKind::ParamValue => param.map_or((0, -1), |p| {
                let (lo, hi) = p.range();
                (lo.into(), hi.into())
            }),
            FieldKind::Choice(tokens) => (0, tokens.len() as i64 - 1),
            FieldKind::ParamName => (0, ParamId::ALL.len() as i64 - 1),
        }
    }

    /// The value of one field's token; `param` is the parameter named so far (set by a
    /// [`FieldKind::ParamName`], read by a [`FieldKind::ParamValue`]). `any_case`: tokens as a
    /// person types them; otherwise as the wire has them (upper case).
    pub fn parse(
        &self,
        tok: &[u8],
        param: &mut Option<ParamId>,
        any_case: bool,
    ) -> Result<i64, FieldProblem> {
        let same = |a: &str| {
            if any_case {
                a.as_bytes().eq_ignore_ascii_case(tok)
            } else {
                a.as_bytes() == tok
            }
        };
        match self.kind {
            FieldKind::Choice(tokens) => tokens
                .iter()
                .position(|t| same(t))
                .map(|i| i as i64)
                .ok_or(FieldProblem::UnknownChoice),
            FieldKind::ParamName => {
                let id = ParamId::ALL
                    .into_iter()
                    .find(|p| same(p.token()))
                    .ok_or(FieldProblem::UnknownParam)?;
                *param = Some(id);
                Ok(id.index() as i64)
            }
            FieldKind::Int { .. } | FieldKind::ParamValue => {
                let v = match parse_int(tok) {
                    Some(v) => v,
                    None if !any_case => return Err(FieldProblem::NotAnInteger),
                    None => {
                        // A person's number the rig would not read: say how to write it.
                        let lenient = core::str::from_utf8(tok).ok().and_then(|s| s.parse().ok());
                        return Err(lenient.map_or(FieldProblem::NotAnInteger, |v| {
                            FieldProblem::NotCanonical(v)
                        }));
                    }
                };
                let (lo, hi) = self.range(*param);
                if (lo..=hi).contains(&v) {
                    Ok(v)
                } else {
                    Err(FieldProblem::OutOfRange(v))
                }
            }
        }
    }

    /// Whether `value` is one this field takes (what [`Field::parse`] can return).
    pub fn accepts(&self, value: i64, param: &mut Option<ParamId>) -> bool {
        if self.kind == FieldKind::ParamName {
            *param = usize::try_from(value)
                .ok()
                .and_then(|i| ParamId::ALL.get(i))
                .copied();
        }
        let (lo, hi) = self.range(*param);
        (lo..=hi).contains(&value)
    }
}

impl Command {
    /// Whether every field is inside its range (the encoder refuses a command that is not:
    /// the decoder would).
    pub fn in_range(&self) -> bool {
        let mut param = None;
        self.kind()
            .fields()
            .iter()
            .zip(self.values())
            .all(|(f, v)| f.accepts(v, &mut param))
    }
}
