//! Reads the instruction counts of the QEMU run (`tests/run` keeps its output in
//! `target/test-logs/qemu-cases.log`): lines `bench NAME inputs=N min=A mean=B max=C [budget=..]`.

use std::collections::BTreeMap;

/// Instruction counts of one benchmark.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Counts {
    /// Grid points measured.
    pub inputs: u64,
    /// Fewest instructions of one call.
    pub min: u64,
    /// Mean over the grid.
    pub mean: u64,
    /// Most instructions of one call.
    pub max: u64,
}

/// Why a log line that starts with `bench ` could not be read.
#[derive(Debug, PartialEq, Eq)]
pub enum LogError {
    /// Line `line` (1-based) lacks the field `field` or its value is not a whole number.
    BadField {
        /// 1-based line number.
        line: usize,
        /// The missing or malformed field.
        field: &'static str,
    },
}

impl std::fmt::Display for LogError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LogError::BadField { line, field } => {
                write!(f, "QEMU log line {line}: missing or malformed `{field}=`")
            }
        }
    }
}

impl std::error::Error for LogError {}

/// Benchmark counts by name. Lines that are not `bench` lines are skipped (the log also holds
/// case results and the summary).
pub fn parse(text: &str) -> Result<BTreeMap<String, Counts>, LogError> {
    let mut out = BTreeMap::new();
    for (n, line) in text.lines().enumerate() {
        let Some(rest) = line.trim().strip_prefix("bench ") else {
            continue;
        };
        let mut words = rest.split_whitespace();
        let Some(name) = words.next() else { continue };
        let fields: Vec<(&str, &str)> = words.filter_map(|w| w.split_once('=')).collect();
        let get = |field: &'static str| {
            fields
                .iter()
                .find(|(k, _)| *k == field)
                .and_then(|(_, v)| v.parse::<u64>().ok())
                .ok_or(LogError::BadField { line: n + 1, field })
        };
        out.insert(
            name.to_string(),
            Counts {
                inputs: get("inputs")?,
                min: get("min")?,
                mean: get("mean")?,
                max: get("max")?,
            },
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_bench_lines_and_skips_the_rest() {
        let log = "case bowl::x ok\n\
                   bench cost::paper::flat::closed-f32-libm inputs=1 min=96 mean=96 max=96\n\
                   bench particle::residence_flat_f32 inputs=48 min=80 mean=101 max=130 budget=250 ok\n\
                   qemu-cases: 3 passed, 0 failed\n";
        let m = parse(log).unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(
            m["particle::residence_flat_f32"],
            Counts {
                inputs: 48,
                min: 80,
                mean: 101,
                max: 130
            }
        );
    }

    #[test]
    fn a_broken_bench_line_names_its_line() {
        let log = "x\nbench a inputs=1 min=2 mean=oops max=3\n";
        assert_eq!(
            parse(log),
            Err(LogError::BadField {
                line: 2,
                field: "mean"
            })
        );
    }
}
