//! The log's PC time for what the rig sent before the monitor was reading: the frames that
//! waited in the port's buffer arrive in one burst when the port opens (70 rows, 1.4 s of device
//! time, at the same instant), and stamping each with its arrival would give them all one PC
//! time. So rows read before the port first goes quiet are held; the first frame after that
//! quiet arrived live, and dates them back by the device clock (its time minus theirs). Rows it
//! cannot date (an earlier boot, the rig never went live) are written with the PC time empty
//! rather than a wrong one.

use std::io::Write;
use std::time::{Duration, SystemTime};

use anyhow::Result;
use model_core::wire::{GateEvent, Telemetry};
use rig_client::telemetry_csv;

/// More rows than a port's buffer holds: a stream that never goes quiet is live, not backlog.
const HELD_MAX: usize = 4096;

enum Held {
    Row(u64, Telemetry),
    Gate(u64, GateEvent),
}

/// The rows held while the port's backlog drains.
#[derive(Default)]
pub(super) struct Backlog {
    held: Vec<Held>,
    /// From the port's (re)opening until its first quiet read.
    draining: bool,
}

impl Backlog {
    /// The port was opened (or reopened): what it holds already is backlog.
    pub(super) fn opened(&mut self) {
        self.draining = true;
    }

    /// A read found nothing waiting: the buffer is drained, the next frame is live.
    pub(super) fn quiet(&mut self) {
        self.draining = false;
    }

    /// Whether a frame read now belongs to the backlog (then it is held, not written).
    pub(super) fn holding(&self) -> bool {
        self.draining && self.held.len() < HELD_MAX
    }

    /// Whether a gate event read now waits with the held rows (to stay in their order).
    pub(super) fn pending(&self) -> bool {
        self.holding() || !self.held.is_empty()
    }

    /// Holds a telemetry row of boot `boot`.
    pub(super) fn hold_row(&mut self, boot: u64, t: Telemetry) {
        self.held.push(Held::Row(boot, t));
    }

    /// Holds a gate event of boot `boot`.
    pub(super) fn hold_gate(&mut self, boot: u64, e: GateEvent) {
        self.held.push(Held::Gate(boot, e));
    }

    /// Writes the held rows, dated back from `live` (a frame of boot `boot` that arrived live
    /// at `arrived`), or with the PC time empty when `live` is `None` (the port was lost, the rig
    /// restarted, the monitor ends). Returns the telemetry rows written.
    pub(super) fn release(
        &mut self,
        w: &mut impl Write,
        live: Option<(u64, &Telemetry, SystemTime)>,
    ) -> Result<u64> {
        let mut rows = 0;
        // The latest held row's (boot, device ms): where a held gate sits on the device clock.
        let mut latest: Option<(u64, u32)> = None;
        for held in self.held.drain(..) {
            // The device milliseconds (or microseconds, the gates' time base) from this row to
            // the live frame; only within one boot, where the device clock is one clock.
            let back = |boot: u64, ago: Option<Duration>| {
                let (live_boot, _, arrived) = live?;
                (live_boot == boot).then_some(())?;
                arrived.checked_sub(ago?)
            };
            match held {
                Held::Row(boot, t) => {
                    latest = Some((boot, t.time_ms));
                    let ago = live.and_then(|(_, l, _)| {
                        let ms = l.time_ms.checked_sub(t.time_ms)?;
                        Some(Duration::from_millis(u64::from(ms)))
                    });
                    telemetry_csv::write_row(w, boot, &t, back(boot, ago))?;
                    rows += 1;
                }
                Held::Gate(boot, e) => {
                    let ago = live.map(|(_, l, _)| {
                        // The gates' microseconds wrap every 71.6 minutes: a wrapping difference.
                        let live_us = (u64::from(l.time_ms) * 1000) as u32;
                        Duration::from_micros(u64::from(live_us.wrapping_sub(e.time_us)))
                    });
                    let near = latest
                        .or(live.map(|(b, l, _)| (b, l.time_ms)))
                        .filter(|(b, _)| *b == boot)
                        .map(|(_, ms)| ms);
                    telemetry_csv::write_gate_event(w, boot, back(boot, ago), &e, near)?;
                }
            }
        }
        Ok(rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::wire::{DeviceState, FaultCode, MotorTelemetry, Residence};

    fn telemetry(time_ms: u32, seq: u16) -> Telemetry {
        Telemetry {
            time_ms,
            seq,
            state: DeviceState::Idle,
            fault: FaultCode::None,
            precession: MotorTelemetry::default(),
            spin: MotorTelemetry::default(),
            bowl_mrad_s: 0,
            residence_flat: Residence::Unavailable,
            residence_coriolis: Residence::Unavailable,
        }
    }

    /// Backlog rows get the live frame's PC time less their device time's distance from it;
    /// an earlier boot's rows stay undated.
    #[test]
    fn backlog_rows_are_dated_back_by_the_device_clock() {
        let mut b = Backlog::default();
        b.opened();
        assert!(b.holding());
        b.hold_row(0, telemetry(1000, 1));
        b.hold_row(1, telemetry(1020, 2));
        b.hold_row(1, telemetry(2340, 3));
        b.quiet();
        assert!(!b.holding());
        let arrived = SystemTime::UNIX_EPOCH + Duration::from_secs(100);
        let live = telemetry(2360, 4);
        let mut out = Vec::new();
        assert_eq!(b.release(&mut out, Some((1, &live, arrived))).unwrap(), 3);
        let text = String::from_utf8(out).unwrap();
        let hosts: Vec<&str> = text
            .lines()
            .map(|l| l.split(',').nth(16).unwrap_or(""))
            .collect();
        assert_eq!(
            hosts,
            ["", "1970-01-01T00:01:38.660Z", "1970-01-01T00:01:39.980Z"],
            "{text}"
        );
    }
}
