//! The rig from a plain serial console, as a person at the bench uses one: picocom and tio on
//! the virtual rig's pty (the same protocol device as the Black Pill's), commands typed as the
//! words `bowl send` takes, without `$`, id or CRC, and the answers read off the screen.
//! tests/lib/ensure-tools.sh installs both consoles.

mod common;

use common::Sim;
use common::tmux::Tmux;

/// Types into `console` (a command line that opens the pty given last) what a person would:
/// telemetry off, a speed, the status, a typo; each answer must appear on the screen, id 0.
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
