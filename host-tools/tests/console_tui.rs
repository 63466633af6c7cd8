//! The monitor's terminal UI in a real terminal (tmux): what a person sees. Charts with labelled
//! axes and numbers, the values, a command typed into the UI and its answer, a fault banner, the
//! link-lost banner, and a quit key that gives the terminal back with the counters printed.

mod common;

use common::tmux::Tmux;
use common::{BOWL, Sim};

#[test]
fn a_person_sees_the_rig_commands_it_and_quits() {
    let sim = Sim::start(&[]);
    // `; sleep` keeps the pane after the monitor exits, so what it leaves behind can be read.
    let tmux = Tmux::start("tui", &format!("{BOWL} monitor {} ; sleep 30", sim.path));
    let screen = tmux.wait_for(
        &[
            "LINK OK",
            "precession w1",
            "spin w2",
            "precession w1 rad/s: set, measured",
            "spin w2 rad/s: set, measured",
            "20 s",
            "set rad/s",
            "measured rad/s",
            "state idle",
            "no fault",
        ],
        "the dashboard",
    );
    // The speed axis has numbers, and at rest spans at least 1 rad/s (noise does not fill it).
    assert!(screen.contains("1.10"), "a numbered speed axis:\n{screen}");

    // A command typed into the UI, and its answer.
    tmux.keys(&[":", "speed 1500 1500", "Enter"]);
    tmux.wait_for(&["speed 1500 1500 -> ok (id"], "the answer to speed");
    tmux.keys(&[":", "start", "Enter"]);
    tmux.wait_for(&["start -> ok (id", "state running"], "running");
    // The set speed 1.500 rad/s shows in the values of both axes.
    tmux.wait_for(&["1.500"], "the set speed");

    // A smaller window: the screen is drawn again to fit, axes and values still there.
    tmux.resize(90, 30);
    let small = tmux.wait_for(
        &["precession w1 rad/s: set, measured", "measured rad/s"],
        "after a resize",
    );
    assert!(
        small.lines().all(|l| l.chars().count() <= 90),
        "fits 90 columns:\n{small}"
    );

    // Pause.
    tmux.keys(&["p"]);
    tmux.wait_for(&["PAUSED"], "the pause key");
    tmux.keys(&["p"]);

    // A fault cannot be missed, and its line is wrapped, not cut, in 90 columns: its end says
    // what to do.
    tmux.keys(&[":", "inject sensor1", "Enter"]);
    let fault = tmux.wait_for(
        &["FAULT ", "the rig stopped the motors"],
        "the fault banner",
    );
    let flat: String = fault.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        flat.contains("Type `:clear` once the cause is fixed"),
        "the whole fault line:\n{fault}"
    );

    // The link dies: said so, and the values are no longer shown as current.
    drop(sim);
    tmux.wait_for(
        &["LINK LOST", "last values before the link was lost"],
        "link lost",
    );

    // q quits: the alternate screen is gone and the counters are printed.
    tmux.keys(&["q"]);
    let screen = tmux.wait_for(&["\"frames_ok\""], "the counters after quitting");
    assert!(
        !screen.contains("device time (s)"),
        "terminal restored:\n{screen}"
    );
}

