//! The refusal texts, without a rig.

use super::*;
use model_core::binding::default_params;

fn w(s: &str) -> Vec<String> {
    s.split_whitespace().map(str::to_string).collect()
}

/// A rig's STATUS in `state`, with no fault.
fn status_in(state: model_core::wire::DeviceState) -> Status {
    use model_core::wire::{FaultCode, ResetCause};
    Status {
        state,
        fault: FaultCode::None,
        reset_cause: ResetCause::PowerOn,
        reset_count: 0,
        uptime_ms: 0,
        telemetry_hz: 10,
        flags: 0,
    }
}

/// A speed, a residence time, START or COMMISSION while stopping is told to wait for idle
/// (a speed got "see docs/protocol.md" where START got the wait).
#[test]
fn while_stopping_every_refused_command_is_told_to_wait_for_idle() {
    let s = status_in(model_core::wire::DeviceState::Stopping);
    for typed in ["speed 1000 1000", "rtime cori 800", "start", "commission"] {
        let words = w(typed);
        let text = state_words(&s, &words[0], &words);
        assert!(
            text.contains("wait until the rig is idle"),
            "{typed}: {text}"
        );
    }
}

/// CLEAR refused in any state but faulted is told there is no fault (a running rig got "see
/// docs/protocol.md for what each state allows").
#[test]
fn clear_without_a_fault_says_so_in_every_state() {
    use model_core::wire::DeviceState;
    for state in [
        DeviceState::Idle,
        DeviceState::ChangingSpeed,
        DeviceState::Running,
        DeviceState::Stopping,
        DeviceState::Commissioning,
    ] {
        let text = state_words(&status_in(state), "clear", &w("clear"));
        assert!(
            text.contains("there is no fault to clear"),
            "{state:?}: {text}"
        );
    }
}

/// A loop bandwidth SET while commissioning is told it waits for the end of commissioning;
/// before, the refusal listed commissioning among the states `set` is taken in.
#[test]
fn a_loop_setting_refused_while_commissioning_says_why() {
    let s = status_in(model_core::wire::DeviceState::Commissioning);
    for typed in ["set BW1_MRAD_S 8000", "set per_pulse2_milli 400"] {
        let words = w(typed);
        let text = state_words(&s, "set", &words);
        let name = words[1].to_ascii_uppercase();
        assert!(
            text.contains(&format!("{name} changes in any state but commissioning"))
                && text.contains("wait until it is idle again")
                && !text.contains("is taken while"),
            "{typed}: {text}"
        );
    }
}

/// A STATE refusal whose STATUS came back in a state that takes the command (the monitor asks
/// after the refusal, and a `stop` typed next had ended the run meanwhile) says the state has
/// changed and to send it again. Before: "the rig is idle: see docs/protocol.md for what each
/// state allows (`set` is taken while idle, ...)", naming the state as the reason.
#[test]
fn a_state_the_rig_has_since_left_is_said_so() {
    use model_core::wire::DeviceState as D;
    for (typed, state, what) in [
        ("set TEETH1 5", D::Idle, "`set TEETH1`"),
        ("set teeth1 5", D::Faulted, "`set TEETH1`"),
        ("set BW1_MRAD_S 8000", D::Running, "`set BW1_MRAD_S`"),
        ("speed 1000 1000", D::Running, "`speed`"),
        ("start", D::Idle, "`start`"),
        ("commission", D::Idle, "`commission`"),
        ("clear", D::Faulted, "`clear`"),
    ] {
        let words = w(typed);
        let text = state_words(&status_in(state), &words[0], &words);
        assert!(
            text.contains(&format!("now, where {what} is taken"))
                && text.contains("send it again")
                && !text.contains("see docs/protocol.md"),
            "{typed} in {state:?}: {text}"
        );
    }
    // Still refused in the state answered: the reason, as before.
    let words = w("set TEETH1 5");
    let text = state_words(&status_in(D::Running), "set", &words);
    assert!(text.contains("stop the motors first"), "{text}");
}

