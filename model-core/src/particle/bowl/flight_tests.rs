//! Flight and landing (issue 30, part 2): the arc in the bowl frame against the bowl-frame
//! equations of a free particle, the ballistic arc's landing and exit against their closed
//! forms, the impact against its closed form, a lift-off scene that now answers, and no panic
//! or NaN on any finite input with flights.

use super::flight::{FlightEnd, Surface, fly, impact, launch, state_at};
use super::*;
use crate::particle::rolling::equations::{cross, frame};

fn scene(w1: f64, w2: f64, th_deg: f64, l: f64) -> RollingScene<f64> {
    RollingScene {
        precession_rad_s: w1,
        spin_rad_s: w2,
        axes_angle_rad: th_deg.to_radians(),
        rod_length_m: l,
        ..RollingScene::equal_speeds(1.0, 0.5, 0.15)
    }
}

fn close(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol * (1.0 + want.abs()),
        "{what}: {got} vs {want}"
    );
}

/// The closed-form arc seen from the bowl is the bowl frame's free particle:
/// `du/dt = gB - A_O - alpha x q - Omega x (Omega x q) - 2 Omega x u` and the spin `ds/dt = -a alpha - Omega x s`
/// (`rolling::equations`' frame, integrated here by RK4 at 1e-5 s), to 1e-9, for a tilted,
/// precessing, spinning bowl on a rod offset (both spin directions).
#[test]
fn the_arc_is_the_bowl_frames_free_particle() {
    for sc in [scene(2.5, 3.1, 60.0, 0.3), scene(-1.7, -2.7, 35.0, 0.1)] {
        let t0 = 0.37;
        let q0 = [0.03, -0.02, 0.004];
        let u0 = [0.2, 0.1, 0.3];
        let s0 = [0.05, -0.02, 0.01];
        let f = launch(&sc, t0, q0, u0, s0);
        let a = sc.particle_radius_m;
        let rhs = |t: f64, y: &[f64; 9]| -> [f64; 9] {
            let fr = frame(&sc, t);
            let q = [y[0], y[1], y[2]];
            let u = [y[3], y[4], y[5]];
            let s = [y[6], y[7], y[8]];
            let o = fr.omega;
            let oq = cross(&o, &q);
            let ooq = cross(&o, &oq);
            let aq = cross(&fr.alpha, &q);
            let ou = cross(&o, &u);
            let os = cross(&o, &s);
            let mut d = [0.0; 9];
            for i in 0..3 {
                d[i] = u[i];
                d[3 + i] = fr.gravity[i] - fr.carrier[i] - aq[i] - ooq[i] - 2.0 * ou[i];
                d[6 + i] = -a * fr.alpha[i] - os[i];
            }
            d
        };
        let mut y = [
            q0[0], q0[1], q0[2], u0[0], u0[1], u0[2], s0[0], s0[1], s0[2],
        ];
        let (h, n) = (1e-5, 30_000);
        let mut t = t0;
        for _ in 0..n {
            let k1 = rhs(t, &y);
            let k2: [f64; 9] = core::array::from_fn(|i| y[i] + 0.5 * h * k1[i]);
            let k2 = rhs(t + 0.5 * h, &k2);
            let k3: [f64; 9] = core::array::from_fn(|i| y[i] + 0.5 * h * k2[i]);
            let k3 = rhs(t + 0.5 * h, &k3);
            let k4: [f64; 9] = core::array::from_fn(|i| y[i] + h * k3[i]);
            let k4 = rhs(t + h, &k4);
            for i in 0..9 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            t += h;
        }
        let [q, u, s] = state_at(&sc, &f, t);
        for i in 0..3 {
            close(q[i], y[i], 1e-9, "position");
            close(u[i], y[3 + i], 1e-9, "velocity");
            close(s[i], y[6 + i], 1e-9, "spin");
        }
        // And the launch state comes back at the start.
        let [q, u, s] = state_at(&sc, &f, t0);
        for i in 0..3 {
            close(q[i], q0[i], 1e-14, "start position");
            close(u[i], u0[i], 1e-14, "start velocity");
            close(s[i], s0[i], 1e-14, "start spin");
        }
    }
}

