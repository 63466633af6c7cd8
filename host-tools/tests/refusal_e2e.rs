//! A refusal says why in particulars: the value and its limit (`RANGE`), the state the rig is
//! in (`STATE`), the residence times it can give (`INFEASIBLE`). Checked against the virtual rig
//! itself: the ends of the range `bowl send` prints are accepted just inside and refused just
//! outside by the rig.

mod common;

use common::{Sim, bowl, send, sim_timed, stdout};
use model_core::binding::default_params;
use model_core::wire::ParamId;

#[test]
fn state_refusal_says_the_state_and_what_to_do() {
    let sim = Sim::start(&[]);
    let (code, text) = send(&sim.path, "clear");
    assert_eq!(code, 1, "{text}");
    assert!(text.contains("rejected"), "{text}");
    assert!(
        text.contains("the rig is idle: there is no fault to clear"),
        "{text}"
    );
    // The states the command table allows it in.
    assert!(text.contains("(`clear` is taken while faulted)"), "{text}");
}

/// SET's states are the parameter's: a setting that rebuilds the controller is refused while
/// the motors run with that reason, and one that changes while running (the loop tuning) is
/// taken. Checked against the rig: each parameter's role says which, and the rig agrees.
#[test]
fn set_while_running_names_the_parameter_and_what_to_do() {
    let sim = sim_timed("30", &["0:speed,1000,1000", "0:start"]);
    std::thread::sleep(std::time::Duration::from_millis(300));
    let (code, text) = send(&sim.path, "set CUR_SENSE 1");
    assert_eq!(code, 1, "{text}");
    // The suggestion names the port given, so it can be pasted as it stands.
    assert!(
        text.contains(&format!(
            "CUR_SENSE changes only while the rig is idle or faulted (it rebuilds the \
             controller); stop the motors first (`bowl send {} stop`), then set it",
            sim.path
        )),
        "{text}"
    );
    let bw = default_params()[ParamId::Bandwidth1MradS.index()];
    let (code, text) = send(&sim.path, &format!("set BW1_MRAD_S {bw}"));
    assert_eq!(code, 0, "loop tuning is taken while running: {text}");
}

#[test]
fn speed_refusal_names_the_axis_and_its_limit() {
    let sim = Sim::start(&[]);
    let max2 = default_params()[ParamId::SpeedMax2MradS.index()];
    let (code, text) = send(&sim.path, &format!("speed 1500 {}", max2 + 100));
    assert_eq!(code, 1, "{text}");
    let limit = format!(
        "the spin speed {:.3} rad/s is above SPEED_MAX2_MRAD_S = {:.3} rad/s",
        f64::from(max2 + 100) * 1e-3,
        f64::from(max2) * 1e-3
    );
    assert!(text.contains(&limit), "{text}");
}

#[test]
fn parameter_out_of_its_range_is_refused_locally_with_the_range() {
    let (lo, hi) = ParamId::MuPpm.range();
    let out = bowl(&[
        "send",
        "/dev/null-not-used",
        "set",
        "MU_PPM",
        &(i64::from(hi) + 1).to_string(),
    ]);
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(2), "a usage error: {text}");
    assert!(text.contains("rejected locally"), "{text}");
    assert!(
        text.contains(&format!("is outside its range {lo}..={hi}")),
        "{text}"
    );
}

/// The range printed is the rig's: 2 % inside either end is accepted, 2 % outside refused.
#[test]
fn infeasible_residence_time_gives_the_range_the_rig_accepts() {
    let sim = Sim::start(&[]);
    let (code, text) = send(&sim.path, "rtime cori 1");
    assert_eq!(code, 1, "{text}");
    assert!(text.contains("INFEASIBLE"), "{text}");
    let range = text
        .split("this rig can give ")
        .nth(1)
        .unwrap_or_else(|| panic!("no range in {text}"));
    let seconds = |part: &str| -> f64 {
        part.trim()
            .split(" s")
            .next()
            .and_then(|t| t.parse().ok())
            .unwrap_or_else(|| panic!("no time in {part:?} of {text}"))
    };
    let shortest_s = seconds(range);
    let longest_s = seconds(range.split(" to ").nth(1).unwrap_or(""));
    assert!(shortest_s < longest_s, "{text}");
    let ms = |t: f64| ((t * 1000.0).round() as i64).to_string();
    for (t, accepted) in [
        (shortest_s * 1.02, true),
        (shortest_s * 0.98, false),
        (longest_s * 0.98, true),
        (longest_s * 1.02, false),
    ] {
        let (code, text) = send(&sim.path, &format!("rtime cori {}", ms(t)));
        assert_eq!(code, if accepted { 0 } else { 1 }, "{t} s: {text}");
    }
}

