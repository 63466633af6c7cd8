//! An emulator process whose standard output is the board's console: the console is read on a
//! thread that keeps its last lines and hands over the one line that names the board's serial
//! device; the process is killed when stopped or dropped. Both emulators' pseudo-terminal boards
//! run on this.

use std::io::{BufRead, BufReader};
use std::process::{Child, ChildStdout};
use std::sync::mpsc::Sender;
use std::thread::JoinHandle;

/// How many console lines are kept for [`EmulatorProcess::stop`].
const KEPT_LINES: usize = 200;

/// A running emulator and the thread reading its console.
pub struct EmulatorProcess {
    /// The emulator.
    pub child: Child,
    console: Option<JoinHandle<Vec<String>>>,
}

impl EmulatorProcess {
    /// Reads `stdout` on a thread: every line that `announces` recognises (the one naming the
    /// board's serial device, the board's "up" line) is also sent to `tx`; the last
    /// [`KEPT_LINES`] lines are kept.
    pub fn watch(
        child: Child,
        stdout: ChildStdout,
        announces: fn(&str) -> bool,
        tx: Sender<String>,
    ) -> EmulatorProcess {
        let console = std::thread::spawn(move || {
            let mut keep = Vec::new();
            for line in BufReader::new(stdout).lines().map_while(|l| l.ok()) {
                if announces(&line) {
                    let _ = tx.send(line.clone());
                }
                if keep.len() == KEPT_LINES {
                    keep.remove(0);
                }
                keep.push(line);
            }
            keep
        });
        EmulatorProcess {
            child,
            console: Some(console),
        }
    }

    /// Stops the emulator; returns the last lines of its console.
    pub fn stop(mut self) -> Vec<String> {
        self.kill();
        self.console
            .take()
            .and_then(|t| t.join().ok())
            .unwrap_or_default()
    }

    fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for EmulatorProcess {
    fn drop(&mut self) {
        self.kill();
    }
}
