//! An integer value as the rig reads it (no `+`, no leading zeros), judged against its range in
//! words: the one check behind the local refusals of `speed`, `rtime` and `set`.

/// Whether `arg` is an integer as the rig reads them, inside `lo..=hi`: `None` if so, else
/// what is wrong with it.
pub fn integer_in(arg: &str, what: &str, lo: i64, hi: i64, unit: &str) -> Option<String> {
    match arg.parse::<i64>() {
        Err(_) => Some(format!(
            "{what}: `{arg}` is not an integer (a whole number of {unit}, {lo}..={hi})"
        )),
        Ok(v) if v < lo || v > hi => Some(format!(
            "{what} {v} {unit} is outside its range {lo}..={hi} {unit}"
        )),
        Ok(v) if v.to_string() != arg => Some(format!(
            "{what}: write `{arg}` as `{v}` (the rig reads integers without `+` or leading zeros)"
        )),
        Ok(_) => None,
    }
}
