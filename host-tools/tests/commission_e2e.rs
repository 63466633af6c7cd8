//! End to end: `bowl commission` against `bowl serve --pty` (the virtual rig runs the same
//! controller and protocol binding as the firmware, on the simulated plant, in real time).

mod common;

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

use common::{BOWL, Sim, bowl, last_json};

/// Commissioning over the wire identifies the simulated motors (against the simulator's true
/// models, which `bowl sim commission` reports, with that test's tolerances), and the gains it
/// reports follow the loop's design rule (kp / ki = the identified time constant).
#[test]
fn commissioning_over_the_wire_identifies_the_simulated_motors() {
    let sim = Sim::start(&["--seconds", "120"]);
    let out = bowl(&["commission", &sim.path, "--json", "--timeout-s", "90"]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let got = last_json(&out);
    assert_eq!(got["result"], "ok");
    let truth: serde_json::Value =
        serde_json::from_slice(&bowl(&["sim", "commission"]).stdout).expect("JSON");
    let axes = got["axes"].as_array().expect("axes");
    assert_eq!(axes.len(), 2);
    for (a, t) in axes.iter().zip(truth["axes"].as_array().unwrap()) {
        let g = |k: &str| a[k].as_f64().unwrap_or_else(|| panic!("{k} in {a}"));
        let tr = |k: &str| t[k].as_f64().unwrap();
        let rel = |x: f64, y: f64| (x - y).abs() / y;
        assert_eq!(a["identified"], true, "{a}");
        assert!(
            rel(g("back_emf_v_per_rad_s"), tr("true_volts_per_rad_s")) < 0.03,
            "{a} vs {t}"
        );
        assert!(
            (g("friction_duty") - tr("true_friction_duty")).abs() < 0.01,
            "{a} vs {t}"
        );
        assert!(
            rel(g("time_constant_s"), tr("true_time_constant_s")) < 0.5,
            "{a} vs {t}"
        );
        assert!(
            rel(
                g("kp_duty_per_rad_s") / g("ki_duty_per_rad"),
                g("time_constant_s")
            ) < 1e-3,
            "{a}"
        );
        // The rig's parameter (8 rad/s nominal), never a null where the text gives a number.
        assert_eq!(g("bandwidth_rad_s"), 8.0, "{a}");
        assert!(a.get("bandwidth_unknown").is_none(), "{a}");
    }
}

/// The text run's progress lines are in the result's units (rad/s and duty as a fraction), and
/// its bandwidth is the JSON's.
#[test]
fn progress_is_in_the_units_of_the_result() {
    let sim = Sim::start(&["--seconds", "120"]);
    let out = bowl(&["commission", &sim.path, "--timeout-s", "90"]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    let progress: Vec<&str> = err
        .lines()
        .filter(|l| l.contains(" s  precession"))
        .collect();
    assert!(!progress.is_empty(), "{err}");
    for l in &progress {
        assert!(
            l.contains("rad/s duty") && !l.contains("mrad/s") && !l.contains(" bp"),
            "{l}"
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.matches("bandwidth 8.000 rad/s").count(), 2, "{text}");
}

/// A rig that is running refuses COMMISSION (STATE): exit 1, the reason explained in words, and
/// it keeps running; a rig whose sensor is lost fails commissioning with a fault: exit 1 too (a
/// run that faulted is a failed run, docs/console.md "Exit codes"; 4 is a timeout), told apart by
/// the JSON's `result` (`rejected` or `fault`) and the fault named.
#[test]
fn refusal_and_fault_both_exit_1_told_apart_by_their_result() {
    let sim = Sim::start(&["--seconds", "120"]);
    let send = |words: &[&str]| {
        let mut args = vec!["send", sim.path.as_str()];
        args.extend_from_slice(words);
        let o = bowl(&args);
        assert!(o.status.success(), "{words:?}: {o:?}");
    };
    send(&["speed", "1500", "1500"]);
    send(&["start"]);
    let out = bowl(&["commission", &sim.path, "--json"]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let got = last_json(&out);
    assert_eq!(got["result"], "rejected");
    assert_eq!(got["reason"], "STATE");
    // In words: the reason's token read back as the reason (`Reason::from_token`), explained.
    let out = bowl(&["commission", &sim.path]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let text = common::stdout(&out);
    let want = format!(
        "COMMISSION rejected: STATE - {}",
        rig_client::lines::explain(model_core::wire::Reason::State)
    );
    assert!(text.contains(&want), "{text}");
    // And what to do, as `bowl send PORT commission` says it (the rig's state, asked: still
    // changing speed or running by now).
    assert!(text.contains(": stop the motors first"), "{text}");

    send(&["stop"]);
    std::thread::sleep(std::time::Duration::from_secs(3));
    send(&["inject", "sensor1"]);
    let out = bowl(&["commission", &sim.path, "--json", "--timeout-s", "60"]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let got = last_json(&out);
    assert_eq!(got["result"], "fault");
    assert!(
        got["fault"]
            .as_str()
            .unwrap()
            .contains("precession motor: no sensor pulses"),
        "{got}"
    );
}

/// A `bowl monitor PORT --plain --seconds SECONDS`, once it has printed a status line (it holds
/// the port: `send` and `commission` go through it), and its output, to be kept open: a monitor
/// whose reader goes ends.
fn plain_monitor(
    port: &str,
    seconds: &str,
) -> (
    std::process::Child,
    std::io::Lines<BufReader<std::process::ChildStdout>>,
) {
    let mut monitor = Command::new(BOWL)
        .args(["monitor", port, "--plain", "--seconds", seconds])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(monitor.stdout.take().unwrap()).lines();
    assert!(
        lines.any(|l| l.unwrap().contains("frames ok")),
        "the monitor runs"
    );
    (monitor, lines)
}

/// A STOP from another console (`bowl send PORT stop` through the monitor, or typed into it)
/// ends commissioning at once and the rig goes back to idle with the models it had: that is not
/// "commissioning done" with those old models reported as identified (exit 0, as it was), but
/// `stopped`, exit 1, no axes, and in words what happened.
#[test]
fn a_stop_from_another_console_is_not_commissioning_done() {
    let sim = Sim::start(&["--seconds", "60"]);
    // The monitor holds the port, so `send` and `commission` both go through it.
    let (mut monitor, _output) = plain_monitor(&sim.path, "50");
    for json in [true, false] {
        let mut args = vec!["commission", sim.path.as_str()];
        if json {
            args.push("--json");
        }
        let commission = Command::new(BOWL)
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(1500));
        let stop = bowl(&["send", &sim.path, "stop"]);
        assert!(stop.status.success(), "{stop:?}");
        let out = commission.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{out:?}");
        if json {
            let got = last_json(&out);
            assert_eq!(got["result"], "stopped", "{got}");
            assert_eq!(got["axes"], serde_json::json!([]), "{got}");
        } else {
            let text = common::stdout(&out);
            assert!(
                text.contains("commissioning did NOT finish")
                    && text.contains("with the very motor models it had before")
                    && text.contains(&format!("`bowl send {} stop`", sim.path)),
                "{text}"
            );
            assert!(!text.contains("identified  Ke"), "{text}");
        }
    }
    // SIGTERM: the monitor ends its own way, its socket removed.
    let pid = nix::unistd::Pid::from_raw(monitor.id() as i32);
    nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGTERM).unwrap();
    monitor.wait().unwrap();
}

/// The two timeouts told apart, each with what to do: a rig that never answers COMMISSION
/// (before: "commissioning: timeout after 0.0 s") and commissioning that does not end within
/// `--timeout-s` (before: "commissioning: timeout after 1.0 s", no word of the motors).
#[test]
fn each_timeout_says_which_and_what_to_do() {
    let (_master, path) = common::open_pty();
    let out = bowl(&["commission", &path, "--timeout-s", "1"]);
    let text = common::stdout(&out);
    assert_eq!(out.status.code(), Some(4), "{text}");
    assert!(
        text.contains("commissioning not started: no answer to COMMISSION ("),
        "{text}"
    );
    let sim = Sim::start(&["--seconds", "30"]);
    let out = bowl(&["commission", &sim.path, "--timeout-s", "1"]);
    let text = common::stdout(&out);
    assert_eq!(out.status.code(), Some(4), "{text}");
    assert!(
        text.contains("commissioning did NOT end within --timeout-s 1.0 s")
            && text.contains("STOP sent, the motors are off")
            && text.contains("give a longer --timeout-s"),
        "{text}"
    );
    let (code, now) = common::send(&sim.path, "status");
    assert_eq!(code, 0, "{now}");
    assert!(now.contains("state=idle"), "{now}");
}

/// The monitor that `commission` went through ends meanwhile (`q` typed in it): said as that,
/// not as "the rig's port went away", which sent one to the cable.
#[test]
fn the_monitor_it_went_through_ending_is_said_so() {
    let sim = Sim::start(&["--seconds", "30"]);
    let (mut monitor, _output) = plain_monitor(&sim.path, "2");
    let out = bowl(&["commission", &sim.path]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("the `bowl monitor` this went through ended"),
        "{err}"
    );
    monitor.wait().unwrap();
}
