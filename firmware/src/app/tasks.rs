//! The async loops of the rig, generic over the board's peripherals and over the [`TaskCore`]
//! (controller + protocol). A board wraps each in an `#[embassy_executor::task]` (tasks cannot
//! be generic) and spawns them.
//!
//! Task set and rates:
//! - pulse capture: the board's capture interrupt (STM32: TIM2) or the emulated plant pushes
//!   edge timestamps into one [`EdgeQueue`] per axis;
//! - control: a fixed-rate tick ([`CONTROL_HZ`]): drain edges, run the controller, set duties;
//! - link: commands in, answers and telemetry out over the byte stream;
//! - supervisor: feeds the watchdog only while the control tick keeps running and meeting its
//!   deadlines.

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use embassy_futures::select::{Either, select};
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::RawMutex;
use embassy_time::{Duration, Instant, Ticker};
use embedded_io_async::{Read, Write};
use heapless::Vec;

use super::edges::{EDGES_PER_TICK, EdgeQueue};
use super::hal::{CaptureClock, MotorOutput, PowerStage, Watchdog};
use super::motors::{AXES, Motors};

/// The control tick rate (the controller's nominal `tick_hz`).
pub const CONTROL_HZ: u64 = 1_000;
/// Longest frame the link sends or receives.
pub const FRAME_BYTES: usize = 256;
/// How often the link task asks whether a telemetry frame is due (the protocol paces frames).
pub const TELEMETRY_POLL: Duration = Duration::from_millis(2);
/// Supervisor period: the watchdog is fed at most this often, and only if the control tick ran.
pub const SUPERVISOR_PERIOD: Duration = Duration::from_millis(20);

/// What the tasks need from the controller and the protocol. The binding to
/// `model_core::control` and `model_core::wire` implements it.
pub trait TaskCore {
    /// One control tick: the edges since the previous tick (oldest first), the capture clock
    /// read after draining them, and the motor currents the board sampled (None where it has
    /// none; used only where the parameters say the board measures them). Returns the duties
    /// (-1..=1, 0 = off).
    fn control_tick(
        &mut self,
        now_ticks: u32,
        edges: [&[u32]; AXES],
        currents_a: [Option<f32>; AXES],
    ) -> [f32; AXES];
    /// Whether a fault is latched (the motors are then kept off whatever the duties say).
    fn faulted(&self) -> bool;
    /// The board's hardware stop tripped: latch its fault (kept if another came first).
    fn hardware_stop(&mut self);
    /// Whether the latched fault is one the bridge may not stop, so the supply must be cut.
    fn cuts_supply(&self) -> bool;
    /// The boot announcement frame.
    fn hello(&mut self, out: &mut [u8; FRAME_BYTES]) -> Option<usize>;
    /// Bytes from the host; every answer frame goes to `send`.
    fn receive(&mut self, bytes: &[u8], send: &mut dyn FnMut(&[u8]));
    /// A telemetry frame, if one is due at `now_ms`.
    fn poll_telemetry(&mut self, now_ms: u32, out: &mut [u8; FRAME_BYTES]) -> Option<usize>;
    /// The next gate event as a frame, if one is waiting (sent as soon as the link polls).
    fn poll_gate_event(&mut self, out: &mut [u8; FRAME_BYTES]) -> Option<usize> {
        let _ = out;
        None
    }
    /// Tells the core how many edges the capture queues have dropped so far (per axis).
    fn set_dropped_edges(&mut self, dropped: [u32; AXES]) {
        let _ = dropped;
    }
}

/// The core shared by the control and link tasks (both lock it briefly; no await inside).
/// On the boards `M` is `ThreadModeRawMutex`: every task runs in thread mode on one executor,
/// so the lock never masks interrupts (pulse capture keeps its latency while telemetry
/// computes the residence-time prediction).
pub type SharedCore<M, C> = Mutex<M, RefCell<C>>;

/// Counts control ticks and remembers a missed deadline: the supervisor feeds the watchdog
/// only while the count advances and no tick has missed its deadline since the last feed.
pub struct Heartbeat {
    ticks: AtomicU32,
    missed: AtomicBool,
}

impl Default for Heartbeat {
    fn default() -> Self {
        Self::new()
    }
}

impl Heartbeat {
    /// A heartbeat at zero.
    pub const fn new() -> Self {
        Self {
            ticks: AtomicU32::new(0),
            missed: AtomicBool::new(false),
        }
    }
    fn beat(&self) {
        self.ticks.fetch_add(1, Ordering::Relaxed);
    }
    /// A control tick missed its deadline.
    pub fn miss(&self) {
        self.missed.store(true, Ordering::Relaxed);
    }
    /// Whether a tick missed its deadline since the last call (and forgets it).
    pub fn take_missed(&self) -> bool {
        self.missed.swap(false, Ordering::Relaxed)
    }
    /// Ticks so far, modulo 2^32.
    pub fn count(&self) -> u32 {
        self.ticks.load(Ordering::Relaxed)
    }
}

