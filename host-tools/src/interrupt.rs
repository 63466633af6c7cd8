//! Ctrl-C (SIGINT), SIGTERM and SIGHUP as a flag that the long-running commands poll, so each
//! ends its own way (the monitor closes its log and gives the terminal back, `commission` stops
//! the motors, `serve` removes its `--link`) instead of dying where it stands: a `kill`, a
//! closed terminal or a CI job's timeout is as common as Ctrl-C.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// A flag set when the process is asked to end. Installed once per process (each command that
/// polls it calls this once); should the handler be taken already, the signals keep their
/// default action and the flag never rises.
pub fn flag() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    let raised = flag.clone();
    let _ = ctrlc::set_handler(move || raised.store(true, std::sync::atomic::Ordering::SeqCst));
    flag
}