/// The ballistic arc in a still bowl tilted by `th`: thrown from the bottom at `(vx, 0, vz)`
/// in the bowl frame, it lands after `2 vz / (g cos th)` at `x = vx t - g sin th t^2 / 2` (the
/// tilt's in-plane gravity along -x at psi = 0); thrown outwards faster it passes the rim
/// where `x(t) = R` first. Both located to 1e-9 of their closed forms.
#[test]
fn the_ballistic_arc_lands_and_leaves_where_its_closed_form_says() {
    for th in [0.0, 20.0, 35.0] {
        let sc = scene(0.0, 0.0, th, 0.0);
        let (g, a, rim) = (sc.g_m_s2, sc.particle_radius_m, sc.rim_radius_m);
        let (st, ct) = (th.to_radians().sin(), th.to_radians().cos());
        let (vx, vz) = (0.1, 0.6);
        let f = launch(&sc, 0.2, [-0.05, 0.0, a], [vx, 0.0, vz], [0.0; 3]);
        let FlightEnd::Lands(l) = fly(&sc, None, &f, 10.0) else {
            panic!("{th}: no landing")
        };
        let t = 2.0 * vz / (g * ct);
        close(l.t_s - 0.2, t, 1e-9, "landing time");
        close(
            l.q_m[0],
            -0.05 + vx * t - 0.5 * g * st * t * t,
            1e-9,
            "landing x",
        );
        close(l.q_m[2], a, 1e-12, "landing height");
        close(l.u_m_s[2], -vz, 1e-9, "landing normal speed");
        assert_eq!(l.surface, Surface::Bottom);
        // Outwards: x(t) = R at the smaller root of -g st t^2/2 + vx t + x0 - R = 0.
        let vx = 2.0;
        let f = launch(&sc, 0.0, [0.0, 0.0, a], [vx, 0.0, vz], [0.0; 3]);
        let FlightEnd::Exits(te, _) = fly(&sc, None, &f, 10.0) else {
            panic!("{th}: no exit")
        };
        let want = if st == 0.0 {
            rim / vx
        } else {
            let aa = 0.5 * g * st;
            (vx - (vx * vx - 4.0 * aa * rim).sqrt()) / (2.0 * aa)
        };
        close(te, want, 1e-9, "exit time");
    }
}

/// The impact on a level bottom, `u = (vx, 0, -vz)`, no spin, `k2 = 5/7`: the normal velocity
/// comes back as `e vz`; with enough friction the slip stops (`u_x = k2 vx`, rolling after),
/// otherwise the friction's impulse is `mu_s (1 + e) vz` (`u_x = vx - mu_s (1 + e) vz`), and the
/// spin takes `(k2 / (1 - k2))` of it. On a wall's normal the same, turned.
#[test]
fn an_impact_reverses_the_normal_velocity_times_e() {
    let base = scene(0.0, 0.0, 0.0, 0.0);
    let k2 = base.k2;
    let (vx, vz) = (0.4, 0.3);
    for (e, mu) in [(0.5, 1.0), (0.5, 0.05), (0.0, 0.2), (1.0, 0.3)] {
        let sc = RollingScene {
            sliding_friction: mu,
            ..base
        };
        let (u, s, rebound) = impact(&sc, e, [vx, 0.0, -vz], [0.0; 3], [0.0, 0.0, 1.0]);
        close(rebound, e * vz, 1e-15, "rebound");
        close(u[2], e * vz, 1e-15, "normal velocity");
        let jt = (mu * (1.0 + e) * vz).min((1.0 - k2) * vx);
        close(u[0], vx - jt, 1e-15, "tangential velocity");
        close(u[1], 0.0, 1e-15, "sideways");
        // ds = -(k2/(1-k2)) n x J_t, J_t = (-jt, 0, 0): n x J_t = (0, -jt, 0).
        close(s[1], k2 / (1.0 - k2) * jt, 1e-15, "spin");
        if mu * (1.0 + e) * vz >= (1.0 - k2) * vx {
            // Rolling after: the contact point's slip u - s x n is zero.
            close(u[0] - s[1], 0.0, 1e-15, "slip");
            close(u[0], k2 * vx, 1e-15, "rolls at k2 vx");
        }
        // The same on a wall whose normal is turned by 60 deg about y.
        let (c, sn) = (60f64.to_radians().cos(), 60f64.to_radians().sin());
        let turn = |v: [f64; 3]| [c * v[0] + sn * v[2], v[1], -sn * v[0] + c * v[2]];
        let (u2, s2, r2) = impact(
            &sc,
            e,
            turn([vx, 0.0, -vz]),
            [0.0; 3],
            turn([0.0, 0.0, 1.0]),
        );
        close(r2, rebound, 1e-14, "turned rebound");
        for i in 0..3 {
            close(u2[i], turn(u)[i], 1e-14, "turned velocity");
            close(s2[i], turn(s)[i], 1e-14, "turned spin");
        }
    }
}