/// A SET inside the parameter's own range is taken unless it breaks a rule tying it to another
/// parameter, and then the refusal names that rule with both values. The rig is the check:
/// every controller parameter is taken at both ends of its documented range (a QA pass found
/// SPEED_MAX 200, ACCEL 1..9 and DUTY_MAX 500 inside the range yet refused, with a text about
/// the start radius), and a start radius at the rim is refused with the rim's value.
#[test]
fn set_inside_its_range_is_taken_or_refused_with_the_rule_it_breaks() {
    let sim = Sim::start(&[]);
    let defaults = default_params();
    for id in [
        ParamId::SpeedMax1MradS,
        ParamId::SpeedMax2MradS,
        ParamId::Accel1MradS2,
        ParamId::Accel2MradS2,
        ParamId::DutyMax1Bp,
        ParamId::DutyMax2Bp,
        ParamId::Bandwidth1MradS,
        ParamId::PerPulse2Milli,
        ParamId::Teeth1,
    ] {
        let (lo, hi) = id.range();
        for value in [lo, hi, defaults[id.index()]] {
            let (code, text) = send(&sim.path, &format!("set {} {value}", id.token()));
            assert_eq!(code, 0, "{} {value}: {text}", id.token());
        }
    }
    // The rig's own rim (the virtual rig's bowl, not the table's default).
    let (_, params) = send(&sim.path, "params");
    let rim: i32 = params
        .split_whitespace()
        .find_map(|kv| kv.strip_prefix("RIM_UM="))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no RIM_UM in {params}"));
    let (code, text) = send(&sim.path, &format!("set START_UM {rim}"));
    assert_eq!(code, 1, "{text}");
    assert!(
        text.contains(&format!(
            "the granule's start radius START_UM = {rim} um must lie inside the rim RIM_UM = \
             {rim} um"
        )),
        "{text}"
    );
}

/// `start` while the motors run says so and what to do instead; a SET that waits for idle while
/// the rig is already stopping says to wait, not to stop.
#[test]
fn start_while_running_and_set_while_stopping_say_what_to_do() {
    let sim = Sim::start(&[]);
    // Slow ramps, so the stop lasts seconds; no watchdog, so the test's pauses fault nothing.
    for words in [
        "set LINK_TIMEOUT_MS 0",
        "set ACCEL1_MRAD_S2 500",
        "set ACCEL2_MRAD_S2 500",
        "speed 3000 3000",
        "start",
    ] {
        let (code, text) = send(&sim.path, words);
        assert_eq!(code, 0, "{words}: {text}");
    }
    let (code, text) = send(&sim.path, "start");
    assert_eq!(code, 1, "{text}");
    assert!(
        text.contains(
            "already running (state changing-speed); change speed with `speed`, or `stop` first"
        ) || text.contains(
            "already running (state running); change speed with `speed`, or `stop` first"
        ),
        "{text}"
    );
    std::thread::sleep(std::time::Duration::from_secs(2));
    let (code, text) = send(&sim.path, "stop");
    assert_eq!(code, 0, "{text}");
    let (code, text) = send(&sim.path, "set CUR_SENSE 1");
    assert_eq!(code, 1, "{text}");
    assert!(text.contains("the rig is stopping"), "{text}");
    assert!(
        text.contains("wait until the rig is idle") && !text.contains("stop the motors first"),
        "{text}"
    );
}
