//! The release trigger and exit light gate of a real board: their raw timestamps (capture
//! clock, microseconds, the proximity sensors' time base) arrive in two [`EdgeQueue`]s filled
//! by the board's interrupts and its release solenoid; this turns them into debounced
//! [`GateEvent`]s, oldest first.
//!
//! Debouncing is a lockout: an edge closer than the input's lockout to the last edge it
//! accepted is bounce (a push button's contacts chatter for a few ms; a granule that tumbles
//! through the light beam can break it twice). The first edge of a burst is the event, so
//! the time is the moment the contact closed or the beam first broke.

use heapless::{Deque, Vec};
use model_core::wire::{GateEvent, GateKind};

use super::edges::{EDGES_PER_TICK, EdgeQueue};

/// The release trigger's lockout: a push button's contact bounce, with margin (releases are
/// seconds apart).
pub const RELEASE_LOCKOUT_US: u32 = 50_000;
/// The exit gate's lockout: one granule passing the beam (granules leave seconds apart).
pub const EXIT_LOCKOUT_US: u32 = 5_000;

/// Events waiting to be sent; more than a few never wait between two polls of the link.
const PENDING: usize = 8;

/// One input's lockout.
#[derive(Debug, Clone, Copy)]
struct Lockout {
    lockout_us: u32,
    last_us: Option<u32>,
}

impl Lockout {
    const fn new(lockout_us: u32) -> Self {
        Self {
            lockout_us,
            last_us: None,
        }
    }

    /// Whether the edge at `t_us` is an event (and not bounce of the last one).
    fn accept(&mut self, t_us: u32) -> bool {
        if let Some(last) = self.last_us {
            // Wrapping difference: the clock wraps every 71 minutes. An edge stamped before
            // the last accepted one (the solenoid's stamp racing a button's) is bounce too.
            let since = t_us.wrapping_sub(last) as i32;
            if since < self.lockout_us as i32 {
                return false;
            }
        }
        self.last_us = Some(t_us);
        true
    }
}

/// Debounced gate events from the raw edge queues `[release, exit]`.
pub struct GateReader<'a> {
    raw: &'a [EdgeQueue; 2],
    lockouts: [Lockout; 2],
    pending: Deque<GateEvent, PENDING>,
    boot: u16,
    scratch: Vec<u32, EDGES_PER_TICK>,
    dropped: u32,
}

impl<'a> GateReader<'a> {
    /// A reader of `raw` (`[release, exit]`); events carry `boot`, this boot's reset counter.
    pub fn new(raw: &'a [EdgeQueue; 2], boot: u16) -> Self {
        Self {
            raw,
            lockouts: [
                Lockout::new(RELEASE_LOCKOUT_US),
                Lockout::new(EXIT_LOCKOUT_US),
            ],
            pending: Deque::new(),
            boot,
            scratch: Vec::new(),
            dropped: 0,
        }
    }

    /// The oldest event not yet taken.
    pub fn next_event(&mut self) -> Option<GateEvent> {
        self.collect();
        self.pending.pop_front()
    }

    /// Edges lost so far: raw queues full, over-capture, or more events than wait here.
    pub fn lost(&self) -> u32 {
        self.raw
            .iter()
            .map(EdgeQueue::dropped)
            .fold(self.dropped, u32::saturating_add)
    }

    fn collect(&mut self) {
        for (i, kind) in [GateKind::Release, GateKind::Exit].into_iter().enumerate() {
            self.raw[i].drain_into(&mut self.scratch);
            for &t in &self.scratch {
                if self.lockouts[i].accept(t) {
                    let event = GateEvent {
                        kind,
                        time_us: t,
                        boot: self.boot,
                    };
                    if insert_in_time_order(&mut self.pending, event).is_err() {
                        self.dropped = self.dropped.saturating_add(1);
                    }
                }
            }
        }
    }
}

/// Puts `event` after every pending event not later than it (times compared across the
/// clock's wrap); a full queue refuses it.
fn insert_in_time_order(
    pending: &mut Deque<GateEvent, PENDING>,
    event: GateEvent,
) -> Result<(), ()> {
    if pending.is_full() {
        return Err(());
    }
    let mut later: Vec<GateEvent, PENDING> = Vec::new();
    while let Some(&back) = pending.back() {
        if (event.time_us.wrapping_sub(back.time_us) as i32) >= 0 {
            break;
        }
        if let Some(e) = pending.pop_back() {
            // Cannot fail: `later` holds at most what `pending` held.
            let _ = later.push(e);
        }
    }
    let _ = pending.push_back(event);
    while let Some(e) = later.pop() {
        let _ = pending.push_back(e);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn events(reader: &mut GateReader) -> std::vec::Vec<(GateKind, u32)> {
        core::iter::from_fn(|| reader.next_event())
            .map(|e| (e.kind, e.time_us))
            .collect()
    }

    #[test]
    fn a_bouncing_button_is_one_release_at_its_first_edge() {
        let raw = [EdgeQueue::new(), EdgeQueue::new()];
        let mut reader = GateReader::new(&raw, 3);
        // Contact chatter over 12 ms, then a second press 0.8 s later.
        for t in [1_000, 1_400, 2_900, 7_000, 13_000, 801_000, 801_300] {
            raw[0].push(t);
        }
        assert_eq!(
            events(&mut reader),
            [(GateKind::Release, 1_000), (GateKind::Release, 801_000)]
        );
        let e = {
            raw[1].push(900_000);
            reader.next_event()
        };
        assert_eq!(
            e,
            Some(GateEvent {
                kind: GateKind::Exit,
                time_us: 900_000,
                boot: 3
            })
        );
    }

    #[test]
    fn events_leave_in_time_order_across_the_clock_wrap() {
        let raw = [EdgeQueue::new(), EdgeQueue::new()];
        let mut reader = GateReader::new(&raw, 0);
        // Collected in one poll: an exit just after the wrap, and releases before and after.
        raw[0].push(u32::MAX - 99_999);
        raw[0].push(200_000);
        raw[1].push(50_000);
        assert_eq!(
            events(&mut reader),
            [
                (GateKind::Release, u32::MAX - 99_999),
                (GateKind::Exit, 50_000),
                (GateKind::Release, 200_000)
            ]
        );
    }

    #[test]
    fn the_exit_gate_takes_a_second_granule_after_its_lockout() {
        let raw = [EdgeQueue::new(), EdgeQueue::new()];
        let mut reader = GateReader::new(&raw, 0);
        raw[1].push(10_000);
        raw[1].push(10_000 + EXIT_LOCKOUT_US - 1);
        raw[1].push(10_000 + EXIT_LOCKOUT_US);
        assert_eq!(
            events(&mut reader),
            [
                (GateKind::Exit, 10_000),
                (GateKind::Exit, 10_000 + EXIT_LOCKOUT_US)
            ]
        );
        assert_eq!(reader.lost(), 0);
    }

    #[test]
    fn events_beyond_the_waiting_room_are_counted_as_lost() {
        let raw = [EdgeQueue::new(), EdgeQueue::new()];
        let mut reader = GateReader::new(&raw, 0);
        for k in 0..(PENDING as u32 + 3) {
            raw[1].push(k * EXIT_LOCKOUT_US);
        }
        // The first poll collects all; PENDING wait, 3 are lost and said to be.
        assert!(reader.next_event().is_some());
        assert_eq!(reader.lost(), 3);
        assert_eq!(events(&mut reader).len(), PENDING - 1);
    }
}
