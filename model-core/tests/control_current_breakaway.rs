//! The breakaway seen in the motor current (model-core/src/control/breakaway.rs, issue 27 part
//! 2): with current sense, a shaft whose static friction exceeds its running friction no longer
//! leaps past a low setpoint once it breaks away. Measured on the simulator's true speed, against
//! the same plants without current sense (the pulses-only loop, unchanged).

mod plant_rows;

use plant_rows::sensed;

use model_core::control::breakaway::{BackEmf, BackEmfScale, Breakaway};
use model_core::control::{Controller, ControllerConfig, State};
use model_core::sim::experiments::{commissioned_step, family_plant};
use model_core::sim::{ClosedLoop, CurrentSense, Plant, PlantParams};

/// Overshoot of both axes, % of the target, of the commissioned 0 -> `target` step.
fn overshoot_pct(rig: PlantParams, seed: u32, target: f32, load: [f32; 2]) -> [f32; 2] {
    let o = commissioned_step(rig, ControllerConfig::nominal(), seed, target, true, load);
    assert!(o.commissioned, "commissioning failed");
    assert_eq!(o.fault, None, "a false fault");
    [
        100.0 * o.reports[0].overshoot,
        100.0 * o.reports[1].overshoot,
    ]
}

/// A family plant's row (`plant_rows::rig_from_table`: supply, coupling, both axes) with
/// current sense on both axes: each axis's overshoot of the commissioned step from rest to
/// `target` (the plant's `seed`, the material `load` poured in after commissioning) is within
/// `bound_pct`.
fn sensed_row_within(
    supply_v: f32,
    coupling: f32,
    axes: [[f32; 9]; 2],
    (seed, target, load): (u32, f32, [f32; 2]),
    bound_pct: f32,
) {
    let rig = sensed(plant_rows::rig_from_table(supply_v, coupling, axes));
    let os = overshoot_pct(rig, seed, target, load);
    eprintln!("overshoot {os:?} %");
    for (axis, os) in os.iter().enumerate() {
        assert!(*os <= bound_pct, "axis {axis}: {os} % past {target} rad/s");
    }
}

#[test]
fn the_nominal_rig_reaches_half_a_radian_per_second_without_the_leap() {
    let pulses_only = overshoot_pct(PlantParams::nominal(), 1, 0.5, [0.0; 2]);
    let with_current = overshoot_pct(sensed(PlantParams::nominal()), 1, 0.5, [0.0; 2]);
    // Without current the precession leapt 35 %: its first edge came 0.6 s after the
    // breakaway and kept half the kick. That edge came before the model had turned a pitch,
    // which shows no load, and a rod's such edge now keeps nothing of the kick (pi.rs `early`;
    // docs/control.md, "The rod's kept kick from rest"): 5.1 %. The current shows the
    // breakaway at once.
    assert!(pulses_only[0] < 10.0, "pulses only: {pulses_only:?}");
    for (axis, os) in with_current.iter().enumerate() {
        assert!(*os <= 5.0, "axis {axis}: {os} % with current sense");
    }
}

#[test]
fn a_seeded_family_mostly_stays_within_ten_percent_at_half_a_radian_per_second() {
    // 20 plants of seed 5 (friction x0.5..x2, material added after commissioning), both axes.
    let mut within = 0;
    let mut worst: f32 = 0.0;
    let mut within_pulses = 0;
    let n = 20;
    for i in 0..n {
        let (rig, load) = family_plant(5, i);
        for os in overshoot_pct(sensed(rig), 5 + i, 0.5, load) {
            within += usize::from(os <= 10.0);
            worst = worst.max(os);
        }
        for os in overshoot_pct(rig, 5 + i, 0.5, load) {
            within_pulses += usize::from(os <= 10.0);
        }
    }
    let axes = 2 * n as usize;
    eprintln!(
        "within 10 %: {within} of {axes} with current, {within_pulses} pulses only; worst {worst} %"
    );
    // Measured: 39 of 40 with current sense (worst 27.9 %), 21 of 40 pulses only; main ignored
    // the current, so there both were 21.
    assert!(
        within * 100 >= 90 * axes,
        "{within} of {axes} axes within 10 % (pulses only {within_pulses})"
    );
    assert!(
        within > within_pulses + axes / 4,
        "{within} vs {within_pulses}"
    );
    assert!(worst < 50.0, "worst {worst} %");
}

