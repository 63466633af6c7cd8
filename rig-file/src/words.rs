//! TOML reading errors in plain words, for the rig file and the experiment plan alike.

/// A TOML reading error in plain words: its line (1-based) and its message with the key on
/// that line named and serde's Rust type names said in words ("expected usize" read as a
/// defect to a person; it is "a whole number"). A misspelt key or table gets the nearest name
/// it may have meant, a table header is called a table, and a value typed with its unit
/// (`mu = 0.02 kg`, which TOML's own message told to quote, then refused as a string) is said
/// to be one. The plan's reader uses it too.
pub fn toml_error_words(text: &str, e: &toml::de::Error) -> (Option<usize>, String) {
    let mut words = e.message().trim().to_string();
    for (rust, plain) in [
        ("usize", "a whole number"),
        ("u64", "a whole number"),
        ("u32", "a whole number"),
        ("u16", "a whole number"),
        ("u8", "a whole number"),
        ("i64", "a whole number"),
        ("i32", "a whole number"),
        ("f64", "a number"),
        ("f32", "a number"),
        ("a boolean", "true or false"),
    ] {
        words = words.replace(&format!("expected {rust}"), &format!("expected {plain}"));
    }
    if let Some(near) = nearest_field(&words) {
        words = format!("{words} (did you mean `{near}`?)");
    }
    let Some(span) = e.span() else {
        return (None, words);
    };
    let start = span.start.min(text.len());
    let line_no = 1 + text[..start].matches('\n').count();
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let line = text[line_start..].lines().next().unwrap_or("");
    if line.trim_start().starts_with('[') {
        // `[bowll]`: serde calls a table a field.
        words = words.replacen("unknown field `", "unknown table `", 1);
    } else if let Some((key, value)) = line.split_once('=') {
        let key = key.trim();
        // Only where TOML or serde refused the text for not being a number: a string key's
        // value may well start with digits.
        let not_a_number = [
            "string values must be quoted",
            "invalid type: string",
            "invalid float",
            "invalid integer",
        ]
        .iter()
        .any(|m| words.contains(m));
        if let Some(unit) = with_unit(value).filter(|_| not_a_number) {
            words = format!(
                "`{}` is a number with a unit: write the number alone ({key} = {unit}), in the \
                 unit the key's name says (SI: m, kg, s, rad/s, V, ohm, ...)",
                value_text(value)
            );
        }
        let v = value_text(value);
        if words.contains("expected newline")
            && let Some((whole, part)) = v.split_once(',')
            && [whole, part]
                .iter()
                .all(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
        {
            words = format!(
                "`{v}` has a decimal comma: TOML takes a decimal point ({key} = {whole}.{part})"
            );
        }
        if !key.is_empty() && !key.starts_with('[') {
            words = format!("{key}: {words}");
        }
    }
    (Some(line_no), words)
}

/// For serde's "unknown field `x`, expected one of `a`, `b`": the expected name nearest `x`,
/// if one is near enough to be a slip of the keyboard (two edits, or a transposition).
fn nearest_field(words: &str) -> Option<&str> {
    let rest = words.strip_prefix("unknown field `")?;
    let (typed, rest) = rest.split_once('`')?;
    let expected = rest.split_once("expected")?.1;
    expected
        .split('`')
        .skip(1)
        .step_by(2)
        .map(|name| (strsim::damerau_levenshtein(typed, name), name))
        .filter(|&(d, name)| d <= 2.min(name.len() / 3).max(1))
        .min_by_key(|&(d, _)| d)
        .map(|(_, name)| name)
}

/// A value's text: after the `=`, without a trailing comment, spaces or quotes.
fn value_text(value: &str) -> &str {
    let v = match value.find('#') {
        Some(i) if value[..i].matches('"').count().is_multiple_of(2) => &value[..i],
        _ => value,
    };
    v.trim().trim_matches('"').trim()
}

/// The number of a value typed with its unit (`0.02 kg`, `"60 deg"`, `12V`), if it is one.
fn with_unit(value: &str) -> Option<&str> {
    let v = value_text(value);
    let end =
        v.find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E' | '_')))?;
    let (number, unit) = v.split_at(end);
    let unit = unit.trim();
    let is_unit = unit
        .chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || matches!(c, '%' | '/' | '\u{b0}'));
    (number.parse::<f64>().is_ok() && is_unit).then_some(number)
}
