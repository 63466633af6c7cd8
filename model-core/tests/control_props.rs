//! Property tests: no input sequence (commands, edges, current-sense readings) makes the
//! controller panic or command an invalid duty.

use model_core::control::commission::LineFit;
use model_core::control::{Controller, ControllerConfig, State};
use proptest::prelude::*;

#[derive(Debug, Clone)]
enum Op {
    Tick {
        dt_us: u32,
        e0: Vec<u32>,
        e1: Vec<u32>,
        currents: [Option<f32>; 2],
    },
    Speeds(f32, f32),
    Start,
    Stop,
    Clear,
    Commission,
    Tune(usize, f32, f32),
}

fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        -10.0f32..10.0,
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(-0.0f32),
        any::<f32>(),
    ]
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        6 => (0u32..5000, proptest::collection::vec(0u32..5000, 0..4),
              proptest::collection::vec(0u32..5000, 0..4),
              proptest::option::of(any_f32()), proptest::option::of(any_f32()))
            .prop_map(|(dt_us, e0, e1, c0, c1)| Op::Tick { dt_us, e0, e1, currents: [c0, c1] }),
        1 => (any_f32(), any_f32()).prop_map(|(a, b)| Op::Speeds(a, b)),
        1 => Just(Op::Start),
        1 => Just(Op::Stop),
        1 => Just(Op::Clear),
        1 => Just(Op::Commission),
        1 => (0usize..3, any_f32(), any_f32()).prop_map(|(a, b, c)| Op::Tune(a, b, c)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    #[test]
    fn any_command_and_edge_sequence_is_safe(
        ops in proptest::collection::vec(op(), 1..300),
        bits in prop_oneof![Just(16u8), Just(32u8)],
    ) {
        let mut cfg = ControllerConfig::nominal();
        cfg.timer_bits = bits;
        let mut c = Controller::new(cfg).unwrap();
        let mut now = 0u32;
        for op in ops {
            match op {
                Op::Tick { dt_us, e0, e1, currents } => {
                    // Edges at offsets inside (or, wrongly, beyond) this tick.
                    let e0: Vec<u32> = e0.iter().map(|o| now.wrapping_add(*o)).collect();
                    let e1: Vec<u32> = e1.iter().map(|o| now.wrapping_add(*o)).collect();
                    now = now.wrapping_add(dt_us);
                    // Any current-sense reading, NaN and infinite included (or none).
                    let d = c.tick_with_currents(now, [&e0, &e1], currents);
                    for x in d {
                        prop_assert!(x.is_finite() && x.abs() <= 1.0, "duty {x}");
                    }
                    if matches!(c.state(), State::Fault | State::Idle) {
                        prop_assert_eq!(d, [0.0, 0.0]);
                    }
                    let s = c.status();
                    prop_assert!(s.combined_measured_rad_s.is_finite());
                    prop_assert_eq!(s.fault_code, c.fault().map_or(0, |f| f.code()));
                    for axis in 0..2 {
                        let (offset, g) = c.current_sense_learned(axis);
                        prop_assert!(offset.is_finite() && g.is_finite() && g >= 0.0);
                    }
                }
                Op::Speeds(a, b) => {
                    let before = c;
                    if c.set_motor_speeds(a, b).is_err() {
                        prop_assert_eq!(c, before);
                    }
                }
                Op::Start => { let _ = c.start(); }
                Op::Stop => { let _ = c.stop(); }
                Op::Clear => { let _ = c.clear_fault(); }
                Op::Commission => { let _ = c.start_commissioning(); }
                Op::Tune(axis, bw, ppb) => {
                    let before = c;
                    if c.set_loop_tuning(axis, bw, ppb).is_err() {
                        prop_assert_eq!(c, before);
                    }
                }
            }
        }
    }

    #[test]
    fn line_fit_never_returns_non_finite(points in proptest::collection::vec((any_f32(), any_f32()), 0..50)) {
        let mut f = LineFit::default();
        for (x, y) in points {
            f.add(x, y);
        }
        if let Some((b, m)) = f.solve_span() {
            prop_assert!(b.is_finite() && m.is_finite());
        }
    }
}