#[test]
fn speed_above_the_limit_names_the_axis_and_limit() {
    let p = default_params();
    let max2 = p[ParamId::SpeedMax2MradS.index()];
    let text = speed_limits(&w(&format!("speed 1000 {}", max2 + 1)), &p).unwrap();
    assert!(text.contains("spin speed"), "{text}");
    assert!(text.contains(ParamId::SpeedMax2MradS.token()), "{text}");
    assert!(!text.contains("precession"), "{text}");
}

#[test]
fn speed_below_the_sensor_names_the_lowest() {
    let p = default_params();
    let text = speed_limits(&w("speed 10 0"), &p).unwrap();
    assert!(
        text.contains("precession speed 0.010 rad/s is below"),
        "{text}"
    );
}

#[test]
fn a_flat_table_is_said_in_the_issues_words() {
    let t: [f32; 8] = core::array::from_fn(|k| 0.1432 + 0.0009 * k as f32 / 7.0);
    let table = SpeedTable::new(0.5, 3.6, t).unwrap();
    assert_eq!(
        speed_range_words(60.0, &table),
        "at 60 deg tilt T is 0.143-0.144 s at every speed from 0.50 to 3.60 rad/s: speed \
         cannot set it; the tilt or the wall can"
    );
    let p = default_params();
    assert!(table_refusal(&w("rtime table 143"), &p).contains("no residence-time table"));
    let p = with_table(p, &table);
    let text = table_refusal(&w("rtime table 143"), &p);
    assert!(
        text.starts_with("0.143 s asked; at 60 deg tilt T is 0.143-0.144 s"),
        "{text}"
    );
}

/// `p` with `table` stored in its residence-time parameters.
fn with_table(mut p: ParamValues, table: &SpeedTable) -> ParamValues {
    for (id, v) in model_core::binding::TABLE_PARAMS
        .into_iter()
        .zip(model_core::binding::table_to_params(table).unwrap())
    {
        p[id.index()] = v;
    }
    p
}

/// A table whose speed sets T quotes only times it takes (rounded inwards, checked against
/// the table's own `omega_for_s`); a flat one says that a time inside its range is what
/// every speed gives, and one outside it is not reachable.
#[test]
fn the_quoted_times_are_the_ones_the_table_takes() {
    let t: [f32; 8] = core::array::from_fn(|k| 0.16773 + 0.011 * k as f32 / 7.0);
    let table = SpeedTable::new(0.5, 3.6, t).unwrap();
    assert!(!table.is_flat());
    let words = speed_range_words(60.0, &table);
    assert!(words.contains("T is 0.168-0.178 s"), "{words}");
    for ms in [168.0f32, 178.0] {
        assert!(table.omega_for_s(ms * 1e-3).is_ok(), "{ms} ms");
    }
    // Rounded to the nearest, the ends would be 0.168-0.179: 179 ms is refused.
    assert!(table.omega_for_s(0.179).is_err());
    let flat: [f32; 8] = core::array::from_fn(|k| 0.16773 + 0.0011 * k as f32 / 7.0);
    let flat = SpeedTable::new(0.5, 3.6, flat).unwrap();
    assert!(flat.is_flat());
    let p = with_table(default_params(), &flat);
    let inside = table_refusal(&w("rtime table 168"), &p);
    assert!(
        inside.contains("that is the time the rig gives at any of these speeds"),
        "{inside}"
    );
    let outside = table_refusal(&w("rtime table 150"), &p);
    assert!(
        outside.contains("speed cannot set it") && !outside.contains("any of these speeds"),
        "{outside}"
    );
}

/// A finite, positive range is printed for the nominal rig (its ends are checked against
/// the rig itself in tests/refusal_e2e.rs).
#[test]
fn residence_range_is_printed_for_the_nominal_rig() {
    let p = default_params();
    let text = residence_range(&w("rtime cori 1"), &p).unwrap();
    assert!(text.contains("this rig can give"), "{text}");
    let shortest: f64 = text
        .split("this rig can give ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap();
    assert!(shortest > 0.0 && shortest.is_finite(), "{text}");
}
