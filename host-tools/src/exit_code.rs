//! The exit codes of every `bowl` command, one documented set (docs/console.md, "Exit codes"):
//! a script can tell a bad value from a refusal by the rig, a silent rig and a lost port.

/// Done, and every check passed.
pub const OK: i32 = 0;
/// The command could not do its job: a bad value or file, a failed check, anything that went
/// wrong on this PC before or apart from the rig's answer.
pub const ERROR: i32 = 1;
/// The command line itself was wrong (clap's own code: unknown flag, missing argument).
pub const USAGE: i32 = 2;
/// The rig answered and refused the command (its reason is printed).
pub const REFUSED: i32 = 3;
/// The rig did not answer in time.
pub const TIMEOUT: i32 = 4;
/// The rig reported a fault during the operation (the motors are off).
pub const FAULT: i32 = 5;
/// The serial port could not be opened or went away.
pub const LINK: i32 = 6;

/// A link problem (the port cannot be opened or went away), in plain words: anywhere in an
/// error's chain, [`for_error`] gives [`LINK`].
#[derive(Debug, Clone)]
pub struct LinkError(pub String);

impl core::fmt::Display for LinkError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for LinkError {}

/// The exit code for an error that ended a command.
pub fn for_error(e: &anyhow::Error) -> i32 {
    if e.chain().any(|c| c.downcast_ref::<LinkError>().is_some()) {
        LINK
    } else {
        ERROR
    }
}

/// Whether the error is only that our standard output was closed (`bowl ... | head`): the
/// reader has what it wanted, so that is not a failure to report.
pub fn is_closed_output(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
