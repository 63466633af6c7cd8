//! Ctrl-C (SIGINT) and SIGTERM as a flag that the long-running commands poll, so each ends its
//! own way (the monitor closes its log and gives the terminal back, `commission` stops the
//! motors, `serve` removes its `--link`) instead of dying where it stands: a `kill` or a CI
//! job's timeout is as common as Ctrl-C.
//!
//! SIGHUP (the terminal closed) raises the flag too where the command asks for it
//! ([`flag_with_hangup`]: the monitor, whose log gets its `monitor end` row); elsewhere it keeps
//! its default action. A command that takes it must come back to the flag without waiting on
//! the terminal, which is gone: its key reader sees an endless end of input.

use std::sync::atomic::{AtomicBool, Ordering};

/// Raised by the handlers; one per process, as the signals are.
static RAISED: AtomicBool = AtomicBool::new(false);
/// Raised with [`RAISED`] when the cause was SIGHUP.
static HUNG_UP: AtomicBool = AtomicBool::new(false);

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

/// [`flag`], raised also when the terminal closes (SIGHUP); [`hung_up`] then says so.
pub fn flag_with_hangup() -> &'static AtomicBool {
    let raised = flag();
    #[cfg(unix)]
    {
        use nix::sys::signal::{SigHandler, Signal, signal};
        extern "C" fn on_sighup(_: nix::libc::c_int) {
            // Atomic stores are async-signal-safe.
            HUNG_UP.store(true, Ordering::SeqCst);
            RAISED.store(true, Ordering::SeqCst);
        }
        // SAFETY: the handler only stores to atomics; nothing else in the process handles
        // SIGHUP.
        let before = unsafe { signal(Signal::SIGHUP, SigHandler::Handler(on_sighup)) };
        // Started to outlive its terminal (`nohup bowl monitor ... &`: SIGHUP ignored, and
        // so inherited): it goes on logging.
        if let Ok(SigHandler::SigIgn) = before {
            // SAFETY: SIG_IGN installs no handler.
            let _ = unsafe { signal(Signal::SIGHUP, SigHandler::SigIgn) };
        }
    }
    raised
}

/// Whether the terminal closed (SIGHUP came): nothing more can be shown on it, and its errors
/// are no news.
pub fn hung_up() -> bool {
    HUNG_UP.load(Ordering::SeqCst)
}

/// A reader that goes away (`bowl monitor PORT --log day.csv | head`) ends this process through
/// its own way out, as Ctrl-C does, instead of SIGPIPE's default killing it where it stands
/// (`main` sets that for the commands that have nothing to close): a write to the closed pipe
/// fails with an error, which the command meets once it has closed its files.
pub fn closed_pipe_as_error() {
    #[cfg(unix)]
    {
        use nix::sys::signal::{SigHandler, Signal, signal};
        // SAFETY: SIG_IGN installs no handler of ours.
        let _ = unsafe { signal(Signal::SIGPIPE, SigHandler::SigIgn) };
    }
}
