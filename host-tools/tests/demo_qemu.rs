//! `bowl demo` on the emulated board: where `qemu-system-arm` is installed and the firmware's
//! `qemu-rig` image builds, the demo (default `--rig auto`, `--fast`) drives that image through
//! its emulated USART and shows the same behaviour as on the host rig; otherwise it says why it
//! used the host rig, and asking for the board (`--rig qemu`) is a clear error.

mod common;

use std::process::{Command, Output};

use common::{BOWL, temp_dir};
use serde_json::Value;

fn qemu_installed() -> bool {
    std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|d| d.join("qemu-system-arm").is_file())
    })
}

fn demo(rig: &str, dir: &std::path::Path) -> Output {
    // The demo ends by itself (the board also ends its run by itself: `-append seconds=`).
    Command::new(BOWL)
        .args(["demo", "--fast", "--rig", rig, "--out"])
        .arg(dir)
        .output()
        .expect("bowl runs")
}

#[test]
fn the_demo_runs_on_the_emulated_board_or_says_why_not() {
    let dir = temp_dir("qemu");
    if !qemu_installed() {
        let out = demo("qemu", &dir);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("qemu-system-arm is not installed"), "{err}");
        let out = demo("auto", &dir);
        assert!(out.status.success());
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("not on the emulated board: qemu-system-arm is not installed"));
        return;
    }
    // What the README command does: the emulated board when its image builds, else the host rig
    // with the reason (a broken firmware build is the firmware tests' to catch; here the demo
    // must still run and say why it is not on the board).
    let out = demo("auto", &dir);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let on_board = text.contains("emulated board: firmware image");
    if !on_board {
        assert!(
            text.contains("not on the emulated board: the emulated board's image did not build"),
            "{text}"
        );
        eprintln!(
            "NOTE: qemu-system-arm is installed but the qemu-rig image did not build: the demo ran on the host rig"
        );
    }
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["rig"], if on_board { "qemu" } else { "host" });
    let checks = &summary["checks"];
    for check in [
        "speeds_tracked",
        "fault_stopped_both_motors",
        "residence_split_agrees",
        "link_clean",
    ] {
        assert_eq!(checks[check], true, "{check}: {text}");
    }
    assert_eq!(summary["ended_at_rest"], true);
    let fault = &summary["fault"];
    assert_eq!(fault["fault"], "no-pulses-spin");
    let detect = fault["detection_s"].as_f64().unwrap();
    let lo = fault["expected_detection_s"][0].as_f64().unwrap();
    let hi = fault["expected_detection_s"][1].as_f64().unwrap();
    assert!((lo..=hi).contains(&detect), "{detect} not in {lo}..{hi}");
    assert_eq!(fault["motors_off_s"].as_f64().unwrap(), detect);
}
