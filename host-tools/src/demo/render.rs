//! The demo's summary as text, for people.

use super::report::Summary;

fn opt(v: Option<f64>, unit: &str) -> String {
    v.map_or("-".into(), |v| format!("{v:.3} {unit}"))
}

/// The summary for people.
pub fn text(s: &Summary) -> String {
    let mut o = String::new();
    o += &format!(
        "\n== demo summary ({} rig, {:.1} s device time, {:.1} s wall) ==\n",
        s.rig, s.device_s, s.wall_s
    );
    o += &format!(
        "frames ok {}  corrupt {}  missing {}  (telemetry rows {})\n",
        s.frames["frames_ok"],
        s.frames["frames_corrupt"],
        s.frames["frames_missing"],
        s.telemetry_rows
    );
    for st in &s.steps {
        o += &format!(
            "step '{}' at t={:.3} s{}\n",
            st.name,
            st.at_s,
            if st.accepted { "" } else { " (REJECTED)" }
        );
        for a in &st.axes {
            o += &format!(
                "  {:<10} {:.3} -> {:.3} rad/s  rise {}{}  settle(+/-{:.0}%) {}  overshoot {:.1}%  steady err {:.2}%  ripple {:.2}%  {}\n",
                a.axis,
                a.from_rad_s,
                a.set_rad_s,
                opt(a.rise_time_s, "s"),
                a.first_reading_s.map_or(String::new(), |f| format!(
                    " (first reading after {f:.3} s)"
                )),
                s.tolerances.settle_band * 100.0,
                opt(a.settling_time_s, "s"),
                a.overshoot_pct,
                a.steady_error_pct,
                a.steady_ripple_pct,
                if a.tracked { "ok" } else { "NOT TRACKED" }
            );
        }
        if let Some(p) = &st.predicted {
            o += &format!(
                "  bowl {:.3} rad/s: residence flat {} (host {}), Coriolis {} (host {})\n",
                p.bowl_rad_s,
                opt(p.flat_ms, "ms"),
                opt(p.host_flat_ms, "ms"),
                opt(p.coriolis_ms, "ms"),
                opt(p.host_coriolis_ms, "ms")
            );
        }
    }
    if let Some(r) = &s.residence {
        o += &format!(
            "residence target {} ms (Coriolis): host inverse bowl {} -> split {} ; rig set [{:.3}, {:.3}] rad/s ; flat model at that speed {} ; {}\n",
            r.target_ms,
            opt(r.host_bowl_rad_s, "rad/s"),
            r.host_split_rad_s
                .map_or("-".into(), |v| format!("[{:.3}, {:.3}] rad/s", v[0], v[1])),
            r.rig_set_rad_s[0],
            r.rig_set_rad_s[1],
            opt(r.host_flat_at_target_ms, "ms"),
            if r.split_agrees {
                "agree"
            } else {
                "DO NOT AGREE"
            }
        );
    }
    if let Some(f) = &s.fault {
        o += &format!(
            "fault at t={:.3} s: {} detected after {} (expected {}), both duties 0 after {}, stayed off {}, precession {:.3} -> {:.3} rad/s (stopped after {})\n",
            f.injected_at_s,
            f.fault_text.as_deref().unwrap_or("no fault"),
            opt(f.detection_s, "s"),
            f.expected_detection_s
                .map_or("-".into(), |[a, b]| format!("{a:.3}..{b:.3} s")),
            opt(f.motors_off_s, "s"),
            f.stayed_off,
            f.precession_before_rad_s,
            f.precession_at_clear_rad_s,
            opt(f.precession_stopped_s, "s"),
        );
    }
    o += &format!(
        "checks: speeds tracked {}, fault stopped both motors {}, residence split agrees {}, link clean {}, ended at rest {}\n",
        s.checks.speeds_tracked,
        s.checks.fault_stopped_both_motors,
        s.checks.residence_split_agrees,
        s.checks.link_clean,
        s.ended_at_rest
    );
    o
}
