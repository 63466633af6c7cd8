//! RTIME through the protocol device: a paper model's target and its prediction, the stored
//! residence table's interpolation and its refusals.

extern crate std;

use super::tests::{TestDevice, command, station};
use super::*;
use crate::wire::Frame;

#[test]
fn residence_target_sets_speeds_whose_prediction_matches() {
    let mut s = station();
    let f = command(&mut s, "C1,10,RTIME,FLAT,2500");
    let st = s.rig.controller().status();
    // The answer names the model and carries the setpoints the controller now holds.
    let Frame::ResidenceSet {
        id: 10,
        model: ResidenceModel::Flat,
        precession_mrad_s,
        spin_mrad_s,
    } = f
    else {
        panic!("{f:?}");
    };
    let held = st.axes.map(|a| (a.target_rad_s * 1e3).round() as i16);
    assert_eq!([precession_mrad_s, spin_mrad_s], held);
    // The forward model at the combined target speed gives back the target.
    let m = s.rig.model(crate::particle::Model::Flat);
    let Residence::Ms(t) = m.predicted(st.combined_target_rad_s) else {
        panic!("the particle leaves at the chosen speed");
    };
    assert!(t.abs_diff(2500) <= 3, "predicted {t} ms for a 2.5 s target");
}

/// Stores `times_us` at bowl speeds 0.5..=3.6 rad/s as the PC does: speeds off first, the
/// fastest speed last (it switches the table on).
fn store_table(s: &mut TestDevice, times_us: [i32; 8]) {
    let mut id = 100;
    let mut set = |s: &mut TestDevice, token: &str, v: i32| {
        id += 1;
        let f = command(s, &std::format!("C1,{id},SET,{token},{v}"));
        assert_eq!(f, Frame::Ack { id }, "SET {token} {v}");
    };
    set(s, "RT_W_HI_MRAD_S", 0);
    for (k, t) in times_us.iter().enumerate() {
        set(s, &std::format!("RT_T{}_US", k + 1), *t);
    }
    set(s, "RT_W_LO_MRAD_S", 500);
    set(s, "RT_W_HI_MRAD_S", 3600);
}

/// The times of a table `T = 2 s / (1 + w)` at 0.5 + k 3.1/7 rad/s, us.
fn falling_table_us() -> [i32; 8] {
    core::array::from_fn(|k| {
        let w = 0.5 + k as f64 * 3.1 / 7.0;
        (2e6 / (1.0 + w)).round() as i32
    })
}

#[test]
fn rtime_table_without_a_table_is_infeasible() {
    let mut s = station();
    let f = command(&mut s, "C1,20,RTIME,TABLE,500");
    assert_eq!(
        f,
        Frame::Reject {
            id: 20,
            reason: Reason::Infeasible
        }
    );
}

#[test]
fn rtime_table_inside_the_table_sets_the_interpolated_speed() {
    let mut s = station();
    let times = falling_table_us();
    store_table(&mut s, times);
    // 0.8 s: between entries 2 (w = 1.386, T = 0.8381 s) and 3 (w = 1.829, T = 0.7071 s).
    let f = command(&mut s, "C1,21,RTIME,TABLE,800");
    let Frame::ResidenceSet {
        model: ResidenceModel::Table,
        ..
    } = f
    else {
        panic!("{f:?}");
    };
    // Independently: linear interpolation between the two bracketing entries.
    let (w2, w3) = (0.5 + 2.0 * 3.1 / 7.0, 0.5 + 3.0 * 3.1 / 7.0);
    let (t2, t3) = (f64::from(times[2]) * 1e-6, f64::from(times[3]) * 1e-6);
    let expected = w2 + (0.8 - t2) / (t3 - t2) * (w3 - w2);
    let got = f64::from(s.rig.controller().status().combined_target_rad_s);
    assert!(
        (got - expected).abs() < 1e-4,
        "{got} rad/s, expected {expected}"
    );
    // And the table at that speed gives the target back.
    let table = table_from_params(s.rig.params()).unwrap().unwrap();
    let back = table.residence_at_s(got as f32).unwrap();
    assert!((back - 0.8).abs() < 1e-4, "{back}");
}

#[test]
fn rtime_table_outside_or_flat_is_infeasible_and_changes_nothing() {
    let mut s = station();
    store_table(&mut s, falling_table_us());
    let before = s.rig.controller().status().combined_target_rad_s;
    // The table spans 0.4348 s (3.6 rad/s) to 1.3333 s (0.5 rad/s).
    for (id, ms) in [(30, 400), (31, 1400)] {
        let f = command(&mut s, &std::format!("C1,{id},RTIME,TABLE,{ms}"));
        assert_eq!(
            f,
            Frame::Reject {
                id,
                reason: Reason::Infeasible
            }
        );
    }
    assert_eq!(s.rig.controller().status().combined_target_rad_s, before);
    // 0.143 to 0.144 s over the whole range: speed cannot set it, even inside.
    store_table(
        &mut s,
        core::array::from_fn(|k| 143_000 + (k as i32) * 1_000 / 7),
    );
    let f = command(&mut s, "C1,32,RTIME,TABLE,143");
    assert_eq!(
        f,
        Frame::Reject {
            id: 32,
            reason: Reason::Infeasible
        }
    );
}

#[test]
fn a_switched_on_table_with_a_zero_time_is_refused() {
    let mut s = station();
    store_table(&mut s, falling_table_us());
    let f = command(&mut s, "C1,40,SET,RT_T4_US,0");
    assert_eq!(
        f,
        Frame::Reject {
            id: 40,
            reason: Reason::Range
        }
    );
    // Switched off, the same value is taken (the PC writes a table that way).
    assert_eq!(
        command(&mut s, "C1,41,SET,RT_W_HI_MRAD_S,0"),
        Frame::Ack { id: 41 }
    );
    assert_eq!(
        command(&mut s, "C1,42,SET,RT_T4_US,0"),
        Frame::Ack { id: 42 }
    );
}

#[test]
fn rtime_with_a_paper_model_outside_the_speed_limits_is_infeasible() {
    // Without a table the 1-D models answer, and refuse a time no allowed speed gives: the
    // flat model's T grows without bound as the bowl slows, and below the lowest speed the
    // sensors can measure, no setpoint gives 9999 s.
    let mut s = station();
    let f = command(&mut s, "C1,50,RTIME,FLAT,9999999");
    assert_eq!(
        f,
        Frame::Reject {
            id: 50,
            reason: Reason::Infeasible
        }
    );
    let f = command(&mut s, "C1,51,RTIME,CORI,1");
    assert_eq!(
        f,
        Frame::Reject {
            id: 51,
            reason: Reason::Infeasible
        }
    );
}
