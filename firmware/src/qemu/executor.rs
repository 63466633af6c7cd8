//! A thread-mode executor that idles with WFI, for the emulated board.
//!
//! embassy's stock Cortex-M executor sleeps with WFE, which QEMU treats as a no-op: the board
//! would spin and virtual time would crawl. WFI lets QEMU (with `-icount sleep=off`) skip straight
//! to the next interrupt deadline, so an idle board costs no host time.

use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicBool, Ordering};

use embassy_executor::{Spawner, raw};

/// Set by the pender (any wake of a task) and cleared by the idle loop before it polls again.
static WORK_PENDING: AtomicBool = AtomicBool::new(false);

#[unsafe(export_name = "__pender")]
fn pender(_context: *mut ()) {
    WORK_PENDING.store(true, Ordering::Release);
}

/// Creates the board's single executor and runs it forever: `init` spawns the tasks, then
/// poll, sleep, poll. A second call is refused (returns to the caller's fault path) by `None`.
pub fn start(init: impl FnOnce(Spawner)) -> Option<core::convert::Infallible> {
    static STARTED: AtomicBool = AtomicBool::new(false);
    static mut EXECUTOR: MaybeUninit<raw::Executor> = MaybeUninit::uninit();
    if STARTED.swap(true, Ordering::AcqRel) {
        return None;
    }
    // SAFETY: the `STARTED` flag makes this the only access to `EXECUTOR`, ever.
    let executor: &'static raw::Executor = unsafe {
        (*core::ptr::addr_of_mut!(EXECUTOR)).write(raw::Executor::new(core::ptr::null_mut()))
    };
    run(executor, init)
}

fn run(executor: &'static raw::Executor, init: impl FnOnce(Spawner)) -> ! {
    init(executor.spawner());
    loop {
        // SAFETY: `poll` is only ever called from this loop, in thread mode.
        unsafe { executor.poll() };
        // Interrupts off between the check and WFI: a wake in between would otherwise be slept
        // through. A pending interrupt still ends WFI with PRIMASK set; it runs after `enable`.
        cortex_m::interrupt::disable();
        if !WORK_PENDING.swap(false, Ordering::AcqRel) {
            cortex_m::asm::wfi();
        }
        // SAFETY: re-enables what was disabled just above; no critical section spans this point.
        unsafe { cortex_m::interrupt::enable() };
    }
}
