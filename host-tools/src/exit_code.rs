//! The exit status of every `bowl` command, one set for all (documented in docs/console.md).
//! Clap's own usage errors exit with 2, so a rig's refusal never shares its code with a typo.

/// Done: the command ran and the rig (or the check) agreed.
pub const OK: i32 = 0;
/// The rig refused the command, or a check or report failed (e.g. a run that faulted).
pub const REFUSED: i32 = 1;
/// Usage: a flag or value on the command line is wrong (clap's code; also our own usage checks).
pub const USAGE: i32 = 2;
/// The link: the port is missing, not a serial port, busy, not permitted, or went away.
pub const LINK: i32 = 3;
/// No answer came in time.
pub const TIMEOUT: i32 = 4;
/// Ended by Ctrl-C or SIGTERM after putting the rig in a safe state (`commission` stops the
/// motors); 128 + SIGINT, as a shell reports a command Ctrl-C ended.
pub const INTERRUPTED: i32 = 130;

/// Whether the error is only that our standard output was closed (`bowl ... | head`): the
/// reader has what it wanted, so that is not a failure to report.
pub fn is_closed_output(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// A flag or value on the command line is wrong: its words say which value, the limit and
/// what to do. `main` ends with [`USAGE`] when an error carries one, so a script can tell a
/// typo from a rig's refusal or a failed run (both 1). One type for the binary and the lab's
/// library (`predict`, `experiment`), which raises it too.
pub use lab::usage::Usage;

/// A usage error with these words (a check's message, or a library's error about a flag's value).
pub fn usage(words: impl std::fmt::Display) -> anyhow::Error {
    // `{:#}` keeps an error's whole chain of causes in the one line printed.
    anyhow::Error::new(Usage(format!("{words:#}")))
}
