//! The words of a command as `bowl send` and `bowl serve --command` take them: as the rig's
//! console reads a typed line, split at spaces, tabs, CR and commas. A script saved with CRLF
//! line ends passes `status\r`: it was refused as "`status` is not a command" (the CR
//! invisible in the words); a command given as one quoted argument (`"speed  1800 2100"`, a
//! variable) was an unknown command; `speed,5000,0` was sent and refused RANGE without the
//! limit (its particulars read the words by position).

mod common;

use common::{Sim, bowl, stdout};

/// `bowl send PORT ARGS...` (each argument as given, no splitting here).
fn send(port: &str, args: &[&str]) -> (i32, String) {
    let mut all = vec!["send", port, "--timeout-ms", "3000"];
    all.extend_from_slice(args);
    let out = bowl(&all);
    (out.status.code().unwrap_or(-1), stdout(&out))
}

#[test]
fn words_with_a_cr_a_tab_or_in_one_argument_are_the_command() {
    let sim = Sim::start(&[]);
    let p = sim.path.as_str();
    let (code, out) = send(p, &["status\r"]);
    assert_eq!(code, 0, "{out}");
    assert!(out.starts_with("status (id "), "{out}");
    let (code, out) = send(p, &["set", "MU_PPM", "29000\r"]);
    assert_eq!(code, 0, "{out}");
    let (code, out) = send(p, &["speed  1800\t2100 "]);
    assert_eq!(code, 0, "{out}");
    assert!(out.starts_with("ok (id "), "{out}");
    // A refusal of such words names the limit, as for words given one by one.
    for args in [
        &["speed,5000,0"][..],
        &["speed 5000 0\r"],
        &["speed", "5000", "0"],
    ] {
        let (code, out) = send(p, args);
        assert_eq!(code, 1, "{args:?}: {out}");
        assert!(
            out.contains(
                "the precession speed 5.000 rad/s is above SPEED_MAX1_MRAD_S = 4.000 rad/s"
            ),
            "{args:?}: {out}"
        );
    }
    // Refused before sending: the word quoted is the word typed, without the CR.
    let (code, out) = send(p, &["statsu\r"]);
    assert_eq!(code, 2, "{out}");
    assert!(out.contains("`statsu` is not a command"), "{out:?}");
}

/// `bowl serve --command AT_MS:WORDS` takes `bowl send`'s spaces as well as the commas (it
/// refused `0:speed 1800 2100`).
#[test]
fn serve_commands_take_spaces() {
    let dir = common::temp_dir("send-words-serve");
    let cap = dir.join("c.bin");
    let out = bowl(&[
        "serve",
        "--capture",
        cap.to_str().unwrap(),
        "--seconds",
        "1",
        "--command",
        "0:speed 1800 2100",
        "--command",
        "10:start",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&cap).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.contains("$A1,1*"), "SPEED acknowledged");
    assert!(!text.contains("$R1,1,"), "SPEED not refused");
}
