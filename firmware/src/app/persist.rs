//! The persistence loop: saves changed parameters and motor models to the parameter log while
//! the motors are off, and reports capture losses (the wire has no field for them, so the
//! board logs them: never silently). Generic over the flash region; the board supplies only
//! how an event is logged.

use embassy_sync::blocking_mutex::raw::RawMutex;
use embassy_time::{Duration, Instant};

use super::binding::{DeviceCore, Injector, Persisted};
use super::hal::FlashRegion;
use super::motors::AXES;
use super::params::{ParamLog, SaveError};
use super::tasks::SharedCore;

/// How often the loop looks for something to save or report.
pub const PERSIST_PERIOD: Duration = Duration::from_millis(500);
/// Shortest time between two saves: a host sending SET in a loop cannot wear the flash out
/// (a sector takes 10 000 erases; a save erases at most one sector per several hundred).
pub const MIN_SAVE_INTERVAL: Duration = Duration::from_secs(2);

/// What the persistence loop needs from the core.
pub trait PersistSource {
    /// The record to save now, if parameters or motor models changed since the last call and
    /// the motors are off (a flash erase stalls the CPU).
    fn take_record_to_save(&mut self) -> Option<Persisted>;
    /// Edges lost in capture so far, per axis.
    fn dropped_edges(&self) -> [u32; AXES];
}

impl<I: Injector> PersistSource for DeviceCore<I> {
    fn take_record_to_save(&mut self) -> Option<Persisted> {
        self.backend
            .take_params_to_save()
            .then(|| self.params_to_persist())
    }

    fn dropped_edges(&self) -> [u32; AXES] {
        DeviceCore::dropped_edges(self)
    }
}

/// What one step of the loop did, for the board's log.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PersistReport {
    /// The capture queues have lost more edges since the last report: the totals so far, per
    /// axis.
    pub edges_lost: Option<[u32; AXES]>,
    /// A record was due: saved (or already the newest one in flash), or why not (the previous
    /// record then stays in force).
    pub saved: Option<Result<Persisted, SaveError>>,
}

/// The persistence state between steps: the flash log and the losses already reported. The
/// board calls [`Persistence::step`] every [`PERSIST_PERIOD`] and logs the report.
pub struct Persistence<'a, F: FlashRegion> {
    log: &'a mut ParamLog<F>,
    reported_lost: [u32; AXES],
    /// No save before this time (rate limit).
    next_save: Instant,
}

impl<'a, F: FlashRegion> Persistence<'a, F> {
    /// Persistence into `log`, with no losses reported yet.
    pub fn new(log: &'a mut ParamLog<F>) -> Self {
        Self {
            log,
            reported_lost: [0; AXES],
            next_save: Instant::now(),
        }
    }

