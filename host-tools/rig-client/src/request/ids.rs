//! Request ids: each command of ours gets one the rig has not seen within its resend horizon,
//! and never one left to others (the monitor's own two, the console's 0).

/// A request id for the first command of a process: the wall clock in milliseconds, mod 2^16
/// (one turn in 65.5 s). The rig takes a command with the id and words of one of its recent
/// commands, up to 60 s old, for a copy and does not carry it out again (docs/protocol.md), so
/// ids must not come back within 60 s: from the clock, each process starts past the ids of
/// the ones before it and counts up from there (a process sends far fewer than one command a
/// millisecond). `u16::MAX` and `u16::MAX - 1` are left to the monitor (its heartbeat and its
/// own STATUS), and 0 to a line typed at the rig's console: the rig answers a typed line, or a
/// fragment of a damaged frame that lost its `$`, with request id 0, which then never passes
/// for the answer to a command of ours.
pub fn fresh_id() -> u16 {
    let ms = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_millis())
        .unwrap_or(0);
    own_id((ms % 65_536) as u16)
}

/// The request id after `id`, skipping the monitor's own two and the console's (see
/// [`fresh_id`]).
pub fn next_id(id: u16) -> u16 {
    own_id(id.wrapping_add(1))
}

/// `id`, or 1 where it is one the tools leave to others (see [`fresh_id`]).
fn own_id(id: u16) -> u16 {
    match id {
        0 | 0xFFFE..=u16::MAX => 1,
        id => id,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ids the tools count through leave out the console's 0 (the rig's answer to a typed
    /// line, or to a fragment of a damaged frame, is id 0: before, a command of ours with id 0
    /// could take it for its own refusal) and the monitor's two.
    #[test]
    fn ids_never_reach_the_consoles_or_the_monitors() {
        assert_eq!(next_id(0xFFFC), 0xFFFD);
        for id in [0xFFFD, 0xFFFE, u16::MAX, 0] {
            assert_eq!(next_id(id), 1, "after {id}");
        }
        assert_eq!(next_id(1), 2);
        let id = fresh_id();
        assert!((1..0xFFFE).contains(&id), "{id}");
    }
}
