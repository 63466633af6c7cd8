use super::*;

fn hold(pulses_per_rev: u16, gain: f64, amplitude_pct: f64, mean_error_pct: f64) -> HoldPoint {
    HoldPoint {
        setup: LoopSetup {
            tick_hz: 1000,
            pulses_per_rev,
        },
        per_pulse_bandwidth: gain,
        scheduled: true,
        half_peak_to_peak_pct: amplitude_pct,
        mean_error_pct,
        fault: None,
    }
}

/// One pulse a revolution cannot measure 0.5 rad/s: the shaft never turns, its amplitude is 0
/// and its mean error 100 %. Its line was drawn along the floor as the quietest hold of all; now
/// it is left out and a note says why, while a setup that held keeps its line.
#[test]
fn a_setup_that_never_reached_the_speed_is_not_drawn_as_a_perfect_hold() {
    let points = [
        hold(1, 0.5, 0.0, 100.0),
        hold(1, 1.0, 0.0, 100.0),
        hold(12, 0.5, 0.002, 0.001),
        hold(12, 1.0, 0.3, 0.01),
    ];
    let (fig, table) = stability_chart(&points);
    let named = |n: &str| fig.series.iter().any(|s| s.name.starts_with(n));
    assert!(!named("N 1 "), "{:?}", fig.series);
    assert!(named("N 12 "), "{:?}", fig.series);
    let notes = fig.notes.join(" ");
    assert!(
        notes.contains("Not drawn: N 1, 1000 Hz never reached 0.5 rad/s"),
        "{notes}"
    );
    assert!(!notes.contains("N 12,"), "{notes}");
    // The CSV keeps every run.
    assert_eq!(table.rows.len(), 4);
}