/// The fixed-rate control loop, forever. A tick whose work ends more than `deadline` after
/// the tick was due has missed its deadline (see [`Heartbeat`]).
///
/// The power stage: a tripped hardware stop latches its fault in the same tick, and the motor
/// supply stays cut from then until the fault is cleared (CLEAR holds only once the stop's
/// line is released: it re-latches at every tick while active), or while the latched fault is
/// one the bridge may not stop ([`TaskCore::cuts_supply`]).
pub async fn control<RM: RawMutex, C: TaskCore, M: MotorOutput, K: CaptureClock, P: PowerStage>(
    core: &SharedCore<RM, C>,
    queues: &[EdgeQueue; AXES],
    clock: &K,
    motors: &mut Motors<M>,
    power: &mut P,
    heartbeat: &Heartbeat,
    deadline: Duration,
) -> ! {
    let mut stop_tripped = false;
    power.set_supply(true);
    let mut buffers: [Vec<u32, EDGES_PER_TICK>; AXES] = [Vec::new(), Vec::new()];
    let period = Duration::from_hz(CONTROL_HZ);
    let mut ticker = Ticker::every(period);
    let mut due = Instant::now() + period;
    loop {
        ticker.next().await;
        for (q, b) in queues.iter().zip(&mut buffers) {
            q.drain_into(b);
        }
        // Read after draining: every edge handed over is older than `now`.
        let now = clock.now_ticks();
        let dropped = [queues[0].dropped(), queues[1].dropped()];
        let tripped = power.stop_tripped();
        let currents = power.currents_a();
        let (duties, faulted, cut) = core.lock(|c| {
            let mut c = c.borrow_mut();
            c.set_dropped_edges(dropped);
            let d = c.control_tick(now, [&buffers[0], &buffers[1]], currents);
            if tripped {
                c.hardware_stop();
            }
            (d, c.faulted(), c.cuts_supply())
        });
        // The motors first, then the supply: a fault stops the outputs before anything else.
        if faulted {
            motors.fault_stop();
        } else {
            motors.apply(duties);
        }
        stop_tripped = (stop_tripped || tripped) && faulted;
        power.set_supply(!(stop_tripped || cut));
        // A tick that starts late (the ticker catching up) counts from when it was due.
        let done = Instant::now();
        if done > due + deadline {
            heartbeat.miss();
        }
        due += period;
        heartbeat.beat();
    }
}

/// Device time in ms since boot (wraps after 49.7 days, as the protocol's field does).
pub fn now_ms() -> u32 {
    Instant::now().as_millis() as u32
}

/// Commands in, answers and telemetry out, forever. A write error (a broken link) drops that
/// frame: telemetry's sequence numbers show the host what it missed.
pub async fn link<RM: RawMutex, C: TaskCore, R: Read, W: Write>(
    core: &SharedCore<RM, C>,
    mut rx: R,
    mut tx: W,
) -> ! {
    let mut frame = [0u8; FRAME_BYTES];
    if let Some(n) = core.lock(|c| c.borrow_mut().hello(&mut frame)) {
        let _ = tx.write_all(&frame[..n]).await;
    }
    let mut ticker = Ticker::every(TELEMETRY_POLL);
    let mut rx_buf = [0u8; 64];
    loop {
        match select(rx.read(&mut rx_buf), ticker.next()).await {
            Either::First(Ok(n)) => {
                // One byte at a time: a byte completes at most one command, so at most one
                // answer frame is pending at any moment and none can be lost to buffer space.
                for &byte in &rx_buf[..n] {
                    let mut len = 0;
                    core.lock(|c| {
                        c.borrow_mut().receive(&[byte], &mut |f: &[u8]| {
                            if let Some(dst) = frame.get_mut(..f.len()) {
                                dst.copy_from_slice(f);
                                len = f.len();
                            }
                        })
                    });
                    if len > 0 {
                        let _ = tx.write_all(&frame[..len]).await;
                    }
                }
            }
            Either::First(Err(_)) => {} // framing/noise error: the decoder resyncs on the next frame
            Either::Second(()) => {
                while let Some(n) = core.lock(|c| c.borrow_mut().poll_gate_event(&mut frame)) {
                    let _ = tx.write_all(&frame[..n]).await;
                }
                let due = core.lock(|c| c.borrow_mut().poll_telemetry(now_ms(), &mut frame));
                if let Some(n) = due {
                    let _ = tx.write_all(&frame[..n]).await;
                }
            }
        }
    }
}

/// Feeds the watchdog while the control tick runs and meets its deadlines; stops feeding (so
/// the watchdog resets the MCU, and the bridge pull-downs hold the motors off) when it has not
/// ticked for a period or a tick missed its deadline since the last feed.
pub async fn supervisor<W: Watchdog>(mut watchdog: W, heartbeat: &Heartbeat) -> ! {
    let mut ticker = Ticker::every(SUPERVISOR_PERIOD);
    let mut last = heartbeat.count();
    loop {
        ticker.next().await;
        let now = heartbeat.count();
        let missed = heartbeat.take_missed();
        if now != last && !missed {
            watchdog.feed();
        }
        last = now;
    }
}