/// Telemetry that stops while the port stays open (`SET TELEM_HZ 0`, typed with Tab completion):
/// the banner says "no telemetry for N s" instead of LINK OK, the values turn grey and say so,
/// the log gets a "no telemetry" row; when frames come again (the command brought back with
/// Up and edited) LINK OK returns and the log says after how long.
#[test]
fn telemetry_that_stops_is_said_and_marked_in_the_log() {
    let sim = Sim::start(&[]);
    let dir = common::temp_dir("tui-stale");
    let log = dir.join("run.csv");
    let tmux = Tmux::start(
        "tui-stale",
        &format!(
            "{BOWL} monitor {} --log {} ; sleep 30",
            sim.path,
            log.display()
        ),
    );
    tmux.wait_for(&["LINK OK", "state idle"], "the dashboard");
    // Tab completes the command and the parameter name.
    tmux.keys(&[":", "st"]);
    tmux.keys(&["Tab"]);
    tmux.wait_for(
        &["command> st_", "Tab: start status stop"],
        "the candidates for st",
    );
    tmux.keys(&["BSpace", "BSpace", "se", "Tab", "tel", "Tab"]);
    tmux.wait_for(&["command> set TELEM_HZ _"], "completed to set TELEM_HZ");
    tmux.keys(&["0", "Enter"]);
    let quiet = tmux.wait_for(
        &[
            "set TELEM_HZ 0 -> ok (id",
            "no telemetry for",
            "last values before the telemetry stopped",
            "fault: unknown (no current telemetry)",
        ],
        "the stale state",
    );
    assert!(
        !quiet.contains("LINK OK"),
        "LINK OK while nothing comes:\n{quiet}"
    );
    // Up brings the command back; edit it and send: telemetry comes again.
    tmux.keys(&[":", "Up"]);
    tmux.wait_for(&["command> set TELEM_HZ 0_"], "the history");
    tmux.keys(&["BSpace", "50", "Enter"]);
    tmux.wait_for(
        &["LINK OK", "telemetry again after", "no fault"],
        "telemetry back",
    );
    tmux.keys(&["q"]);
    tmux.wait_for(&["\"frames_ok\""], "the counters after quitting");
    let text = std::fs::read_to_string(&log).unwrap();
    let events: Vec<&str> = text
        .lines()
        .filter_map(|l| l.rsplit(',').next())
        .filter(|e| !e.is_empty() && *e != "event")
        .collect();
    let stop = events.iter().position(|e| *e == "no telemetry");
    let again = events
        .iter()
        .position(|e| e.starts_with("telemetry again after"));
    assert!(
        stop.is_some() && again > stop,
        "the gap is marked in the log: {events:?}"
    );
}

/// A small terminal (40 x 12, a split pane): the charts give way, never the banner (link and
/// state), the fault line, the values (as sentences, wrapped, not cut at the edge) or the
/// command line; a time label is never shown with its first digits cut off.
#[test]
fn a_small_terminal_keeps_the_state_values_and_command_line() {
    let sim = Sim::start(&[]);
    let tmux = Tmux::start(
        "tui-small",
        &format!("{BOWL} monitor {} ; sleep 30", sim.path),
    );
    tmux.resize(40, 12);
    let screen = tmux.wait_for(
        &[
            "LINK OK",
            "state idle",
            "no fault",
            "precession w1: set 0.000 measured",
            "spin w2: set 0.000 measured",
            ": command",
        ],
        "the state, values and command line in 40 x 12",
    );
    assert!(
        screen.lines().all(|l| l.chars().count() <= 40),
        "fits 40 columns:\n{screen}"
    );
    // Taller, still 40 wide: the charts come back, their time axis whole (`NNN s`, the
    // numbers the device time gives).
    tmux.resize(40, 30);
    let screen = tmux.wait_for(&["precession w1 rad", " s│"], "charts at 40 x 30");
    let device_s: f64 = screen
        .split("device time ")
        .nth(1)
        .and_then(|r| r.split(" s").next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("device time on:\n{screen}"));
    let axis = screen.lines().find(|l| l.ends_with(" s│")).unwrap();
    let last: f64 = axis
        .trim_end_matches(" s│")
        .rsplit(' ')
        .next()
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("a time label: {axis}"));
    assert!(
        (last - device_s).abs() <= 20.0,
        "the axis ends at {last} s, the device time is {device_s} s:\n{screen}"
    );
}

