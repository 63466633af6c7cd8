//! `bowl chart log --csv run.csv --out run.svg`: a logged run (the monitor's `--log`, the demo's
//! telemetry CSV or `bowl replay --csv`) drawn as set and measured speed per axis, with the link
//! events and fault changes marked. Writes `run-precession.svg/png` and `run-spin.svg/png`.
//!
//! Time axis: the PC's wall clock from the first row where the log has it (so device restarts
//! and link gaps sit where they happened), otherwise device time. The speed lines break at each
//! link event, so no line is drawn across a gap the rig's data does not cover.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use model_core::wire::FaultCode;

use super::plot::{Figure, Mark, Scale, Series, VLine};

/// Palette indices (the demo's charts use the same).
const SET_COLOUR: usize = 6;
const MEASURED_COLOUR: usize = 0;
/// Faults and a lost link.
pub const FAULT_COLOUR: usize = 8;
const EVENT_COLOUR: usize = 7;

/// One row of the log: a telemetry frame, or a link event.
enum Row {
    Telemetry {
        t_s: f64,
        set: [f64; 2],
        measured: [f64; 2],
        fault: String,
    },
    Event {
        t_s: f64,
        what: String,
    },
}

/// Seconds since the first row, from an ISO 8601 UTC time `YYYY-MM-DDTHH:MM:SS.mmmZ` (days
/// counted from the civil date, so a run across midnight or a month end stays in order).
fn iso_seconds(s: &str) -> Option<f64> {
    let (date, time) = s.strip_suffix('Z')?.split_once('T')?;
    let mut d = date.split('-').map(|p| p.parse::<i64>().ok());
    let (y, m, day) = (d.next()??, d.next()??, d.next()??);
    let mut t = time.split(':');
    let (hh, mm) = (
        t.next()?.parse::<f64>().ok()?,
        t.next()?.parse::<f64>().ok()?,
    );
    let ss = t.next()?.parse::<f64>().ok()?;
    // Days from civil (H. Hinnant), the inverse of telemetry_csv::utc.
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (m + if m > 2 { -3 } else { 9 }) + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some(days as f64 * 86_400.0 + hh * 3_600.0 + mm * 60.0 + ss)
}

/// The rows, and whether their times are the PC's clock.
fn read(path: &Path) -> Result<(Vec<Row>, bool)> {
    let mut log = rig_client::telemetry_csv::LogReader::open(path)?;
    let col = |name: &str| log.column(name);
    let time = col("device_time_ms")?;
    let fault = col("fault")?;
    let speeds = [
        [col("prec_set_mrad_s")?, col("prec_measured_mrad_s")?],
        [col("spin_set_mrad_s")?, col("spin_measured_mrad_s")?],
    ];
    let host = log.optional("host_time_utc");
    let event = log.optional("event");
    let mut first_host: Option<f64> = None;
    let mut rows = Vec::new();
    let names = log.names();
    for (i, record) in log.reader.records().enumerate() {
        let line = i + 2;
        let r = record.with_context(|| format!("{}: line {line}", path.display()))?;
        let cell = |k: usize| r.get(k).unwrap_or("").trim();
        let host_s = host.and_then(|k| iso_seconds(cell(k)));
        let t_s = match host_s {
            Some(h) => h - *first_host.get_or_insert(h),
            None => match cell(time).parse::<f64>() {
                Ok(ms) => ms / 1000.0,
                Err(_) if event.is_some_and(|k| !cell(k).is_empty()) => continue,
                Err(_) => bail!(
                    "{}: line {line}: device_time_ms = {:?} is not a number",
                    path.display(),
                    cell(time)
                ),
            },
        };
        if let Some(what) = event.map(cell).filter(|e| !e.is_empty()) {
            rows.push(Row::Event {
                t_s,
                what: what.to_string(),
            });
            continue;
        }
        let num = |k: usize| -> Result<f64> {
            cell(k).parse::<f64>().map(|v| v / 1000.0).map_err(|_| {
                anyhow!(
                    "{}: line {line}: {} = {:?} is not a number",
                    path.display(),
                    names.get(k).map_or("?", String::as_str),
                    cell(k)
                )
            })
        };
        rows.push(Row::Telemetry {
            t_s,
            set: [num(speeds[0][0])?, num(speeds[1][0])?],
            measured: [num(speeds[0][1])?, num(speeds[1][1])?],
            fault: cell(fault).to_string(),
        });
    }
    if !rows.iter().any(|r| matches!(r, Row::Telemetry { .. })) {
        bail!("{}: no telemetry rows to draw", path.display());
    }
    Ok((rows, first_host.is_some()))
}

