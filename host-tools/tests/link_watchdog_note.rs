//! `bowl send PORT start` on its own: the rig faults `link-lost` LINK_TIMEOUT_MS after the last
//! message (docs/protocol.md, "Host silence"), so `send` says so at once, under the "ok", with
//! the rig's own timeout; not when the watchdog is off, nor for a command that starts nothing
//! (the monitor's case, where it keeps the link, is in `console_e2e`).

mod common;

use common::{Sim, send};

#[test]
fn start_without_a_monitor_warns_of_the_watchdog_and_the_rig_does_fault() {
    let sim = Sim::start(&[]);
    let (code, text) = send(&sim.path, "speed 1000 1000");
    assert_eq!(code, 0, "{text}");
    assert!(!text.contains("note:"), "a speed starts nothing: {text}");
    let (code, text) = send(&sim.path, "set LINK_TIMEOUT_MS 1500");
    assert_eq!(code, 0, "{text}");
    let (code, text) = send(&sim.path, "start");
    assert_eq!(code, 0, "{text}");
    let mut lines = text.lines();
    assert!(lines.next().unwrap_or("").starts_with("ok"), "{text}");
    let note = lines.next().unwrap_or("");
    assert!(
        note.contains("link-lost fault after 1.5 s (LINK_TIMEOUT_MS = 1500)")
            && note.contains(&format!("keep `bowl monitor {}` open", sim.path))
            && note.contains("set LINK_TIMEOUT_MS 0"),
        "{text}"
    );
    // What the note says happens: nothing pings, the rig stops with a link-lost fault.
    std::thread::sleep(std::time::Duration::from_millis(2500));
    let (_, status) = send(&sim.path, "status");
    assert!(status.contains("fault=link-lost"), "{status}");
}

#[test]
fn no_note_when_the_watchdog_is_off() {
    let sim = Sim::start(&[]);
    for words in ["set LINK_TIMEOUT_MS 0", "speed 1000 1000"] {
        let (code, text) = send(&sim.path, words);
        assert_eq!(code, 0, "{words}: {text}");
    }
    let (code, text) = send(&sim.path, "start");
    assert_eq!(code, 0, "{text}");
    assert!(!text.contains("note:"), "{text}");
}
