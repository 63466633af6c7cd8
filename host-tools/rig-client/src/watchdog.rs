//! The rig's host-silence watchdog (docs/protocol.md, "Host silence") seen from a one-shot
//! command: `bowl send PORT start` answers "ok" and ends, nothing keeps pinging, and the rig
//! stops with a `link-lost` fault `LINK_TIMEOUT_MS` later. That is the rig's safety behaviour
//! and stays; the sender is told at once, in words, instead of finding the fault later.

use std::time::Duration;

use model_core::wire::{CommandKind, ParamId};

use crate::link::Link;
use crate::refusal::ask_params;

/// Whether the command, done, sets the motors turning: `start` (and `commission`, which drives
/// both motors for several seconds). A speed or residence target while running only moves the
/// setpoints; the note came with the `start`.
pub fn starts_motors(words: &[String]) -> bool {
    // Read by the command table, as `send` reads the word.
    matches!(
        words.first().and_then(|w| CommandKind::from_word(w)),
        Some(CommandKind::Start | CommandKind::Commission)
    )
}

/// The note for a command that `starts_motors`, done over `link`, on `port`: `None` when a
/// running monitor carried it (the monitor pings once a second, so the link stays) or when the
/// rig's watchdog is off (`LINK_TIMEOUT_MS` 0). The timeout is read from the rig (one PARAMS
/// question, which counts as host presence too); if that goes unanswered, the parameter is named.
pub fn note(link: &mut Link, port: &str, id: u16, timeout: Duration) -> Option<String> {
    if matches!(link, Link::Monitor(_)) {
        return None;
    }
    let name = ParamId::LinkTimeoutMs.token();
    let after = match ask_params(link, id, timeout) {
        Some(values) => match values[ParamId::LinkTimeoutMs.index()] {
            0 => return None,
            ms => format!("{:.1} s ({name} = {ms})", f64::from(ms) / 1000.0),
        },
        None => format!(
            "{name} (default {} ms)",
            ParamId::LinkTimeoutMs.default_value()
        ),
    };
    Some(format!(
        "note: the rig stops with a link-lost fault after {after} without a message from the \
         PC: keep `bowl monitor {port}` open (it keeps the link), or `bowl send {port} set \
         {name} 0` to turn the watchdog off"
    ))
}
