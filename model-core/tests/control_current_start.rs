//! Starts from rest to 1 rad/s with current sense on family plants whose start the current
//! read wrong (docs/control.md, "A start read the same way with current sense"): a spin its
//! material held still fed the rod a reaction it did not have, and the start's first window
//! was read without the proportional part and without the shaft's lag. Each plant is
//! commissioned, loaded with the material its model does not know, and measured on the
//! simulator's true speed.

#[allow(dead_code)] // the rod-only helper is for the pulses-only tests
mod from_rest;
mod plant_rows;

use plant_rows::sensed;

/// Seed 3's p19 (`bowl sim make-family --seed 3 --plants 60`): its spin's material held it for
/// a second after the command, while the decoupling fed the fast rod (time constant 0.07 s) the
/// reaction of a spin that would accelerate: the rod ran 13.2 % past 1 rad/s. The current shows
/// no breakaway, so no reaction: 2.4 %.
#[test]
fn with_current_a_spin_its_material_holds_gives_the_rod_no_reaction() {
    let p19 = plant_rows::rig_from_table(
        11.997,
        0.592,
        [
            [
                1.5136, 0.02503, 0.05552, 0.5552, 0.7402, 0.0295, 0.000169, 0.002, 0.0036,
            ],
            [
                1.2606, 0.03772, 0.04416, 0.4416, 0.6183, 0.026, 0.000155, 0.0038, 0.0951,
            ],
        ],
    );
    let [rod, spin] = from_rest::from_rest_to_1_rad_s(sensed(p19), 3019);
    assert!(
        rod.overshoot <= 0.05,
        "the rod passed 1 rad/s by {:.1} %",
        rod.overshoot * 100.0
    );
    assert!(
        spin.overshoot <= 0.05,
        "the spin passed 1 rad/s by {:.1} %",
        spin.overshoot * 100.0
    );
}

/// family-60's p10 (tests/rigs/family-60.toml): its loaded spin's first window read the load
/// right (0.315 rad/s), but the integral took it on top of the proportional part: 4.8 % past
/// 1 rad/s, within 2 % at 3.88 s. Read as without current sense (the correction this tick is the
/// load), it settles within 2 % by 3 s and passes the target by at most 2 %.
#[test]
#[allow(clippy::approx_constant)] // 0.3926 N m is the family row's stiction, not pi / 8
fn with_current_a_loaded_spins_first_window_is_read_as_without() {
    let p10 = plant_rows::rig_from_table(
        12.461,
        0.447,
        [
            [
                1.9008, 0.02858, 0.02126, 0.2126, 0.2835, 0.0123, 0.000554, 0.002, 0.0141,
            ],
            [
                1.2172, 0.05993, 0.02804, 0.2804, 0.3926, 0.0095, 0.00072, 0.0092, 0.0655,
            ],
        ],
    );
    let [_, spin] = from_rest::from_rest_to_1_rad_s(sensed(p10), 1010);
    from_rest::assert_settled_within_2_pct_by(spin, 3.0, "the spin");
}

/// Seed 5's p48 (`bowl sim make-family --seed 5 --plants 60`): a heavy rod (0.071 kg m^2, time
/// constant 0.23 s identified) the kick ran ahead of its model. Its first window read that as
/// no load (-0.077 rad/s, a third of the window the start's mismatch), the integral took 0.024
/// duty off where the rod needed 0.002 more, and the loop closed the rest at its bandwidth:
/// within 2 % of 1 rad/s at 3.43 s. The second window, read with the first, moves the load by
/// 0.1 rad/s (more than a window's noise): the rod settles within 3 s.
#[test]
fn with_current_a_rod_that_ran_ahead_of_its_model_is_read_again() {
    let p48 = plant_rows::rig_from_table(
        12.755,
        0.501,
        [
            [
                1.3866, 0.07126, 0.06492, 0.6492, 0.8656, 0.0404, 0.000811, 0.002, 0.0042,
            ],
            [
                1.8741, 0.05594, 0.01725, 0.1725, 0.2414, 0.0082, 0.000444, 0.0098, 0.0895,
            ],
        ],
    );
    let [rod, _] = from_rest::from_rest_to_1_rad_s(sensed(p48), 5048);
    from_rest::assert_settled_within_2_pct_by(rod, 3.0, "the rod");
}

/// Seed 31's p41 (`bowl sim make-family --seed 31 --plants 60`) at the lowest speed: a heavy
/// rod (friction duty 0.20, breakaway 0.33 identified) whose feedforward at 0.2 rad/s (0.22
/// duty) does not start it. The first current sample of the start, at zero duty, read the
/// sense chain's offset as 0.056 rad/s of back-EMF, a breakaway 3 ms in: the kick ended, and
/// the expected-edge watch faulted the rod that never turned ("sensor lost", 7.5 s in). Below
/// the friction duty no breakaway is taken: the kick starts it, and it runs within 5 %.
#[test]
fn with_current_no_breakaway_is_read_below_the_friction_duty() {
    let p41 = plant_rows::rig_from_table(
        11.430,
        0.545,
        [
            [
                1.1481, 0.02195, 0.03265, 0.3265, 0.4354, 0.0119, 0.000549, 0.002, 0.022,
            ],
            [
                2.0166, 0.01575, 0.00295, 0.0295, 0.0414, 0.041, 0.00016, 0.0068, 0.0395,
            ],
        ],
    );
    let [rod, _] = from_rest::from_rest_to(sensed(p41), 31041, 0.2);
    assert!(
        rod.settled && rod.overshoot <= 0.05,
        "the rod: settled {}, {:.1} % past 0.2 rad/s",
        rod.settled,
        rod.overshoot * 100.0
    );
}

/// Seed 34's p03 (`bowl sim make-family --seed 34 --plants 60`): a heavy rod (time constant
/// 0.56 s identified) whose first tooth came 60 ms into the start, before the current confirmed
/// the breakaway and while the rod was behind its model: half the kick (0.045 duty) stayed in
/// the integral until the first measurement, 1.2 s in, and the rod ran 35 % past 0.5 rad/s
/// while its back-EMF speed showed it 30 % ahead of the model. Dropped once the back-EMF shows
/// the rod ahead by more than the band: within 12 %.
#[test]
fn with_current_a_kept_kick_the_back_emf_shows_unneeded_goes() {
    let p03 = plant_rows::rig_from_table(
        11.054,
        0.488,
        [
            [
                1.1882, 0.10593, 0.011, 0.11, 0.1467, 0.0134, 0.000579, 0.002, 0.0333,
            ],
            [
                1.4789, 0.03963, 0.00312, 0.0312, 0.0437, 0.0331, 0.000297, 0.0051, 0.0559,
            ],
        ],
    );
    let [rod, _] = from_rest::from_rest_to(sensed(p03), 34003, 0.5);
    assert!(
        rod.overshoot <= 0.12,
        "the rod passed 0.5 rad/s by {:.1} %",
        rod.overshoot * 100.0
    );
}
