//! The command line judged in words: values refused before anything is sent name the value, the
//! limit and the valid names and exit 2 (usage); a negative number is a value, not a flag; a
//! file that is not what the command reads says so, with its name; a timeout on a noisy line
//! says what to try.

mod common;

use std::io::Write;
use std::time::Duration;

use common::{bowl, stdout, temp_dir};

/// `bowl send` to a port that is never opened: every one of these is refused before.
fn refused_locally(words: &[&str]) -> String {
    let mut args = vec!["send", "/dev/null-never-opened"];
    args.extend_from_slice(words);
    let out = bowl(&args);
    let text = format!("{}{}", stdout(&out), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(2), "{words:?}: {text}");
    text
}

#[test]
fn values_refused_locally_are_said_in_words_and_exit_2() {
    // A negative speed is a value (not taken for a flag), judged by the protocol's rule.
    let text = refused_locally(&["speed", "-1", "2100"]);
    assert!(
        text.contains("the precession speed -1 mrad/s is below 0"),
        "{text}"
    );
    assert!(text.contains("SPEED_MAX1_MRAD_S"), "{text}");
    assert!(!text.contains("--"), "no flag tip: {text}");
    let text = refused_locally(&["speed", "1800", "-2100"]);
    assert!(
        text.contains("the spin speed -2100 mrad/s is below 0"),
        "{text}"
    );
    let text = refused_locally(&["speed", "abc", "2100"]);
    assert!(text.contains("`abc` is not an integer"), "{text}");
    let text = refused_locally(&["set", "FOO", "1"]);
    assert!(text.contains("`FOO` is not a parameter"), "{text}");
    assert!(
        text.contains("MU_PPM") && text.contains("LINK_TIMEOUT_MS"),
        "the valid names: {text}"
    );
    let text = refused_locally(&["set", "MU_PPM", "-5"]);
    assert!(
        text.contains("MU_PPM -5 ppm is outside its range 0..=1000000"),
        "{text}"
    );
    let text = refused_locally(&["fly"]);
    assert!(
        text.contains("`fly` is not a command") && text.contains("speed"),
        "{text}"
    );
}

#[test]
fn a_zero_timeout_is_a_usage_error() {
    let out = bowl(&[
        "send",
        "/dev/null-never-opened",
        "status",
        "--timeout-ms",
        "0",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("'0'") && err.contains("1..=60000"), "{err}");
}

#[test]
fn replay_of_what_is_not_a_capture_says_so_and_fails() {
    let dir = temp_dir("not-a-capture");
    let text_file = dir.join("notes.txt");
    std::fs::write(&text_file, "minutes of the lab meeting\n").unwrap();
    let out = bowl(&["replay", text_file.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("notes.txt is not a capture of the rig's output"),
        "{err}"
    );
    let empty = dir.join("empty.bin");
    std::fs::write(&empty, "").unwrap();
    let out = bowl(&["replay", empty.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("empty.bin is empty"));
}

/// `--csv` naming the capture itself is refused before anything is written: the capture
/// stays as it was (it used to be emptied, then reported empty).
#[test]
fn replay_never_writes_its_csv_over_the_capture() {
    let dir = temp_dir("csv-over-capture");
    let capture = dir.join("run.bin");
    std::fs::write(&capture, "minutes of the lab meeting\n").unwrap();
    let path = capture.to_str().unwrap();
    let out = bowl(&["replay", path, "--csv", path]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("is the capture being read"), "{err}");
    assert_eq!(
        std::fs::read_to_string(&capture).unwrap(),
        "minutes of the lab meeting\n"
    );
}

/// A directory where a file is expected: the error names it (never a bare "Is a directory").
#[test]
fn every_file_error_names_its_file() {
    let dir = temp_dir("dir-for-file");
    let d = dir.to_str().unwrap();
    for args in [
        vec!["replay", d],
        vec!["chart", "log", "--csv", d, "--out", "x.svg"],
        vec!["fit", d],
        vec!["serve", "--capture", d, "--seconds", "1"],
    ] {
        let out = bowl(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_ne!(out.status.code(), Some(0), "{args:?}");
        assert!(err.contains(d), "{args:?} names the file: {err}");
    }
}

/// A directory given as the file to write: `bowl chart radial --out DIR` wrote DIR.svg, .png and
/// .csv beside it without a word; now refused (usage, exit 2) before any work, naming it.
#[test]
fn a_directory_to_write_to_is_refused_in_words() {
    let dir = temp_dir("dir-for-out");
    let d = dir.to_str().unwrap();
    for args in [
        vec!["chart", "radial", "--out", d],
        vec!["chart", "log", "--csv", "run.csv", "--out", d],
        vec!["replay", "run.bin", "--csv", d],
    ] {
        let out = bowl(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(&format!("{d} is a directory: give the name of a file")),
            "{args:?}: {err}"
        );
    }
    for ext in ["svg", "png", "csv"] {
        assert!(
            !dir.with_extension(ext).exists(),
            "{ext} written beside {d}"
        );
    }
}

/// A line that brings only damaged frames: the timeout says it is noisy and what to try.
#[test]
fn a_timeout_on_a_noisy_line_says_what_to_try() {
    let (mut master, path) = common::open_pty();
    let noise = std::thread::spawn(move || {
        for _ in 0..60 {
            // Frames whose CRC is wrong: what a noisy line delivers.
            if master.write_all(b"$T1,1,2,0,0*00000000\r\n").is_err() {
                break;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    });
    let out = bowl(&["send", &path, "status", "--timeout-ms", "600"]);
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(4), "{text}");
    assert!(text.contains("the line is noisy"), "{text}");
    assert!(text.contains("--timeout-ms"), "{text}");
    assert!(text.contains("damaged"), "the counters: {text}");
    noise.join().unwrap();
}