    /// One step: takes what is due from the core (a brief lock), then writes flash outside
    /// the lock.
    pub fn step<RM: RawMutex, C: PersistSource>(
        &mut self,
        core: &SharedCore<RM, C>,
    ) -> PersistReport {
        // A change that comes within MIN_SAVE_INTERVAL of the last save stays pending (the
        // core keeps it dirty) until the interval is over.
        let may_save = Instant::now() >= self.next_save;
        let (record, lost) = core.lock(|c| {
            let mut c = c.borrow_mut();
            let record = if may_save {
                c.take_record_to_save()
            } else {
                None
            };
            (record, c.dropped_edges())
        });
        if record.is_some() {
            self.next_save = Instant::now() + MIN_SAVE_INTERVAL;
        }
        let edges_lost = (lost != self.reported_lost).then_some(lost);
        self.reported_lost = lost;
        PersistReport {
            edges_lost,
            saved: record.map(|r| self.log.save(&r).map(|()| r)),
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use core::cell::RefCell;

    use embassy_sync::blocking_mutex::Mutex;
    use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
    use model_core::control::ControllerConfig;
    use model_core::wire::{Command, Frame, Hello, ParamId, ResetCause, decode_frame, encode};

    use super::*;
    use crate::app::binding::{
        ControllerBackend, NoInjection, PERSISTED_COUNT, default_persisted, split_persisted,
    };
    use crate::app::params::{LoadError, SLOT_BYTES};
    use crate::app::tasks::{FRAME_BYTES, TaskCore};
    use crate::app::test_flash::RamFlash;

    type Core = SharedCore<CriticalSectionRawMutex, DeviceCore<NoInjection>>;

    fn core() -> Core {
        let hello = Hello {
            reset_cause: ResetCause::PowerOn,
            reset_count: 0,
        };
        let (backend, ok) = ControllerBackend::new(
            ControllerConfig::nominal(),
            default_persisted(),
            hello,
            NoInjection,
        );
        assert_eq!(ok, Ok(()));
        Mutex::new(RefCell::new(DeviceCore::new(backend)))
    }

    /// Sends one command and returns the answer.
    fn send(core: &Core, id: u16, command: Command) -> Frame {
        let mut buf = [0u8; FRAME_BYTES];
        let n = encode(&Frame::Command { id, command }, &mut buf).expect("encodes");
        let mut answer = None;
        core.lock(|c| {
            c.borrow_mut().receive(&buf[..n], &mut |f: &[u8]| {
                answer = Some(decode_frame(f).expect("the answer decodes"))
            })
        });
        answer.expect("every command is answered")
    }

    const NOTHING: PersistReport = PersistReport {
        edges_lost: None,
        saved: None,
    };

    #[test]
    fn a_changed_parameter_is_saved_once_and_loads_back() {
        let core = core();
        let mut log = ParamLog::new(RamFlash::<{ 4 * SLOT_BYTES }>::new());
        let mut p = Persistence::new(&mut log);
        assert_eq!(p.step(&core), NOTHING, "nothing changed yet");
        let set = Command::SetParam {
            id: ParamId::Teeth2,
            value: 60,
        };
        assert_eq!(send(&core, 1, set), Frame::Ack { id: 1 });
        let report = p.step(&core);
        let Some(Ok(record)) = report.saved else {
            panic!("one save expected, got {report:?}");
        };
        assert_eq!(report.edges_lost, None);
        assert_eq!(record[ParamId::Teeth2.index()], 60);
        assert_eq!(p.step(&core), NOTHING, "saved once");
        let loaded = log.load::<PERSISTED_COUNT>().expect("the record loads");
        assert_eq!(loaded, record);
        let params = split_persisted(&loaded).params;
        assert_eq!(params[ParamId::Teeth2.index()], 60);
        assert_eq!(params[ParamId::Teeth1.index()], 12);
    }

    #[test]
    fn nothing_is_saved_while_the_motors_run() {
        let core = core();
        let mut log = ParamLog::new(RamFlash::<{ 4 * SLOT_BYTES }>::new());
        let mut p = Persistence::new(&mut log);
        let speeds = Command::SetSpeeds {
            precession_mrad_s: 2000,
            spin_mrad_s: 2000,
        };
        assert_eq!(send(&core, 1, speeds), Frame::Ack { id: 1 });
        assert_eq!(send(&core, 2, Command::Start), Frame::Ack { id: 2 });
        // Loop tuning may change while running; the save waits for the motors to stop.
        let tuning = Command::SetParam {
            id: ParamId::Bandwidth1MradS,
            value: 4000,
        };
        assert_eq!(send(&core, 3, tuning), Frame::Ack { id: 3 });
        assert_eq!(p.step(&core), NOTHING);
        assert_eq!(log.load::<PERSISTED_COUNT>(), Err(LoadError::Empty));
    }

    #[test]
    fn lost_edges_are_reported_when_they_grow_and_only_then() {
        let core = core();
        let mut log = ParamLog::new(RamFlash::<{ 4 * SLOT_BYTES }>::new());
        let mut p = Persistence::new(&mut log);
        core.lock(|c| c.borrow_mut().set_dropped_edges([3, 0]));
        let lost = |edges_lost| PersistReport {
            edges_lost,
            saved: None,
        };
        assert_eq!(p.step(&core), lost(Some([3, 0])));
        assert_eq!(p.step(&core), NOTHING);
        core.lock(|c| c.borrow_mut().set_dropped_edges([3, 1]));
        assert_eq!(p.step(&core), lost(Some([3, 1])));
    }

    #[test]
    fn a_failed_save_is_reported() {
        let core = core();
        // A region too small for one slot: every write is out of bounds.
        let mut log = ParamLog::new(RamFlash::<8>::new());
        let mut p = Persistence::new(&mut log);
        let set = Command::SetParam {
            id: ParamId::Teeth1,
            value: 24,
        };
        assert_eq!(send(&core, 1, set), Frame::Ack { id: 1 });
        let report = p.step(&core);
        assert!(matches!(report.saved, Some(Err(_))), "{report:?}");
    }
}