/// The breakaway watch alone: a held shaft read through a current per duty 10 % off (the
/// supervisor's learned `g` on a family plant) is not taken for a turning one, and a turning
/// one is seen within a few samples.
#[test]
fn a_held_shaft_is_not_read_as_turning_and_a_turning_one_is_seen() {
    let duty_per_rad_s = 0.14;
    let friction_duty = 0.3;
    let r = 0.2;
    let mut b = Breakaway::NONE;
    // The duty rises through the friction duty at 4 per second, the shaft held: the current
    // is `h d` with `h = 0.9` (g learned 10 % high).
    let mut d = 0.0;
    for _ in 0..120 {
        d = (d + 0.004f32).min(0.45);
        assert!(!b.sample(
            d,
            0.9 * d,
            (BackEmf::identified(duty_per_rad_s), friction_duty),
            (true, true),
            r
        ));
    }
    // It breaks away and runs at 0.1 rad/s: the back-EMF takes `0.9 (k/V) w` off the current.
    let mut seen_after = None;
    for k in 0..20 {
        let c = 0.9 * (d - duty_per_rad_s * 0.1);
        if b.sample(
            d,
            c,
            (BackEmf::identified(duty_per_rad_s), friction_duty),
            (true, true),
            r,
        ) {
            seen_after = Some(k + 1);
            break;
        }
    }
    assert!(seen_after.is_some_and(|k| k <= 10), "{seen_after:?}");
}

/// `bowl sim make-family --seed 4 --plants 60`'s p10 (seed 4010), current sense on both axes:
/// a heavy rod with little friction (it breaks away below the commissioning's first duty) and
/// a stiff spin.
fn seed4_p10() -> (PlantParams, [f32; 2]) {
    // torque constant, inertia, viscous, Coulomb, stiction, tooth error, jitter, ripple;
    // the material is poured in by the caller (returned beside the plant)
    let rig = plant_rows::rig_from_table(
        10.841,
        0.566,
        [
            [
                1.4586, 0.05005, 0.00513, 0.0513, 0.0684, 0.0193, 0.000290, 0.0020, 0.0,
            ],
            [
                1.7605, 0.04249, 0.04873, 0.4873, 0.6822, 0.0422, 0.000367, 0.0063, 0.0,
            ],
        ],
    );
    (sensed(rig), [0.0173, 0.0954])
}

/// The spin's reaction turns the rod while the spin is commissioned; its estimator keeps that
/// last edge for seconds after the rod stopped. The rod's own breakaway search then started
/// "not at rest", and its start taught the watch no current per duty: every later start ran
/// pulses only (main: 0 learned, 60 % overshoot at 0.5 rad/s).
#[test]
fn a_rod_turned_by_the_spins_reaction_still_learns_its_current_per_duty() {
    let (rig, load) = seed4_p10();
    let ctrl = Controller::new(ControllerConfig::nominal()).expect("nominal config");
    let mut cl = ClosedLoop::new(Plant::new(rig, 4010), ctrl);
    assert_eq!(cl.commission(300.0), State::Idle);
    for axis in 0..2 {
        let m = rig.axes[axis].motor;
        // Held shaft: i = V d / R, read through the chain's gain.
        let truth = rig.supply_v / m.resistance_ohm * (1.0 + CurrentSense::TYPICAL.gain_error);
        let (_, g) = cl.ctrl.current_sense_learned(axis);
        assert!(
            (g - truth).abs() <= 0.25 * truth,
            "axis {axis}: learned {g} A per duty, held shaft {truth}"
        );
    }
    let os = overshoot_pct(rig, 4010, 0.5, load);
    assert!(os[0] <= 25.0, "precession overshoot {} %", os[0]);
}

/// `bowl sim make-family --seed 6 --plants 60`'s p24 (seed 6024), current sense on both axes: a
/// light rod whose identified breakaway duty (0.20) is ten times its friction duty. Its first
/// edge came 35 ms into the start, before the current had confirmed the breakaway, and the edge
/// kept half the kick in the integral as a load: 0.07 duty too much, 57.5 % past 0.5 rad/s on
/// main. Its back-EMF speed at that edge was already above the model speed's lower band: the
/// kick was more than it needed, and now nothing of it is kept, as at the current's breakaway.
#[test]
fn a_first_edge_before_the_current_confirms_the_breakaway_keeps_no_kick() {
    let rig = sensed(plant_rows::rig_from_table(
        10.263,
        0.570,
        [
            [
                1.8970, 0.01754, 0.00479, 0.0479, 0.0638, 0.0301, 0.000102, 0.0020, 0.0,
            ],
            [
                1.9013, 0.03305, 0.00497, 0.0497, 0.0696, 0.0184, 0.000355, 0.0074, 0.0,
            ],
        ],
    ));
    let os = overshoot_pct(rig, 6024, 0.5, [0.0451, 0.0616]);
    for (axis, os) in os.iter().enumerate() {
        assert!(*os <= 10.0, "axis {axis}: {os} % past 0.5 rad/s");
    }
}

