//! Fitting the monitor's screen into a small terminal (40 x 12, a split tmux pane): what says
//! the rig's state and takes commands is never the part that is cut, and no number is shown
//! with its first digits clipped off.

/// Rows of each part of the screen, top to bottom: banner, fault, charts, values, counters,
/// events (with their title row), command line.
pub type Rows = [u16; 7];

/// The charts' share below which they give their rows to the events (a chart of 8 rows still
/// shows a trend; the events' newest line comes first).
const CHART_ROWS: usize = 8;

/// Shares out `height` rows. The banner (link, state), the fault line and the command line
/// come first, whole; then the values, the counters, the newest event, the charts' first
/// [`CHART_ROWS`], the older events, and the charts take the rest. Each `*_rows` is what that
/// part needs (`events_rows` counts the title row).
pub fn rows(
    height: u16,
    banner_rows: usize,
    fault_rows: usize,
    values_rows: usize,
    counters_rows: usize,
    events_rows: usize,
) -> Rows {
    let mut left = usize::from(height);
    let mut take = |want: usize| {
        let got = want.min(left);
        left -= got;
        got
    };
    let banner = take(banner_rows);
    let fault = take(fault_rows);
    let prompt = take(1);
    let values = take(values_rows);
    let counters = take(counters_rows);
    let newest_event = take(events_rows.min(2));
    let charts = take(CHART_ROWS);
    let events = newest_event + take(events_rows - newest_event);
    let charts = charts + take(usize::MAX);
    let n = |v: usize| u16::try_from(v).unwrap_or(u16::MAX);
    [
        n(banner),
        n(fault),
        n(charts),
        n(values),
        n(counters),
        n(events),
        n(prompt),
    ]
}

/// The narrowest terminal the screen is drawn in: the values' sentences and the banner wrap
/// into a few rows at 40 columns, and below it they would take most of the screen.
pub const MIN_WIDTH: u16 = 40;

/// What to show instead of the screen in a terminal `width` x `height` that cannot hold the
/// banner, fault line, values and command line (`needed_rows` of them, wrapped at the width
/// drawn, at least [`MIN_WIDTH`]): the size it has and the size it needs, in words, in lines of
/// at most `width` and no more than `height` of them (the shortest form when nothing longer
/// fits). `None` when the screen fits.
pub fn too_small(width: u16, height: u16, needed_rows: usize) -> Option<Vec<String>> {
    let needed = u16::try_from(needed_rows).unwrap_or(u16::MAX);
    if width >= MIN_WIDTH && height >= needed {
        return None;
    }
    let (w, h) = (width.max(MIN_WIDTH), height.max(needed));
    let forms = [
        format!(
            "The terminal is {width} x {height}: too small for bowl monitor, which needs at \
             least {w} x {h} here. Make the window larger (the screen comes back), or quit with \
             q and run bowl monitor --plain."
        ),
        format!("Terminal {width} x {height}: too small, bowl monitor needs {w} x {h}. q quits."),
        format!("needs {w}x{h}"),
    ];
    let columns = usize::from(width).max(1);
    let fits = |lines: &Vec<String>| lines.len() <= usize::from(height);
    let mut lines = forms
        .iter()
        .map(|f| super::wrap::wrap(f, columns))
        .find(fits)
        .unwrap_or_else(|| super::wrap::wrap(&forms[2], columns));
    lines.truncate(usize::from(height));
    Some(lines)
}

/// The time axis' labels for a chart `plot_width` columns wide (inside its frame and y labels),
/// from `start` to `end` s: three when each fits in its third of the width (ratatui right-aligns
/// the last in its share and cuts it from the left, so `300 s` would read `00 s`), else the two
/// ends, else the two ends without the unit.
pub fn time_labels(start: f64, end: f64, plot_width: u16) -> Vec<String> {
    let first = format!("{start:.0}");
    let middle = format!("{:.0}", (start + end) / 2.0);
    let last = format!("{end:.0} s");
    let fits = |share: usize, labels: &[&String]| {
        // A middle label gets its share less the one column left before it.
        labels.iter().all(|l| l.chars().count() < share)
    };
    let width = usize::from(plot_width);
    if fits(width / 3, &[&first, &middle, &last]) {
        vec![first, middle, last]
    } else if fits(width / 2 + 1, &[&first, &last]) {
        vec![first, last]
    } else {
        vec![first, format!("{end:.0}")]
    }
}

#[cfg(test)]
mod tests {
    use super::{rows, time_labels, too_small};

    #[test]
    fn a_terminal_too_small_says_the_size_it_needs() {
        assert_eq!(too_small(40, 12, 11), None);
        assert_eq!(too_small(250, 70, 11), None);
        let lines = too_small(20, 5, 11).unwrap();
        assert!(lines.len() <= 5 && lines.iter().all(|l| l.chars().count() <= 20));
        let text = lines.join(" ");
        assert!(
            text.contains("20 x 5") && text.contains("needs 40 x 11"),
            "{text}"
        );
        let text = too_small(80, 8, 11).unwrap().join(" ");
        assert!(text.contains("needs at least 80 x 11 here"), "{text}");
        assert!(text.contains("--plain"), "{text}");
        // Tiny: the size needed is still said, within the screen.
        assert_eq!(too_small(9, 1, 11).unwrap(), ["needs"]);
        assert_eq!(too_small(9, 2, 11).unwrap(), ["needs", "40x11"]);
        assert_eq!(too_small(0, 0, 11).unwrap(), Vec::<String>::new());
    }

    #[test]
    fn a_small_screen_keeps_the_banner_fault_and_command_line() {
        // 40 x 12: a banner over 2 rows, one fault row, 4 value rows, 2 counter rows, events 5.
        let r = rows(12, 2, 1, 4, 2, 5);
        assert_eq!(r.iter().map(|&v| usize::from(v)).sum::<usize>(), 12);
        assert_eq!((r[0], r[1], r[6]), (2, 1, 1), "{r:?}");
        assert_eq!((r[3], r[4]), (4, 2), "values and counters whole: {r:?}");
        assert_eq!(r[5], 2, "the newest event with its title: {r:?}");
        assert_eq!(r[2], 0, "no room for charts: {r:?}");
        // Fewer rows than the must-haves: still in order, nothing beyond the screen.
        let r = rows(3, 2, 1, 4, 1, 5);
        assert_eq!(r, [2, 1, 0, 0, 0, 0, 0]);
    }

    #[test]
    fn a_large_screen_gives_the_charts_the_rest() {
        // 120 x 36 as in docs/console.md: the parts as before, the charts 22 rows.
        let r = rows(36, 1, 1, 5, 1, 5);
        assert_eq!(r, [1, 1, 22, 5, 1, 5, 1]);
    }

    #[test]
    fn time_labels_are_never_clipped() {
        // ratatui gives each of n labels width / n columns, a middle one a column less.
        for width in 12..60u16 {
            for (start, end) in [(280.0, 300.0), (99_980.0, 100_000.0), (0.0, 20.0)] {
                let labels = time_labels(start, end, width);
                let share = usize::from(width) / labels.len();
                let len = |i: usize| labels[i].chars().count();
                assert!(len(labels.len() - 1) <= share, "{width}: {labels:?}");
                if labels.len() == 3 {
                    assert!(len(1) < share, "{width}: {labels:?}");
                }
                assert!(labels.last().unwrap().starts_with(&format!("{end:.0}")));
            }
        }
        assert_eq!(time_labels(280.0, 300.0, 40), ["280", "290", "300 s"]);
        assert_eq!(time_labels(280.0, 300.0, 13), ["280", "300 s"]);
    }
}