/// Starts `bowl monitor ARGS` in a terminal, closes the terminal once the dashboard shows
/// (SIGHUP: tmux killed, an ssh session dropped), and waits for the monitor to end: it must
/// not stay behind holding the port.
fn close_the_terminal_under(name: &str, args: &str) {
    let tmux = Tmux::start(name, &format!("{BOWL} monitor {args}"));
    tmux.wait_for(&["LINK OK"], "the dashboard");
    // The monitor itself, not the shell tmux may start it through.
    let out = std::process::Command::new("pgrep")
        .args(["-f", &format!("^{BOWL} monitor {args}$")])
        .output()
        .unwrap();
    let monitor: u32 = String::from_utf8_lossy(&out.stdout)
        .trim()
        .parse()
        .expect("one monitor pid");
    drop(tmux);
    let started = std::time::Instant::now();
    while std::path::Path::new(&format!("/proc/{monitor}")).exists() {
        if started.elapsed() > std::time::Duration::from_secs(5) {
            let _ = std::process::Command::new("kill")
                .args(["-9", &monitor.to_string()])
                .status();
            panic!("the monitor {monitor} still ran 5 s after its terminal closed");
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
}

#[test]
fn closing_the_terminal_ends_the_monitor() {
    let sim = Sim::start(&[]);
    close_the_terminal_under("tui-hangup", &sim.path);
}

/// The terminal closed under a logging monitor: its log is closed as on Ctrl-C, the last row
/// `monitor end` (before, the process died where it stood and the log just stopped).
#[test]
fn closing_the_terminal_closes_the_log() {
    let sim = Sim::start(&[]);
    let dir = common::temp_dir("tui-hangup-log");
    let log = dir.join("run.csv");
    close_the_terminal_under(
        "tui-hangup-log",
        &format!("{} --log {}", sim.path, log.display()),
    );
    common::assert_log_closed(&log);
}

/// The colour parameters of the SGR sequences in `screen` (tmux `capture-pane -e`).
fn colour_codes(screen: &str) -> Vec<String> {
    screen
        .split("\x1b[")
        .skip(1)
        .filter_map(|s| s.split_once('m').map(|(params, _)| params))
        .filter(|p| p.chars().all(|c| c.is_ascii_digit() || c == ';'))
        .flat_map(|p| p.split(';').map(str::to_string).collect::<Vec<_>>())
        .filter(|p| {
            p.parse::<u32>()
                .is_ok_and(|n| matches!(n, 30..=37 | 38 | 40..=47 | 48 | 90..=97 | 100..=107))
        })
        .collect()
}

/// A virtual rig and the monitor's dashboard on it in a terminal, the monitor run with the
/// environment `env` (`NAME=VALUE`), once it shows the rig idle.
fn dashboard_with(name: &str, env: &str) -> (Sim, Tmux) {
    let sim = Sim::start(&[]);
    let tmux = Tmux::start(
        name,
        &format!("env {env} {BOWL} monitor {} ; sleep 30", sim.path),
    );
    tmux.wait_for(&["LINK OK", "state idle"], "the dashboard");
    (sim, tmux)
}

/// NO_COLOR (no-color.org): no colour on the screen, the banner's marks in reverse video; and
/// TERM=dumb (an editor's shell buffer): the plain lines, not a screen of escape sequences.
#[test]
fn no_color_and_a_dumb_terminal_are_respected() {
    let (sim, tmux) = dashboard_with("tui-nocolor", "NO_COLOR=1");
    let out = tmux
        .cmd(&["capture-pane", "-e", "-p", "-t", "0"])
        .output()
        .unwrap();
    let screen = String::from_utf8_lossy(&out.stdout);
    assert_eq!(colour_codes(&screen), Vec::<String>::new(), "{screen}");
    assert!(
        screen.contains("\x1b[7m") || screen.contains(";7m"),
        "reverse: {screen}"
    );
    drop(tmux);

    let tmux = Tmux::start(
        "tui-dumb",
        &format!("env TERM=dumb {BOWL} monitor {} ; sleep 30", sim.path),
    );
    let screen = tmux.wait_for(&["state=idle", "corrupt 0"], "the plain lines");
    assert!(!screen.contains("LINK OK"), "no screen UI:\n{screen}");
}

/// A terminal whose locale has no UTF-8 (`LC_ALL=C`, as on a serial console or a bare ssh
/// session) shows braille and box-drawing as garbage: the dashboard is drawn in ASCII there,
/// frames, axes and both speed lines included, and still reads.
#[test]
fn a_terminal_without_utf8_gets_ascii() {
    let (_sim, tmux) = dashboard_with("tui-ascii", "LC_ALL=C");
    tmux.keys(&[":", "speed 1500 1500", "Enter"]);
    tmux.wait_for(&["speed 1500 1500 -> ok (id"], "the answer to speed");
    tmux.keys(&[":", "start", "Enter"]);
    let screen = tmux.wait_for(
        &[
            "state running",
            "precession w1 rad/s: set (.), measured (*)",
            "+-",
            "s|",
        ],
        "the dashboard in ASCII",
    );
    let odd: Vec<char> = screen.chars().filter(|c| !c.is_ascii()).collect();
    assert!(odd.is_empty(), "not ASCII: {odd:?} on\n{screen}");
    // Both lines are drawn: the set speed's dots and the measured speed's stars, in the left
    // chart's plot (`|1.65|  ....****  ||`: right of its speed axis).
    let plot: String = screen
        .lines()
        .filter(|l| l.starts_with('|'))
        .filter_map(|l| l.split('|').nth(2))
        .collect();
    assert!(
        plot.contains('.') && plot.contains('*'),
        "both speed lines:\n{screen}"
    );
}

/// Control chords in the command line: a newline (Ctrl-J, as a pasted line ends) sends the
/// command as Enter does, and other chords are not typed as their letter (before, Ctrl-U and
/// Ctrl-J made `statusuj`, and Ctrl-Q quit as `q` did).
#[test]
fn control_chords_are_not_typed_as_letters() {
    let (_sim, tmux) = dashboard_with("tui-chords", "BOWL_TEST=chords");
    tmux.keys(&["C-q", ":", "status", "C-u", "M-b"]);
    tmux.wait_for(&["command> status_"], "the line as typed");
    tmux.keys(&["C-j"]);
    tmux.wait_for(&["status -> status (id"], "sent by the newline");
}

/// Terminals of every size a lab has, and a port whose path is 200 characters long (a link in
/// a deep directory), resized while the monitor runs: every line fits the width; the banner
/// keeps the link and state on its first row (the path shortened with `…`, not wrapped over
/// the screen); a terminal too small for the screen says so and the size it needs (before,
/// 20 x 5 showed four rows of the path and 40 x 10 lost the values and the command line); a
/// command typed there still goes; grown back, the screen returns; a long command line shows
/// its end with the cursor, and the keys' hint is never cut mid-word.
#[test]
fn every_terminal_size_fits_or_says_the_size_it_needs() {
    let dir = common::temp_dir("tui-sizes");
    let deep = dir.join("lab-bench-".repeat(14));
    std::fs::create_dir_all(&deep).unwrap();
    let link = deep.join("rig_port_link");
    let link = link.to_str().unwrap();
    assert!(link.len() >= 160, "{}", link.len());
    let _sim = Sim::start(&["--link", link]);
    let tmux = Tmux::start("tui-sizes", &format!("{BOWL} monitor {link} ; sleep 30"));
    let fits = |screen: &str, columns: usize| {
        assert!(
            screen.lines().all(|l| l.chars().count() <= columns),
            "fits {columns} columns:\n{screen}"
        );
    };
    for (columns, rows) in [(80, 24), (100, 30), (60, 15), (40, 12), (250, 70)] {
        tmux.resize(columns, rows);
        // The next draws see the new size (SIGWINCH): the screen read is the new one.
        std::thread::sleep(std::time::Duration::from_millis(1500));
        let screen = tmux.wait_for(&["LINK OK", "no fault"], "the banner");
        fits(&screen, usize::from(columns));
        let first = screen.lines().next().unwrap_or("");
        assert!(
            first.contains("_link  LINK OK") && (first.contains('…') || columns > 200),
            "the path's end and the link on the first row, {columns} x {rows}:\n{screen}"
        );
        let hint = screen.lines().last().unwrap_or("");
        assert!(hint.ends_with("q quit"), "{columns} x {rows}:\n{screen}");
    }
    for (columns, rows) in [(40, 10), (20, 5)] {
        tmux.resize(columns, rows);
        let size = format!("{columns} x {rows}:");
        let screen = tmux.wait_for(&[&size, "small"], "the size needed");
        fits(&screen, usize::from(columns));
        let flat = screen.split_whitespace().collect::<Vec<_>>().join(" ");
        assert!(
            flat.contains("needs 40 x 11") || flat.contains("40 x 11 here"),
            "{screen}"
        );
    }
    // Typed while too small: the line is in sight and Enter sends it.
    tmux.keys(&[":", "status"]);
    tmux.wait_for(&["command> status_"], "the command line at 20 x 5");
    tmux.keys(&["Enter"]);
    tmux.resize(120, 40);
    tmux.wait_for(&["status -> status (id", "LINK OK"], "the screen again");
    // A command longer than the row: its end and the cursor show, the start gives way.
    tmux.resize(40, 12);
    tmux.keys(&[":", "speed 1800 2100 and then some more words"]);
    let screen = tmux.wait_for(&["command> …", "more words_"], "the long line's end");
    fits(&screen, 40);
}