/// family-60's p10 (tests/rigs/family-60.toml, seed 1010), current sense on both axes: a stiff
/// spin whose first tooth came 10 ms after its breakaway, before the current had confirmed it
/// (the back-EMF speed 0.11 rad/s, below the threshold of 0.15). The start counted as unconfirmed
/// from there, so the back-EMF band never held the integral: the spin crawled at 0.20 of 0.5
/// rad/s until the push between its first two edges drove it to 0.75 (50 % past, main after the
/// held commissioning steps moved where it stops). The edge now confirms the breakaway.
#[test]
// 0.3926 N m is p10's stiction as the rig file gives it, not an approximation of pi / 8.
#[allow(clippy::approx_constant)]
fn a_spin_whose_first_edge_beats_the_currents_confirmation_still_gets_the_band() {
    sensed_row_within(
        12.461,
        0.447,
        [
            [
                1.9008, 0.02858, 0.02126, 0.2126, 0.2835, 0.0123, 0.000554, 0.0020, 0.0,
            ],
            [
                1.2172, 0.05993, 0.02804, 0.2804, 0.3926, 0.0095, 0.000720, 0.0092, 0.0,
            ],
        ],
        (1010, 0.5, [0.0141, 0.0655]),
        25.0,
    );
}

/// The back-EMF per rad/s learned where the edges measure the speed (breakaway.rs's
/// `BackEmfScale`): from steady samples of `d - c = e w` through a sense chain's noise it
/// finds `e`, not the identified slope that also holds the viscous share; a duty that ramps
/// (a shaft ahead of the edges' window) teaches nothing; never above the identified slope.
#[test]
fn the_back_emf_is_learned_at_steady_measured_speeds() {
    let identified = 0.15;
    let e = 0.125;
    let dt = 1e-3;
    let mut noise = 0x1234_5678u32;
    let mut next_noise = || {
        noise = noise.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (noise >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    };
    // A ramp of the duty (commissioning's reaction: 0.2 a second) with a speed that lags it.
    let mut ramp = BackEmfScale::NONE;
    for k in 0..3000 {
        let d = 0.2 * k as f32 * dt;
        ramp.sample(d, 0.05, 0.5 * d / e, dt);
    }
    assert_eq!(
        ramp.back_emf(identified).duty_per_rad_s(1.0),
        identified,
        "a ramp taught it"
    );
    // Two steady steps, 2 s each: the current (as duty) 0.05 of friction, 0.007 duty of noise.
    let mut s = BackEmfScale::NONE;
    assert_eq!(
        s.back_emf(identified).duty_per_rad_s(1.0),
        identified,
        "nothing learned yet"
    );
    for w in [1.5f32, 3.0] {
        let d = 0.05 + e * w;
        for _ in 0..2000 {
            s.sample(d, 0.05 + 0.014 * next_noise(), w, dt);
        }
    }
    let learned = s.back_emf(identified).duty_per_rad_s(1.0);
    assert!(
        (learned - e).abs() <= 0.01 * e,
        "learned {learned}, true {e}"
    );
    // A slope above the identified one (impossible: that one holds the viscous share too) is
    // capped there.
    let mut high = BackEmfScale::NONE;
    for _ in 0..2000 {
        high.sample(0.05 + 0.2 * 2.0, 0.05, 2.0, dt);
    }
    assert_eq!(high.back_emf(identified).duty_per_rad_s(1.0), identified);
}

/// The back-EMF learned through a sense chain whose current per duty is off (`c = h (d - e w)`,
/// `h` the held ratio a start measures; the supervisor's `g` was 8 % off on seed 52 p21's
/// rod): read through the start's `h`, the learned slope is the true `e`; the slope of `d - c`
/// alone is not (it holds `(1 - h) d`: a heavy rod's friction duty made it 15 % high).
#[test]
fn the_back_emf_is_read_through_the_starts_held_ratio() {
    let identified = 0.15;
    let e = 0.105;
    let h = 0.92;
    let friction = 0.45;
    let mut s = BackEmfScale::NONE;
    for w in [1.0f32, 2.0, 3.0] {
        let d = friction + identified * w;
        for _ in 0..2000 {
            s.sample(d, h * (d - e * w), w, 1e-3);
        }
    }
    let emf = s.back_emf(identified);
    let read = emf.duty_per_rad_s(h);
    assert!((read - e).abs() <= 0.01 * e, "read {read}, true {e}");
    let plain = emf.duty_per_rad_s(1.0);
    assert!(plain > 1.1 * e, "without the held ratio {plain}, true {e}");
}

/// Seed 52's p21 (`bowl sim make-family --seed 52`, plant seed 52021), current sense on both
/// axes: a heavy rod (0.70 N m of friction, 0.6 duty at 1 rad/s, a back-EMF 0.70 of its
/// identified slope) whose first tooth came before the current confirmed its breakaway, so it
/// kept half its kick (0.034 duty). Its back-EMF speed was read through the slope of `d - c`
/// learned with the supervisor's current per duty 8 % off, and clamped at 1/1.25 of the
/// identified slope: 14 % low, never past the 1.2x of its model that drops the kick, and the rod
/// ran 11.4 % past 1 rad/s until its first measurement. Read through the start's held ratio it
/// reads its speed as it is, and the kick goes once it runs 10 % ahead of its model.
#[test]
fn a_heavy_rods_kept_kick_goes_once_its_back_emf_shows_it_ahead() {
    sensed_row_within(
        10.831,
        0.428,
        [
            [
                1.1348, 0.07595, 0.06984, 0.6984, 0.9312, 0.0231, 0.000789, 0.0020, 0.0,
            ],
            [
                1.6037, 0.00701, 0.00874, 0.0874, 0.1223, 0.0435, 0.000827, 0.0059, 0.0,
            ],
        ],
        (52021, 1.0, [0.0048, 0.0592]),
        5.0,
    );
}

/// family-60's p16 (tests/rigs/family-60.toml, seed 1016), current sense on both axes: a stiff
/// rod (stiction 0.94 N m) with much viscous friction: its slope `k + R b / k` is 1.83 V s/rad
/// of which the back-EMF `k` is 1.43, so read through the identified slope its back-EMF speed
/// was low. The back-EMF band held that reading above 0.8 of the model, the true speed higher,
/// and its first measurement found it 13.8 % past 0.5 rad/s (main). With the back-EMF learned in
/// commissioning's steady steps it reads its speed as it is.
#[test]
fn a_rod_read_through_its_learned_back_emf_does_not_overshoot() {
    sensed_row_within(
        11.273,
        0.560,
        [
            [
                1.4331, 0.02602, 0.07027, 0.7027, 0.9369, 0.0238, 0.000147, 0.0020, 0.0,
            ],
            [
                1.6443, 0.05420, 0.03114, 0.3114, 0.4360, 0.0302, 0.000857, 0.0030, 0.0,
            ],
        ],
        (1016, 0.5, [0.0070, 0.0676]),
        10.0,
    );
}

/// family-60's p13 (tests/rigs/family-60.toml, seed 1013), current sense on both axes: a spin
/// loaded with material (0.095 N m) the kick does not start; the push does, 2.5 s in, and the
/// current sees the breakaway. The back-EMF band then held it near 0.37 of 0.5 rad/s (its
/// back-EMF speed read 0.40, the band's lower edge) until the first measurement, 4.8 s in. The
/// start's reading was left out after a push, and the edges' loop took the spin into 5 % only
/// 10.4 s after the command (main); it now reads the load at that first measurement.
#[test]
fn a_pushed_spin_whose_breakaway_the_current_saw_takes_the_starts_reading() {
    let rig = sensed(plant_rows::rig_from_table(
        10.938,
        0.515,
        [
            [
                1.1466, 0.03203, 0.03213, 0.3213, 0.4283, 0.0296, 0.000921, 0.0020, 0.0,
            ],
            [
                1.3759, 0.00778, 0.00821, 0.0821, 0.1149, 0.0034, 0.000492, 0.0037, 0.0,
            ],
        ],
    ));
    let ctrl = Controller::new(ControllerConfig::nominal()).expect("nominal config");
    let mut cl = ClosedLoop::new(Plant::new(rig, 1013), ctrl);
    assert_eq!(cl.commission(300.0), State::Idle);
    let now = cl.rig.time_s() as f32;
    for (a, load) in cl.rig.params_mut().axes.iter_mut().zip([0.0334, 0.0949]) {
        a.faults.load_step_from_s = now;
        a.faults.load_step_nm = load;
    }
    cl.ctrl.set_motor_speeds(0.5, 0.5).expect("speeds");
    cl.ctrl.start().expect("start");
    // The spin's true speed from 5.5 to 7.5 s after the command: about a second after its
    // first measurement, before the edges' loop alone would have got it there.
    let dt = cl.dt_s();
    let (mut sum, mut n, mut peak) = (0.0f64, 0u32, 0.0f32);
    for k in 0..(7.5 / dt) as usize {
        cl.tick();
        assert_eq!(cl.ctrl.fault(), None, "a false fault");
        let w = cl.rig.speed_rad_s(1);
        peak = peak.max(w);
        if k as f32 * dt >= 5.5 {
            sum += f64::from(w);
            n += 1;
        }
    }
    let mean = sum / f64::from(n);
    eprintln!("spin: mean {mean:.3} rad/s from 5.5 to 7.5 s, peak {peak:.3}");
    assert!(
        (mean - 0.5).abs() <= 0.025,
        "spin at {mean} rad/s, not within 5 % of 0.5"
    );
    assert!(peak <= 0.55, "spin peaked at {peak} rad/s");
}

/// The breakaway watch of a light shaft held by material the model does not know: its
/// identified friction duty (0.017) is far below what holds it, so the start's fit below that
/// duty takes two or three samples, and the supervisor's current per duty, learned while the
/// shaft broke away below the duty that teaches it (0.024 against 0.05), is 26 % low. Held at
/// the kick's 0.08 duty for 1.4 s, the shaft's current is `h d` throughout (`h` 1.35 here):
/// read through the prior alone its back-EMF speed was -0.29 rad/s, and once it broke away the
/// watch saw 0.15 rad/s only at 0.40. The start's own held ratio (the largest mean of `c / d`:
/// the back-EMF only lowers it) reads it as it is.
#[test]
fn a_shaft_held_above_its_friction_duty_reads_its_own_held_ratio() {
    let (duty_per_rad_s, friction_duty, r) = (0.0976, 0.0174, 0.5);
    let h = 1.35;
    let mut noise = 0x2102_7000u32;
    let mut next_noise = || {
        noise = noise.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (noise >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    };
    let mut b = Breakaway::NONE;
    // The kick: the duty slews to 0.08 in ten ticks and stays there, the shaft held; the
    // current as duty carries the chain's noise (10 mA through g = 1.08 A per duty).
    let mut d = 0.0f32;
    let mut held_speed = Vec::new();
    for k in 0..1400 {
        d = (d + 0.008).min(0.08);
        let c = h * d + 0.018 * next_noise();
        assert!(
            !b.sample(
                d,
                c,
                (BackEmf::identified(duty_per_rad_s), friction_duty),
                (true, true),
                r
            ),
            "a held shaft released at tick {k}"
        );
        if k >= 500 {
            held_speed.push(b.speed_rad_s());
        }
    }
    let worst = held_speed.iter().fold(0.0f32, |m, w| m.max(w.abs()));
    assert!(worst <= 0.1, "the held shaft read {worst} rad/s");
    // It breaks away and accelerates at 0.7 rad/s^2 under the rising push (p27's spin):
    // `c = h (d - e w)`. The current shows it before 0.2 rad/s (threshold 0.15).
    let mut w = 0.0f32;
    let mut seen_at = None;
    for _ in 0..1000 {
        d += 0.00007;
        w += 0.0007;
        let c = h * (d - duty_per_rad_s * w) + 0.018 * next_noise();
        if b.sample(
            d,
            c,
            (BackEmf::identified(duty_per_rad_s), friction_duty),
            (true, true),
            r,
        ) {
            seen_at = Some(w);
            break;
        }
    }
    assert!(
        seen_at.is_some_and(|w| w <= 0.2),
        "breakaway seen at {seen_at:?} rad/s"
    );
}

/// `bowl sim make-family --seed 21 --plants 60`'s p27 (seed 21027), current sense on both axes:
/// a light spin (6.4 g m^2, Coulomb 0.027 N m) carrying 0.091 N m of material poured in after
/// commissioning, 3.3 times its friction. The kick does not start it; the push does, 1.5 s in.
/// Read through a current per duty 26 % low (above) the back-EMF band then held its back-EMF
/// speed at 0.8 of the model while the true speed ran 0.3 rad/s above that: 30.1 % past
/// 0.5 rad/s (main).
#[test]
fn a_light_spin_under_heavy_material_is_seen_breaking_away_and_does_not_leap() {
    sensed_row_within(
        11.351,
        0.497,
        [
            [
                1.6712, 0.03611, 0.02183, 0.2183, 0.2911, 0.0474, 0.000141, 0.0020, 0.0,
            ],
            [
                1.1269, 0.00640, 0.00271, 0.0271, 0.0379, 0.0134, 0.000458, 0.0058, 0.0,
            ],
        ],
        (21027, 0.5, [0.0351, 0.0906]),
        15.0,
    );
}
