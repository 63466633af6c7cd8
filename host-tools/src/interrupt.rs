//! Ctrl-C (SIGINT) and SIGTERM as a flag that the long-running commands poll, so each ends its
//! own way (the monitor closes its log and gives the terminal back, `commission` stops the
//! motors, `serve` removes its `--link`) instead of dying where it stands: a `kill` or a CI
//! job's timeout is as common as Ctrl-C.
//!
//! SIGHUP (the terminal closed) keeps its default action, ending the process at once: with the
//! terminal gone the UI's key reader sees an endless end of input and would never come back to
//! look at a flag, leaving a monitor that holds the port and spins.

use std::sync::atomic::{AtomicBool, Ordering};

/// Raised by the handlers; one per process, as the signals are.
static RAISED: AtomicBool = AtomicBool::new(false);

/// The flag set when the process is asked to end. Installs the handlers (once per process:
/// should Ctrl-C's be taken already, it keeps its default action).
pub fn flag() -> &'static AtomicBool {
    let _ = ctrlc::set_handler(|| RAISED.store(true, Ordering::SeqCst));
    #[cfg(unix)]
    {
        use nix::sys::signal::{SigHandler, Signal, signal};
        extern "C" fn on_sigterm(_: nix::libc::c_int) {
            // An atomic store is async-signal-safe.
            RAISED.store(true, Ordering::SeqCst);
        }
        // SAFETY: the handler only stores to an atomic; nothing else in the process handles
        // SIGTERM.
        let _ = unsafe { signal(Signal::SIGTERM, SigHandler::Handler(on_sigterm)) };
    }
    &RAISED
}
