//! The queue of edge timestamps from pulse capture to the control tick.
//!
//! The capture side (an interrupt or the capture task) pushes; the control tick drains all
//! edges seen since the previous tick, oldest first. A full queue drops the new edge and counts
//! it, so the loss reaches telemetry instead of vanishing: the controller cannot see an edge
//! it was never given.

use core::cell::RefCell;

use critical_section::Mutex;
use heapless::{Deque, Vec};

/// Edges one tick can receive per axis. At 1 kHz ticks this allows 32 kHz of pulses, far above
/// any rig speed (60 pulses/rev at 30 rad/s is 290 Hz).
pub const EDGES_PER_TICK: usize = 32;

struct Inner {
    queue: Deque<u32, EDGES_PER_TICK>,
    dropped: u32,
    total: u32,
}

/// An interrupt-safe FIFO of capture timestamps for one axis.
pub struct EdgeQueue {
    inner: Mutex<RefCell<Inner>>,
}

impl Default for EdgeQueue {
    fn default() -> Self {
        Self::new()
    }
}

impl EdgeQueue {
    /// An empty queue.
    pub const fn new() -> Self {
        Self {
            inner: Mutex::new(RefCell::new(Inner {
                queue: Deque::new(),
                dropped: 0,
                total: 0,
            })),
        }
    }

    /// Records one edge; if the queue is full the edge is dropped and counted.
    pub fn push(&self, ticks: u32) {
        critical_section::with(|cs| {
            let mut inner = self.inner.borrow_ref_mut(cs);
            inner.total = inner.total.wrapping_add(1);
            if inner.queue.push_back(ticks).is_err() {
                inner.dropped = inner.dropped.saturating_add(1);
            }
        });
    }

    /// Counts edges the hardware lost before they could be queued (over-capture).
    pub fn count_lost(&self, n: u32) {
        critical_section::with(|cs| {
            let mut inner = self.inner.borrow_ref_mut(cs);
            inner.total = inner.total.wrapping_add(n);
            inner.dropped = inner.dropped.saturating_add(n);
        });
    }

    /// Moves every queued edge into `out` (cleared first), oldest first.
    pub fn drain_into(&self, out: &mut Vec<u32, EDGES_PER_TICK>) {
        out.clear();
        critical_section::with(|cs| {
            let mut inner = self.inner.borrow_ref_mut(cs);
            while let Some(t) = inner.queue.pop_front() {
                // Cannot fail: `out` has the queue's capacity and was cleared.
                let _ = out.push(t);
            }
        });
    }

    /// Edges lost (queue full or over-capture), since reset.
    pub fn dropped(&self) -> u32 {
        critical_section::with(|cs| self.inner.borrow_ref(cs).dropped)
    }

    /// Edges seen since reset (including dropped ones), modulo 2^32.
    pub fn total(&self) -> u32 {
        critical_section::with(|cs| self.inner.borrow_ref(cs).total)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drains_in_order_and_counts_overflow() {
        let q = EdgeQueue::new();
        let n = EDGES_PER_TICK as u32 + 5;
        for t in 0..n {
            q.push(1000 + t);
        }
        let mut out = Vec::new();
        q.drain_into(&mut out);
        let want: std::vec::Vec<u32> = (0..EDGES_PER_TICK as u32).map(|t| 1000 + t).collect();
        assert_eq!(out.as_slice(), want.as_slice());
        assert_eq!(q.dropped(), 5);
        assert_eq!(q.total(), n);
        q.drain_into(&mut out);
        assert!(out.is_empty(), "a drained queue gives nothing twice");
    }
}
