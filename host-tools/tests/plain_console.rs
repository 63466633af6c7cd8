//! The rig from a plain serial console, as a person at the bench uses one: picocom and tio on
//! the virtual rig's pty (the same protocol device as the Black Pill's), commands typed as the
//! words `bowl send` takes, without `$`, id or CRC, and the answers read off the screen.
//! tests/lib/ensure-tools.sh installs both consoles.

mod common;

use common::Sim;
use common::tmux::Tmux;

/// Types into `console` (a command line that opens the pty given last) what a person would:
/// telemetry off, a speed, the status, a typo, Tab, an arrow key, a `µ`, Ctrl-C and Ctrl-U;
/// each answer must appear on the screen, id 0.
fn a_person_types_commands_into(name: &str, console: &str) {
    let sim = Sim::start(&[]);
    let tmux = Tmux::start(name, &format!("{console} {}", sim.path));
    tmux.wait_for(&["$T1,"], "telemetry scrolls on the console");
    tmux.keys(&["set TELEM_HZ 0", "Enter"]);
    tmux.wait_for(&["$A1,0*"], "the rig acknowledges a typed SET");
    tmux.keys(&["speed 1800 21000", "BSpace", "Enter"]);
    tmux.keys(&["status", "Enter"]);
    // State 0 (idle), fault 0, telemetry off (the 6th field after the id: 0 frames/s).
    let screen = tmux.wait_for(&["$S1,0,0,0,"], "the status answers a typed STATUS");
    assert_eq!(
        screen.matches("$A1,0*").count(),
        2,
        "SET and the corrected SPEED (Backspace) are both acknowledged:\n{screen}"
    );
    tmux.keys(&["statsu", "Enter"]);
    tmux.wait_for(&["$R1,0,UNKNOWN*"], "a typo is refused, not ignored");
    tmux.keys(&["speed 1800 99999", "Enter"]);
    tmux.wait_for(&["$R1,0,RANGE*"], "a value out of range is refused");
    // The other keys a person presses. Before, a Tab, an arrow key or a `µ` dropped the line
    // without an answer: silence, as from a dead rig.
    tmux.keys(&["speed", "Tab", "1800", "Tab", "2100", "Enter"]);
    tmux.wait_for_count("$A1,0*", 3, "Tab parts words as a space does");
    tmux.keys(&["status", "Up", "Enter"]);
    tmux.wait_for(
        &["$R1,0,UNREADABLE*"],
        "a line with an arrow key is answered",
    );
    tmux.keys(&["stopµ", "Enter"]);
    tmux.wait_for_count("$R1,0,UNREADABLE*", 2, "a letter beyond ASCII is answered");
    // Ctrl-C and Ctrl-U drop the line typed so far: neither `start` nor the speed is read.
    tmux.keys(&["start", "C-c", "speed 1800 99999", "C-u", "status", "Enter"]);
    let screen = tmux.wait_for_count("$S1,0,0,0,", 2, "the status after Ctrl-C and Ctrl-U");
    assert_eq!(
        screen.matches("$R1,0,RANGE*").count(),
        1,
        "the speed erased by Ctrl-U was not read:\n{screen}"
    );
    // The PC's tools still work on the same rig once the console has let go of it (the
    // console takes a moment to exit after its terminal closes).
    drop(tmux);
    let started = std::time::Instant::now();
    loop {
        let out = common::bowl(&["send", &sim.path, "params"]);
        let text = common::stdout(&out);
        if out.status.success() {
            assert!(text.contains("TELEM_HZ=0"), "{text}");
            break;
        }
        assert!(
            started.elapsed() < std::time::Duration::from_secs(10),
            "bowl send after the console closed: {text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
}

#[test]
fn picocom_talks_to_the_rig_in_plain_words() {
    a_person_types_commands_into("picocom", "picocom -b 115200");
}

#[test]
fn tio_talks_to_the_rig_in_plain_words() {
    a_person_types_commands_into("tio", "tio -b 115200");
}
