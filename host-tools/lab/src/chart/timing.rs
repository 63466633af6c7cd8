//! Host time per call: the median over several batches of many calls, with `std::time::Instant`.
//!
//! Why batches and a median: a single call takes tens of nanoseconds, below the clock's useful
//! resolution, and the machine is shared, so one slow batch (another process, a page fault) must
//! not move the figure. The median of per-batch means is robust to that.

use std::hint::black_box;
use std::time::{Duration, Instant};

/// How long to measure.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    /// Number of batches; the median of their per-call times is reported.
    pub batches: usize,
    /// Target wall time of one batch.
    pub batch_time: Duration,
}

impl Budget {
    /// For the committed charts: 15 batches of 2 ms.
    pub const FULL: Budget = Budget {
        batches: 15,
        batch_time: Duration::from_millis(2),
    };
    /// For tests and quick looks: 3 batches of 0.2 ms.
    pub const QUICK: Budget = Budget {
        batches: 3,
        batch_time: Duration::from_micros(200),
    };
}

/// Per-call times over the batches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Median over batches of the mean ns per call (the figure charted).
    pub median_ns: f64,
    /// Fastest batch's mean ns per call (least disturbed by other load on the machine).
    pub min_ns: f64,
}

/// Nanoseconds per call of `f` (whose result is kept alive through `black_box`).
pub fn ns_per_call<R>(budget: Budget, mut f: impl FnMut() -> R) -> Timing {
    // Calibrate: double the repetitions until one batch takes the target time.
    let mut reps: u64 = 1;
    loop {
        let t0 = Instant::now();
        for _ in 0..reps {
            black_box(f());
        }
        let dt = t0.elapsed();
        if dt >= budget.batch_time || reps >= 1 << 24 {
            break;
        }
        reps *= 2;
    }
    let mut per_call: Vec<f64> = (0..budget.batches.max(1))
        .map(|_| {
            let t0 = Instant::now();
            for _ in 0..reps {
                black_box(f());
            }
            t0.elapsed().as_nanos() as f64 / reps as f64
        })
        .collect();
    per_call.sort_by(f64::total_cmp);
    Timing {
        median_ns: per_call[per_call.len() / 2],
        min_ns: per_call[0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn more_work_takes_longer() {
        // Not a timing assertion on absolute speed: only that 100x the work is measured as
        // clearly more (a factor 10 leaves room for noise on a shared machine).
        let small = ns_per_call(Budget::QUICK, || black_box(1.0f64).sqrt()).median_ns;
        let big = ns_per_call(Budget::QUICK, || {
            let mut s = 0.0f64;
            for i in 0..1000 {
                s += black_box(i as f64).sqrt();
            }
            s
        })
        .median_ns;
        assert!(
            small > 0.0 && big > 10.0 * small,
            "small {small} ns, big {big} ns"
        );
    }
}