fn figure(rows: &[Row], axis: usize, file: &str, wall_clock: bool) -> Figure {
    let (name, symbol) = [("precession", "w1"), ("spin", "w2")][axis];
    let (mut set, mut measured, mut vlines) = (Vec::new(), Vec::new(), Vec::new());
    // The CSV's fault word (`none`, `no-pulses-spin`, ...); logs written before the words
    // spelled them `None`, `SensorLostOrStallSpin`: a change is a change either way.
    let mut last_fault = "none".to_string();
    for row in rows {
        match row {
            Row::Telemetry {
                t_s,
                set: s,
                measured: m,
                fault,
            } => {
                set.push((*t_s, s[axis]));
                measured.push((*t_s, m[axis]));
                if !fault.eq_ignore_ascii_case(&last_fault) {
                    vlines.push(VLine {
                        x: *t_s,
                        label: match FaultCode::from_token(fault) {
                            _ if fault.eq_ignore_ascii_case("none") => "fault cleared".into(),
                            Some(code) => format!("fault: {}", code.words()),
                            None => format!("fault: {fault}"),
                        },
                        color: FAULT_COLOUR,
                    });
                    last_fault = fault.clone();
                }
            }
            Row::Event { t_s, what } => {
                // A link event breaks both lines: nothing is known across it. A gate event
                // (`... gate at ...`) is only marked: telemetry goes on through it.
                if !what.contains(" gate at ") {
                    set.push((*t_s, f64::NAN));
                    measured.push((*t_s, f64::NAN));
                }
                vlines.push(VLine {
                    x: *t_s,
                    label: what.clone(),
                    color: if what == "link lost" || what == "no telemetry" {
                        FAULT_COLOUR
                    } else {
                        EVENT_COLOUR
                    },
                });
            }
        }
    }
    let x_label = if wall_clock {
        "time since the log's first row (PC clock), s"
    } else {
        "device time, s"
    };
    let mut fig = speed_figure(
        format!("{file}: {name} motor {symbol}, set vs measured"),
        x_label,
        symbol,
        [set, measured],
        vec![
            "Vertical lines: link events (red: link".into(),
            "lost), gate events and fault changes;".into(),
            "the speed lines break at each link event.".into(),
        ],
    );
    fig.vlines = vlines;
    fig
}

/// One axis's set and measured speed, rad/s, against time (`bowl chart log` and the demo's
/// charts): `[set, measured]` points, no marker lines yet.
pub fn speed_figure(
    title: String,
    x_label: &str,
    symbol: &str,
    [set, measured]: [Vec<(f64, f64)>; 2],
    notes: Vec<String>,
) -> Figure {
    Figure {
        title,
        x_label: x_label.into(),
        y_label: format!("{symbol}, rad/s"),
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
        series: vec![
            Series {
                name: format!("{symbol} set"),
                points: set,
                mark: Mark::Dashed,
                color: SET_COLOUR,
            },
            Series {
                name: format!("{symbol} measured"),
                points: measured,
                mark: Mark::Line,
                color: MEASURED_COLOUR,
            },
        ],
        hlines: Vec::new(),
        vlines: Vec::new(),
        notes,
    }
}

/// Draws `csv` into `out`-precession.svg/png and `out`-spin.svg/png; returns the files.
pub fn draw(csv: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let (rows, wall_clock) = read(csv)?;
    let file = csv
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut written = Vec::new();
    for (axis, suffix) in [(0, "precession"), (1, "spin")] {
        let fig = figure(&rows, axis, &file, wall_clock);
        let svg = super::suffixed(out, suffix);
        let png = svg.with_extension("png");
        fig.write_svg(&svg)?;
        fig.write_png(&png)?;
        written.extend([svg, png]);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iso_seconds_inverts_the_log_format() {
        use std::time::{Duration, SystemTime};
        for (s, ms) in [(0u64, 0u64), (951_782_400, 5), (1_764_038_666, 123)] {
            let t = SystemTime::UNIX_EPOCH + Duration::from_millis(s * 1000 + ms);
            let text = rig_client::telemetry_csv::utc(t);
            let back = iso_seconds(&text).unwrap();
            assert!(
                (back - (s as f64 + ms as f64 / 1000.0)).abs() < 1e-6,
                "{text}"
            );
        }
    }
}
