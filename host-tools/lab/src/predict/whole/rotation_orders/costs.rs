//! What the rotation's bounds cost where they take the incline (the parent module's printout):
//! the second order from the incline's times, the incline, and the choice with both, on the
//! sliding row (60 deg, 3.6 rad/s, mu_s 0.4) and a rolling one (30 deg, 1.8 rad/s, mu_s 0.2,
//! at 1 %).

use super::*;

/// Times and prints them (1000 calls, best of 5); asserts the rolling row takes the second
/// order.
pub(super) fn costs() {
    // What a bound may cost on the rows it is to take: within 1.25x of the plain incline
    // leaves a quarter of the incline's own time (1000 calls, best of 5).
    let s = scene((60.0, 3.6, 3.6, 0.4, 0.0375, 0.075));
    let time = |f: &dyn Fn()| super::super::pinned::per_call_s(5, f);
    // The second order as the chooser runs it: from the incline's own times.
    let times = incline_times_s(&s).unwrap();
    let second = time(&|| {
        std::hint::black_box(
            model_core::choose::incline_rotation::mean_second_order_from(
                std::hint::black_box(&s),
                &times,
            ),
        );
    });
    let incline = time(&|| {
        std::hint::black_box(incline_mean_s(std::hint::black_box(&s)));
    });
    let choice = time(&|| {
        std::hint::black_box(choose_level(
            std::hint::black_box(&s),
            &BowlShape::bare_rim(),
            0.01,
            false,
        ));
    });
    // A rolling row the a-priori estimate refuses at 1 % and the second order takes: the
    // choice there runs the incline, its checks and the second order.
    let r = scene((30.0, 1.8, 1.8, 0.2, 0.0375, 0.075));
    let incline_r = time(&|| {
        std::hint::black_box(incline_mean_s(std::hint::black_box(&r)));
    });
    let choice_r = time(&|| {
        std::hint::black_box(choose_level(
            std::hint::black_box(&r),
            &BowlShape::bare_rim(),
            0.01,
            false,
        ));
    });
    assert!(
        choose_level(&r, &BowlShape::bare_rim(), 0.01, false)
            .second_order
            .is_some()
    );
    println!(
        "the incline {incline:.2e} s, the choice (with it) {choice:.2e} s, the closed-form second \
         order from the incline's times {second:.2e} s per call; on 30 deg, 1.8 rad/s, mu_s 0.2 at 1 %: the incline \
         {incline_r:.2e} s, the choice taking it by the second order {choice_r:.2e} s ({:.2}x)",
        choice_r / incline_r
    );
}
