//! The status LED's patterns: what the rig is doing, readable from across the lab without a PC.
//! Each state has its own rhythm in a 1 s frame, told apart by the number and length of flashes
//! (not by speed alone, which is hard to judge without a reference):
//!
//! | state                                  | pattern (1 s frame)                         |
//! |----------------------------------------|---------------------------------------------|
//! | idle                                   | one short flash (100 ms on, 900 ms off)     |
//! | driving (commissioning, changing speed, running, stopping) | on, one short gap (900 ms on, 100 ms off) |
//! | fault (any but link lost)              | fast blink, 5 flashes (100 ms on/off)       |
//! | link lost (fault `link-lost`)          | two flashes (100 on, 100 off, 100 on, 700 off) |
//!
//! Running on the internal oscillator because the crystal did not start (`clocks`): every
//! fourth frame shows three quick flashes (60 ms on, 60 ms off) instead, so the state stays
//! readable while the warning repeats.

use model_core::control::{Fault, State};

/// What the LED shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LedMode {
    /// Motors off, waiting for a command.
    Idle,
    /// A motor may be driven (commissioning, changing speed, running, stopping).
    Driving,
    /// A fault stopped the motors (sensor, over-speed, configuration).
    Fault,
    /// The host went silent while driving: the link-loss fault.
    LinkLost,
}

/// Length of one pattern frame, ms.
pub const FRAME_MS: u32 = 1_000;
/// The LED task's step: every pattern edge falls on a multiple of it.
pub const STEP_MS: u32 = 20;

impl LedMode {
    /// The mode for the controller's state and latched fault.
    pub fn of(state: State, fault: Option<Fault>) -> Self {
        match (state, fault) {
            (State::Fault, Some(Fault::HostSilent)) => LedMode::LinkLost,
            (State::Fault, _) => LedMode::Fault,
            (State::Idle, _) => LedMode::Idle,
            _ => LedMode::Driving,
        }
    }
}

/// Whether the LED is lit `t_ms` into the pattern (any time base: the pattern repeats).
pub fn lit(mode: LedMode, clock_fallback: bool, t_ms: u32) -> bool {
    let frame = t_ms / FRAME_MS;
    let t = t_ms % FRAME_MS;
    if clock_fallback && frame % 4 == 3 {
        // Three quick flashes: 0-60, 120-180, 240-300 ms.
        return t < 300 && (t / 60).is_multiple_of(2);
    }
    match mode {
        LedMode::Idle => t < 100,
        LedMode::Driving => t < 900,
        LedMode::Fault => (t / 100).is_multiple_of(2),
        LedMode::LinkLost => t < 100 || (200..300).contains(&t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Flashes (rising edges) and lit time in one frame, sampled at the task's step.
    fn frame(mode: LedMode, fallback: bool, start_ms: u32) -> (u32, u32) {
        let (mut flashes, mut on_ms, mut was) = (0, 0, false);
        for k in 0..FRAME_MS / STEP_MS {
            let on = lit(mode, fallback, start_ms + k * STEP_MS);
            flashes += u32::from(on && !was);
            on_ms += if on { STEP_MS } else { 0 };
            was = on;
        }
        (flashes, on_ms)
    }

    #[test]
    fn every_state_has_its_own_rhythm() {
        let seen = [
            LedMode::Idle,
            LedMode::Driving,
            LedMode::Fault,
            LedMode::LinkLost,
        ]
        .map(|m| frame(m, false, 0));
        assert_eq!(seen, [(1, 100), (1, 900), (5, 500), (2, 200)]);
    }

    #[test]
    fn the_clock_warning_takes_every_fourth_frame_only() {
        for mode in [LedMode::Idle, LedMode::Driving, LedMode::Fault] {
            assert_eq!(frame(mode, true, 3 * FRAME_MS), (3, 180));
            assert_eq!(frame(mode, true, 0), frame(mode, false, 0));
            assert_eq!(frame(mode, true, 4 * FRAME_MS), frame(mode, false, 0));
        }
    }

    #[test]
    fn modes_follow_the_controller() {
        use LedMode as L;
        assert_eq!(L::of(State::Idle, None), L::Idle);
        for s in [
            State::Commissioning,
            State::ChangingSpeed,
            State::Running,
            State::Stopping,
        ] {
            assert_eq!(L::of(s, None), L::Driving);
        }
        assert_eq!(L::of(State::Fault, Some(Fault::HostSilent)), L::LinkLost);
        assert_eq!(L::of(State::Fault, Some(Fault::Overspeed(1))), L::Fault);
        assert_eq!(L::of(State::Fault, None), L::Fault);
    }
}
