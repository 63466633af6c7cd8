//! The order of the pieces of the rolling loop through rests (`rest_loop`), which both rolling
//! runs take from it: a held rest holds, a hold's end restarts with its own stretches (to the
//! start speed, then the slow speed) and does not hold again at once, a release from rest that
//! is not held restarts so too, and a rest the resistance cannot hold rolls on.

// The scripted pieces keep their answers and log on the heap, in the tests only.
extern crate std;

use core::ops::ControlFlow;
use std::vec;
use std::vec::Vec;

use super::equations::State;
use super::rest::{slow_speed_m_s, start_speed_m_s};
use super::rest_loop::{AfterHold, AfterPiece, AfterRoll, RollPieces, Rolled, roll_with_rests};
use super::*;

/// The QA round's scene (`rest_tests::stopping`) on a bottom whose rolling resistance holds a
/// granule at rest anywhere (`mu_r` g far above the drive of its 5 deg tilt at 3.3 rad/s).
fn sticky() -> RollingScene<f64> {
    RollingScene {
        rolling_resistance: 1.0,
        ..super::rest_tests::stopping()
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    Hold(f64, State<f64>),
    Roll(f64, State<f64>, Option<f64>),
}

/// Pieces that end as scripted, one answer a call, and log what the loop asked of them.
struct Scripted {
    holds: Vec<ControlFlow<&'static str, f64>>,
    rolls: Vec<Rolled<f64, &'static str>>,
    log: Vec<Piece>,
}

impl RollPieces<f64> for Scripted {
    type End = &'static str;

    fn next(&mut self, _: f64, y: &State<f64>) -> AfterPiece<f64, Self::End> {
        Ok(ControlFlow::Continue(*y))
    }

    fn hold(&mut self, t: f64, rest: &State<f64>) -> AfterHold<f64, Self::End> {
        self.log.push(Piece::Hold(t, *rest));
        Ok(self.holds.remove(0))
    }

    fn roll(&mut self, t: f64, y: &State<f64>, start: Option<f64>) -> AfterRoll<f64, Self::End> {
        self.log.push(Piece::Roll(t, *y, start));
        Ok(self.rolls.remove(0))
    }
}

#[test]
fn a_held_rest_holds_then_restarts_by_its_own_stretch_and_an_unheld_one_rolls_on() {
    let s = sticky();
    let at = |u: [f64; 2]| [0.02, 0.01, u[0], u[1], 0.5];
    let still = at([0.0, 0.0]);
    let start = start_speed_m_s(&s);
    let mut pieces = Scripted {
        holds: vec![
            ControlFlow::Continue(1.0),
            ControlFlow::Break("held to the end"),
        ],
        rolls: vec![
            Rolled::Started(1.05, at([1.1 * start, 0.0])),
            Rolled::Started(1.1, at([0.01, 0.0])),
            // Turned by more than a right angle in a step, at a speed far above a rest's.
            Rolled::Rest(1.2, at([-0.05, 0.0])),
            // A located rest: only the integration's error is left of the velocity.
            Rolled::Rest(1.5, at([1e-9, -1e-9])),
        ],
        log: Vec::new(),
    };
    let end = roll_with_rests(&s, &mut pieces, (0.0, still)).unwrap();
    assert_eq!(end, "held to the end");
    assert_eq!(
        pieces.log,
        [
            Piece::Hold(0.0, still),
            // From the hold's end, not held again there: the restart stretch.
            Piece::Roll(1.0, still, Some(start)),
            // On up to the slow speed, a stretch still.
            Piece::Roll(1.05, at([1.1 * start, 0.0]), Some(slow_speed_m_s(&s))),
            // Under way: at the scene's own tolerances.
            Piece::Roll(1.1, at([0.01, 0.0]), None),
            Piece::Roll(1.2, at([-0.05, 0.0]), None),
            // Held with no velocity at all.
            Piece::Hold(1.5, still),
        ]
    );
}

#[test]
fn an_end_in_any_piece_ends_the_loop_there() {
    let s = sticky();
    let moving = [0.02, 0.01, 0.03, 0.0, 0.5];
    let mut pieces = Scripted {
        holds: Vec::new(),
        rolls: vec![Rolled::Ended("left")],
        log: Vec::new(),
    };
    assert_eq!(roll_with_rests(&s, &mut pieces, (0.0, moving)), Ok("left"));
    assert_eq!(pieces.log, [Piece::Roll(0.0, moving, None)]);
}

/// A release from rest that the resistance does not hold starts as a hold's end does (before,
/// as a roll at the scene's tolerances, which hovered near rest at the stick threshold:
/// `rest_tests::a_release_that_barely_starts_is_its_own_stretch`).
#[test]
fn a_release_from_rest_not_held_restarts_by_its_own_stretch() {
    let s = RollingScene {
        rolling_resistance: 0.0,
        ..super::rest_tests::stopping()
    };
    let still = [0.02, 0.01, 0.0, 0.0, 0.5];
    let mut pieces = Scripted {
        holds: Vec::new(),
        rolls: vec![Rolled::Ended("left")],
        log: Vec::new(),
    };
    assert_eq!(roll_with_rests(&s, &mut pieces, (0.0, still)), Ok("left"));
    assert_eq!(
        pieces.log,
        [Piece::Roll(0.0, still, Some(start_speed_m_s(&s)))]
    );
}
