//! What speed can do, end to end on the virtual rig (`bowl serve --pty`): `bowl predict --model
//! bowl --store-table PORT` stores the residence-time table computed with the bowl model at the
//! rig's limits, `bowl send PORT rtime table MS` refuses a target speed cannot give, in words
//! and with exit status 1, and answers one it can with setpoints at which the bowl model gives
//! that time back (docs/model.md §11).

mod common;

use common::{Sim, bowl, stdout, success_json};

fn send(port: &str, words: &str) -> (i32, String) {
    let mut args = vec!["send", port, "--timeout-ms", "3000"];
    args.extend(words.split_whitespace());
    let out = bowl(&args);
    (out.status.code().unwrap_or(-1), stdout(&out))
}

/// The bowl model's scene: a bare rim, tilt `tilt`, both motors at `w` rad/s.
fn scene(tilt: &str, w: &str) -> Vec<String> {
    [
        "predict",
        "--model",
        "bowl",
        "--axes-angle-deg",
        tilt,
        "--precession-rad-s",
        w,
        "--spin-rad-s",
        w,
        "--rim-radius-m",
        "0.075",
        "--ri-m",
        "0.0375",
        "--sliding-mu",
        "0.4",
        "--release-azimuth-deg",
        "0,90,180,270",
        "--json",
    ]
    .map(str::to_string)
    .to_vec()
}

fn store(port: &str, tilt: &str) -> serde_json::Value {
    let mut args = scene(tilt, "1.2");
    args.extend(["--store-table".to_string(), port.to_string()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    success_json(&bowl(&args), "bowl predict --store-table")
}

#[test]
fn without_a_table_rtime_table_says_how_to_store_one() {
    let sim = Sim::start(&[]);
    let (code, text) = send(&sim.path, "rtime table 500");
    assert_eq!(code, 1, "{text}");
    assert!(text.contains("INFEASIBLE"), "{text}");
    assert!(text.contains("no residence-time table is stored"), "{text}");
    assert!(text.contains("--store-table PORT"), "{text}");
}

/// At the rig's 60 deg gravity dominates: with the motors limited to 2 rad/s (bowl speeds up
/// to 3.5 rad/s, the range) T moves under 1 % over every allowed speed, and every
/// target is refused with the range predict computed.
#[test]
fn at_sixty_degrees_speed_cannot_set_t_and_the_refusal_says_so() {
    let sim = Sim::start(&[]);
    for axis in [1, 2] {
        let (code, text) = send(&sim.path, &format!("set SPEED_MAX{axis}_MRAD_S 2000"));
        assert_eq!(code, 0, "{text}");
    }
    let v = store(&sim.path, "60");
    let speed = &v["speed"];
    assert_eq!(speed["speed_can_set_T"], false, "{speed}");
    let words = speed["words"].as_str().unwrap();
    // "at 60 deg tilt T is 0.143-0.144 s at every speed from A to B rad/s: speed cannot ..."
    let span = words.split(": speed cannot").next().unwrap();
    assert!(span.starts_with("at 60 deg tilt T is 0.14"), "{words}");
    let [lo, hi] = [0, 1].map(|i| speed["residence_time_range_s"][i].as_f64().unwrap());
    let mid_ms = ((lo + hi) * 500.0).round() as i64;
    for ms in [mid_ms, 100, 2000] {
        let (code, text) = send(&sim.path, &format!("rtime table {ms}"));
        assert_eq!(code, 1, "{text}");
        assert!(text.contains("INFEASIBLE"), "{text}");
        assert!(text.contains(span), "{span} not in {text}");
        assert!(
            text.contains("speed cannot set it; the tilt or the wall can"),
            "{text}"
        );
    }
}

/// At 10 deg speed does set T: a target inside the stored range is answered with setpoints at
/// which the bowl model itself gives the target back (to the table's interpolation), one
/// outside is refused with the range.
#[test]
fn at_ten_degrees_a_target_inside_is_set_and_one_outside_refused() {
    let sim = Sim::start(&[]);
    let (code, text) = send(&sim.path, "set AXES_MDEG 10000");
    assert_eq!(code, 0, "{text}");
    let v = store(&sim.path, "10");
    let speed = &v["speed"];
    assert_eq!(speed["speed_can_set_T"], true, "{speed}");
    let [lo, hi] = [0, 1].map(|i| speed["residence_time_range_s"][i].as_f64().unwrap());
    let target_s = 0.5 * (lo + hi);
    let ms = (target_s * 1000.0).round() as i64;
    let (code, text) = send(&sim.path, &format!("rtime table {ms}"));
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("the stored table's model answered"), "{text}");
    // "precession 1.234 rad/s, spin 1.234 rad/s": the bowl model at those speeds.
    let after = |key: &str| {
        text.split(key)
            .nth(1)
            .and_then(|t| t.split(" rad/s").next())
            .unwrap()
            .trim()
            .to_string()
    };
    let (w1, w2) = (after("precession "), after("spin "));
    let mut args = scene("10", &w1);
    let at = args.iter().position(|a| a == "--spin-rad-s").unwrap();
    args[at + 1] = w2;
    args.extend(["--speed-range".to_string(), "false".to_string()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let back = success_json(&bowl(&args), "bowl predict at the chosen speeds");
    let t = back["residence_time_mean_s"].as_f64().unwrap();
    let asked = ms as f64 * 1e-3;
    assert!(
        (t - asked).abs() < 0.01 * asked,
        "the bowl model gives {t} s at the chosen speeds, {asked} s asked"
    );
    // Outside: refused, with the range.
    let (code, text) = send(
        &sim.path,
        &format!("rtime table {}", (hi * 1000.0) as i64 + 50),
    );
    assert_eq!(code, 1, "{text}");
    assert!(text.contains("at 10 deg tilt T is"), "{text}");
    assert!(text.contains("ask for a time in that range"), "{text}");
}