/// Issue 30's lift-off: on a rod offset 0.3 m at 4.4 rad/s of precession (60 deg, 75 mm bottom,
/// a 20 mm wall flared at 60 deg) the normal force reaches zero, which used to end the model
/// with no answer. Now every release leaves, some fly from the release, and one at least lifts
/// off after rolling or sliding and lands again (an impact) before it leaves.
#[test]
fn a_lift_off_scene_now_answers_with_a_fly_share() {
    let sc = RollingScene {
        rolling_resistance: 0.029,
        sliding_friction: 0.4,
        ..scene(4.4, 2.0, 60.0, 0.3)
    };
    let sc = RollingScene {
        rim_radius_m: 0.075,
        ri_m: 0.0375,
        ..sc
    };
    let shape = BowlShape {
        wall_angle_rad: 60f64.to_radians(),
        wall_height_m: 0.02,
        fillet_radius_m: 0.005,
        restitution: 0.5,
    };
    let lim = SystemLimits {
        horizon_s: 3.0,
        max_steps: 2_000_000,
    };
    let (mut flew, mut landed_between) = (0, 0);
    for deg in crate::particle::rolling::AZIMUTHS_DEG {
        let r = residence(
            &sc,
            &shape,
            deg.to_radians(),
            RollingMethod::Dp54 { rtol: 1e-9 },
            lim,
        )
        .unwrap();
        let BowlOutcome::Leaves {
            residence_time_s, ..
        } = r.outcome
        else {
            panic!("{deg}: {r:?}")
        };
        let total = r.regime.roll_s + r.regime.slide_s + r.flight_s;
        assert!((total - residence_time_s).abs() < 1e-9, "{deg}: {r:?}");
        if r.flight_s > 0.0 {
            flew += 1;
            if r.landings > 0 && r.regime.roll_s + r.regime.slide_s > 0.0 {
                landed_between += 1;
            }
        }
    }
    assert!(flew >= 3, "{flew}");
    assert!(landed_between >= 1, "{landed_between}");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]
    /// Any finite scene, with rod offsets and precessions that make it fly: an answer or an
    /// error, never a panic, every time finite and within the horizon.
    #[test]
    fn any_finite_bowl_with_flights_gives_an_answer_or_an_error(
        w1 in -8.0f64..8.0, w2 in -8.0f64..8.0, th in -0.1f64..1.6, l in -0.01f64..1.0,
        mu_s in -0.01f64..1.0, alpha in 0.2f64..1.8, h in -0.01f64..0.05, f in -0.01f64..0.03,
        e in -0.1f64..1.1, beta in -7.0f64..7.0,
    ) {
        let sc = RollingScene {
            precession_rad_s: w1, spin_rad_s: w2, axes_angle_rad: th, rod_length_m: l,
            sliding_friction: mu_s, rolling_resistance: 0.029, ri_m: 0.03, rim_radius_m: 0.075,
            ..scene(1.0, 1.0, 30.0, 0.0)
        };
        let sh = BowlShape { wall_angle_rad: alpha, wall_height_m: h, fillet_radius_m: f, restitution: e };
        let lim = SystemLimits { horizon_s: 0.5, max_steps: 20_000 };
        if let Ok(r) = residence(&sc, &sh, beta, RollingMethod::Dp54 { rtol: 1e-6 }, lim) {
            let ok = |v: f64| v.is_finite() && (0.0..=0.5 + 1e-9).contains(&v);
            proptest::prop_assert!(ok(r.regime.roll_s) && ok(r.regime.slide_s) && ok(r.flight_s), "{r:?}");
            if let BowlOutcome::Leaves { residence_time_s, exit_speed_m_s } = r.outcome {
                proptest::prop_assert!(ok(residence_time_s) && exit_speed_m_s.is_finite());
            }
        }
    }
}

/// The answer converges with the integrator's tolerance through flights, landings and the
/// lip's edge: on the lift-off scene every release's T at rtol 1e-8 is within 1e-6 of rtol
/// 1e-12's (an edge taken as a jump of the normal force, not as the arc length reaching it,
/// once made a release exit at the lip at one tolerance and fly off the edge at another: 5 ms).
#[test]
fn the_answer_converges_with_the_tolerance_through_flights() {
    let sc = RollingScene {
        rolling_resistance: 0.029,
        sliding_friction: 0.4,
        rim_radius_m: 0.075,
        ri_m: 0.0375,
        ..scene(4.4, 2.0, 60.0, 0.3)
    };
    let shape = BowlShape {
        wall_angle_rad: 60f64.to_radians(),
        wall_height_m: 0.02,
        fillet_radius_m: 0.005,
        restitution: 0.5,
    };
    let lim = SystemLimits {
        horizon_s: 3.0,
        max_steps: 2_000_000,
    };
    let t = |deg: f64, rtol: f64| {
        let r = residence(
            &sc,
            &shape,
            deg.to_radians(),
            RollingMethod::Dp54 { rtol },
            lim,
        )
        .unwrap();
        match r.outcome {
            BowlOutcome::Leaves {
                residence_time_s, ..
            } => residence_time_s,
            other => panic!("{deg}: {other:?}"),
        }
    };
    for deg in crate::particle::rolling::AZIMUTHS_DEG {
        let (coarse, fine) = (t(deg, 1e-8), t(deg, 1e-12));
        assert!(
            (coarse - fine).abs() < 1e-6 * fine,
            "{deg}: {coarse} vs {fine}"
        );
    }
}

