//! `bowl serve` and `bowl sim` split: a transport must be named, and the reports no longer take
//! the transport's flags.

mod common;

use common::bowl;

#[test]
fn serve_without_a_transport_says_which_to_pick() {
    let out = bowl(&["serve"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--pty") && err.contains("--capture FILE --seconds S"),
        "{err}"
    );
    let out = bowl(&["serve", "--pty", "--line-noise-percent", "120"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--line-noise-percent must be between 0 and 100 (got 120)"),
        "{err}"
    );
}

#[test]
fn sim_is_reports_only() {
    for args in [&["sim"][..], &["sim", "--pty"]] {
        let out = bowl(args);
        assert!(!out.status.success(), "{args:?}");
    }
    let help = String::from_utf8_lossy(&bowl(&["sim", "--help"]).stdout).into_owned();
    for report in [
        "step",
        "family",
        "commission",
        "sweep",
        "stability",
        "trace",
    ] {
        assert!(help.contains(report), "{help}");
    }
    assert!(!help.contains("--pty"), "{help}");
}
