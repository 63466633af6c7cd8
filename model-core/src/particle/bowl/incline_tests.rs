//! The wall of a still, tilted bowl against the incline's closed forms (issue 30: "every limit
//! checked by a test against its closed form"). On the downhill meridian the cone is a straight
//! line at `alpha - th` from the horizontal, and gravity has no part across the meridian plane,
//! so a granule moving along it stays on it: a sphere on an incline, with the wall's rolling
//! resistance and sliding friction. The held-out sweep's scene 20 (docs/model.md §10) turned on
//! how much speed a granule keeps climbing a 36 deg wall; these hold the climb itself.

use super::tests::{run_on_wall, shape};
use super::wall::{Contact, Meridian, WallState, wall_forces};
use crate::particle::rolling::RollingScene;

const G: f64 = 9.81;

/// A still bowl tilted `th_deg`, granule radius 3 mm, on a 100 mm bottom.
fn still(th_deg: f64, mu_r: f64, mu_s: f64) -> RollingScene<f64> {
    RollingScene {
        precession_rad_s: 0.0,
        spin_rad_s: 0.0,
        axes_angle_rad: th_deg.to_radians(),
        rolling_resistance: mu_r,
        sliding_friction: mu_s,
        g_m_s2: G,
        k2: 5.0 / 7.0,
        particle_radius_m: 0.003,
        rod_length_m: 0.0,
        ri_m: 0.05,
        rim_radius_m: 0.1,
    }
}

/// Rolling up and down the downhill meridian of a still cone (tilt 20 deg, walls at 50 and 75
/// deg: inclines of 30 and 55 deg): the speed along it changes at `k2 g (sin b + mu_r cos b)`
/// going up and `k2 g (sin b - mu_r cos b)` coming down (`b = alpha - th`), the normal force is
/// `g cos b`, and it stays on the meridian; to 1e-9.
#[test]
fn rolling_on_a_still_tilted_cone_is_rolling_on_an_incline() {
    let th = 20.0;
    for (alpha, mu_r) in [(50.0, 0.03), (75.0, 0.05), (50.0, 0.0)] {
        let sc = still(th, mu_r, 10.0);
        let m: Meridian<f64> = shape(alpha, 0.3, 0.01).meridian(&sc).unwrap();
        let b = (alpha - th).to_radians();
        let s0 = m.arc_length() + 0.05;
        for v0 in [0.8, -0.3] {
            // Downhill is the bowl frame's -x (gravity `-g (sin th, 0, cos th)` at t = 0): the
            // azimuth `(ex, ey) = (-1, 0)`, where the meridian's tangent is `(-cos a, 0, sin a)`
            // and the normal towards the centre `(sin a, 0, cos a)`. Rolling: `s = n x u`.
            let y0: WallState<f64> = [s0, -1.0, 0.0, v0, 0.0, 0.0, -v0, 0.0];
            let decel = if v0 > 0.0 {
                5.0 / 7.0 * G * (b.sin() + mu_r * b.cos())
            } else {
                5.0 / 7.0 * G * (b.sin() - mu_r * b.cos())
            };
            // Up: stop short of the apex, where the resistance turns; down: 50 ms.
            let t1 = if v0 > 0.0 { 0.8 * v0 / decel } else { 0.05 };
            let y = run_on_wall(&sc, &m, y0, Contact::Roll, t1, |_| ());
            let s_closed = s0 + v0 * t1 - 0.5 * decel * t1 * t1;
            let v_closed = v0 - decel * t1;
            assert!(
                (y[0] - s_closed).abs() < 1e-9 * 0.05,
                "alpha {alpha} v0 {v0}: s {} closed {s_closed}",
                y[0]
            );
            assert!(
                (y[3] - v_closed).abs() < 1e-9 * v0.abs(),
                "alpha {alpha} v0 {v0}: speed {} closed {v_closed}",
                y[3]
            );
            assert!(
                y[2].abs() < 1e-12 && y[4].abs() < 1e-9,
                "left the meridian: {y:?}"
            );
            let f = wall_forces(&sc, &m, t1, &y, Contact::Roll);
            assert!((f.normal_m_s2 - G * b.cos()).abs() < 1e-9 * G);
            // Still rolling: the spin follows the speed (`s = n x u` = (0, -v, 0)).
            assert!((y[6] + y[3]).abs() < 1e-9 && y[5].abs() < 1e-9 && y[7].abs() < 1e-9);
        }
    }
}

/// Sliding up the downhill meridian of a still cone, thrown without spin: the speed falls at
/// `g (sin b + mu_s cos b)` and the spin grows at `(k2 / (1 - k2)) mu_s g cos b` (the friction's
/// torque) until the slip is gone; to 1e-9 before that.
#[test]
fn sliding_up_a_still_tilted_cone_is_sliding_up_an_incline() {
    let th = 20.0;
    for (alpha, mu_s) in [(50.0, 0.2), (75.0, 0.4)] {
        let sc = still(th, 0.03, mu_s);
        let m: Meridian<f64> = shape(alpha, 0.3, 0.01).meridian(&sc).unwrap();
        let b = (alpha - th).to_radians();
        let (sa, ca) = (m.alpha_rad.sin(), m.alpha_rad.cos());
        let (s0, v0) = (m.arc_length() + 0.05, 0.8);
        // The slip `u - s x n` points up the meridian, `(-cos a, 0, sin a)`: the friction down.
        let y0: WallState<f64> = [s0, -1.0, 0.0, v0, 0.0, 0.0, 0.0, 0.0];
        let decel = G * (b.sin() + mu_s * b.cos());
        let spin_rate = 2.5 * mu_s * G * b.cos();
        // The slip `v - |s|` is gone at `v0 / (decel + spin_rate)`: stop at 80 % of that.
        let t1 = 0.8 * v0 / (decel + spin_rate);
        let y = run_on_wall(&sc, &m, y0, Contact::Slide([-ca, 0.0, sa]), t1, |_| ());
        let s_closed = s0 + v0 * t1 - 0.5 * decel * t1 * t1;
        assert!(
            (y[0] - s_closed).abs() < 1e-9 * 0.05,
            "alpha {alpha}: s {} closed {s_closed}",
            y[0]
        );
        assert!(
            (y[3] - (v0 - decel * t1)).abs() < 1e-9 * v0,
            "alpha {alpha}: speed {}",
            y[3]
        );
        // The spin about the azimuth's axis, the sense that rolls it up the wall: `-s_y`.
        assert!(
            (-y[6] - spin_rate * t1).abs() < 1e-9 * v0,
            "alpha {alpha}: spin {}",
            y[6]
        );
        assert!(y[5].abs() < 1e-9 && y[7].abs() < 1e-9 && y[4].abs() < 1e-9);
    }
}
