//! The case and benchmark types, and small comparison helpers.

/// One test case: a name and a function that returns what went wrong, if anything.
pub struct Case {
    /// `module::what`, printed by both runners.
    pub name: &'static str,
    /// Runs the case.
    pub run: fn() -> Result<(), Failure>,
}

/// What a failing case saw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Failure {
    /// What was being checked.
    pub what: &'static str,
    /// The value the code under test gave.
    pub got: f64,
    /// The reference value.
    pub want: f64,
    /// The tolerance that was exceeded (absolute, or relative where `what` says so).
    pub tolerance: f64,
}

/// A benchmark: `run(i)` evaluates the function under test on the `i`-th input of its grid,
/// `0 <= i < inputs`. The QEMU runner counts the instructions of each call and reports the
/// minimum, maximum and mean over the grid; on the host, `tests/host.rs` checks each call returns
/// a finite value (the benchmarks must not measure an error path by accident).
pub struct Bench {
    /// `module::function_f32`, printed with the counts.
    pub name: &'static str,
    /// Number of grid points.
    pub inputs: usize,
    /// Evaluates grid point `i`; returns a value so the call is not optimised away.
    pub run: fn(usize) -> f32,
    /// Instruction budget, if one is set (the runner flags a breach).
    pub budget_instructions: Option<u32>,
}

/// Checks `|got - want| <= tolerance * max(1, |want|)`.
pub fn close(what: &'static str, got: f64, want: f64, tolerance: f64) -> Result<(), Failure> {
    let scale = if want.abs() > 1.0 { want.abs() } else { 1.0 };
    let ok = (got - want).abs() <= tolerance * scale;
    if ok && got.is_finite() == want.is_finite() {
        Ok(())
    } else {
        Err(Failure {
            what,
            got,
            want,
            tolerance,
        })
    }
}

/// Checks a condition, reporting `got` and `want` as 1/0.
pub fn ensure(what: &'static str, condition: bool) -> Result<(), Failure> {
    if condition {
        Ok(())
    } else {
        Err(Failure {
            what,
            got: 0.0,
            want: 1.0,
            tolerance: 0.0,
        })
    }
}