/// A sphere's oblique impact with Coulomb friction and incoming spin, in closed form (Routh;
/// Stronge, Impact Mechanics, ch. 5: for a sphere the slip keeps its direction through the
/// impact). With `v_n = u . n < 0` and the contact point's slip `c = (u - s x n)_t`: a sticking
/// impact when `(1 - k2) |c| <= mu (1 + e) |v_n|`, after which it rolls with
/// `u_t' = k2 u_t + (1 - k2) (s x n)_t`; else sliding, `u_t' = u_t - mu (1 + e) |v_n| c / |c|`.
/// Either way `u_n' = -e v_n` and the angular momentum about the contact point,
/// `((1 - k2)/k2) s + n x u` per `m a`, is kept (the impulse passes through that point), and no
/// energy is made. Oblique normals, spins with and against the motion, slip not along `u`.
#[test]
fn an_oblique_impact_with_spin_matches_rouths_closed_form() {
    let base = scene(0.0, 0.0, 0.0, 0.0);
    let k2 = base.k2;
    let unit = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / l, v[1] / l, v[2] / l]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (mut sticking, mut sliding) = (0, 0);
    for n in [
        [0.0, 0.0, 1.0],
        unit([-0.866, 0.0, 0.5]),
        unit([0.3, -0.5, 0.8]),
    ] {
        for (u, s) in [
            ([0.4, 0.1, -0.6], [0.0, 0.0, 0.0]),
            ([0.4, 0.1, -0.6], [0.2, 0.5, -0.1]),
            ([1.5, -0.7, -0.3], [-0.3, 0.9, 0.2]),
            ([0.05, 0.02, -0.9], [1.2, -0.4, 0.0]),
        ] {
            // Make the normal component of u inbound on this normal.
            let un = dot(u, n);
            let u: [f64; 3] = core::array::from_fn(|i| u[i] - (un + 0.5) * n[i]);
            for (e, mu) in [(0.0, 0.4), (0.15, 0.4), (0.5, 0.1), (1.0, 0.05), (0.3, 2.0)] {
                let sc = RollingScene {
                    sliding_friction: mu,
                    ..base
                };
                let (u2, s2, rebound) = impact(&sc, e, u, s, n);
                let vn = dot(u, n);
                close(rebound, -e * vn, 1e-14, "rebound");
                close(dot(u2, n), -e * vn, 1e-14, "normal velocity");
                let sxn = cross(&s, &n);
                let tang = |v: [f64; 3]| -> [f64; 3] {
                    let vn = dot(v, n);
                    core::array::from_fn(|i| v[i] - vn * n[i])
                };
                let c = tang(core::array::from_fn(|i| u[i] - sxn[i]));
                let cl = dot(c, c).sqrt();
                let jn = (1.0 + e) * -vn;
                let (ut, sxn_t) = (tang(u), tang(sxn));
                let want: [f64; 3] = if (1.0 - k2) * cl <= mu * jn {
                    sticking += 1;
                    // Rolls after: no slip.
                    let slip2 = tang(core::array::from_fn(|i| u2[i] - cross(&s2, &n)[i]));
                    close(dot(slip2, slip2).sqrt(), 0.0, 1e-14, "slip after sticking");
                    core::array::from_fn(|i| k2 * ut[i] + (1.0 - k2) * sxn_t[i])
                } else {
                    sliding += 1;
                    core::array::from_fn(|i| ut[i] - mu * jn * c[i] / cl)
                };
                let u2t = tang(u2);
                for i in 0..3 {
                    close(u2t[i], want[i], 1e-14, "tangential velocity");
                }
                // Angular momentum about the contact point, per m a.
                let l = |u: [f64; 3], s: [f64; 3]| -> [f64; 3] {
                    let nu = cross(&n, &u);
                    core::array::from_fn(|i| (1.0 - k2) / k2 * s[i] + nu[i])
                };
                let (l0, l1) = (l(u, s), l(u2, s2));
                for i in 0..3 {
                    close(
                        l1[i],
                        l0[i],
                        1e-14,
                        "angular momentum about the contact point",
                    );
                }
                // Kinetic energy per m: |u|^2/2 + ((1 - k2)/(2 k2)) |s|^2, not increased.
                let ke =
                    |u: [f64; 3], s: [f64; 3]| 0.5 * dot(u, u) + 0.5 * (1.0 - k2) / k2 * dot(s, s);
                assert!(ke(u2, s2) <= ke(u, s) * (1.0 + 1e-14), "energy made");
            }
        }
    }
    assert!(
        sticking >= 10 && sliding >= 10,
        "{sticking} sticking, {sliding} sliding"
    );
}
