//! Scenarios as data (`tests/scenarios/*.toml`): commands at device times, and expectations on
//! the telemetry over time spans. This module reads a scenario, turns its commands into what
//! `bowl serve --command` takes, and checks a run's outcome against it: the telemetry as
//! `bowl replay --csv` writes it (the column names are the scenario's vocabulary) and the answer
//! each command got. Every failure is one sentence: scenario file, device time, expected, got.
//!
//! The file format, by example:
//!
//! ```toml
//! description = "what the scenario shows"
//! seconds = 25            # device seconds to run
//!
//! [[command]]
//! at_ms = 0
//! send = "speed 3000 3000"   # the words of `bowl send PORT ...`
//! answer = "done"            # default; or a rejection's wire token: "STATE", "RANGE", ...
//!
//! [[expect]]
//! what = "settled at 3 rad/s"   # said in a failure
//! from_ms = 4000                # held on every telemetry frame from ..= to (device time)
//! to_ms = 12000
//! state = ["running"]           # allowed states (the CSV's `state` words)
//! fault = "none"                # the CSV's `fault` word
//! telemetry_hz = [45, 55]       # frames per second over the span
//! [expect.window]               # any numeric CSV column: [lo, hi], inclusive
//! prec_measured_mrad_s = [2940, 3060]
//! ```
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use model_core::wire::{Decoder, DeviceState, FaultCode, Frame};
use serde::Deserialize;

/// One scenario file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// What it shows, for people.
    pub description: String,
    /// Device seconds to run.
    pub seconds: f64,
    /// Commands, at device times.
    #[serde(default, rename = "command")]
    pub commands: Vec<TimedCommand>,
    /// Expectations, each over a span of device time.
    #[serde(default, rename = "expect")]
    pub expects: Vec<Expect>,
}

/// A command the PC sends at a device time.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimedCommand {
    /// Device time to send it, ms.
    pub at_ms: u32,
    /// Its words, as typed after `bowl send PORT`.
    pub send: String,
    /// `done` (the default: acknowledged, or answered with data) or a rejection's wire token.
    #[serde(default = "done")]
    pub answer: String,
}

fn done() -> String {
    "done".to_string()
}

/// What must hold on every telemetry frame of a span.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// Said in a failure.
    pub what: String,
    /// Span start, device ms (inclusive).
    pub from_ms: u32,
    /// Span end, device ms (inclusive).
    pub to_ms: u32,
    /// The states allowed (`idle`, `commissioning`, `changing-speed`, `running`, `stopping`,
    /// `faulted`: the words `bowl send status` and the CSV use).
    #[serde(default)]
    pub state: Vec<String>,
    /// The fault (`none`, `no-pulses-spin`, ...: the CSV's and `bowl send status`'s words).
    pub fault: Option<String>,
    /// Telemetry frames per second over the span, [lo, hi].
    pub telemetry_hz: Option<[f64; 2]>,
    /// Numeric CSV columns and their windows [lo, hi], inclusive.
    #[serde(default)]
    pub window: BTreeMap<String, [i64; 2]>,
}

/// What the rig answered to a scripted command: `done`, a rejection token, or `no answer`.
pub type Answer = String;

/// One telemetry row of `bowl replay --csv`: column name -> cell.
pub type Row = HashMap<String, String>;

/// The state words a scenario may expect: the rig's own tokens (`DeviceState::token`).
fn states() -> Vec<&'static str> {
    DeviceState::ALL.iter().map(|s| s.token()).collect()
}

/// The workspace's `tests/scenarios` folder.
pub fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/scenarios")
}

/// Every scenario file, sorted by name.
pub fn files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder())
        .expect("tests/scenarios exists")
        .map(|e| e.expect("a directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

/// The file name, for messages.
pub fn name(path: &Path) -> String {
    format!(
        "tests/scenarios/{}",
        path.file_name().unwrap_or_default().to_string_lossy()
    )
}

/// Reads and checks a scenario file (spans inside the run, known states, windows lo <= hi).
pub fn load(path: &Path) -> Result<Scenario, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", name(path)))?;
    let s: Scenario = toml::from_str(&text).map_err(|e| format!("{}: {e}", name(path)))?;
    let end_ms = (s.seconds * 1000.0) as u32;
    let bad = |why: String| Err(format!("{}: {why}", name(path)));
    if s.expects.is_empty() {
        return bad("no [[expect]]: a scenario must check something".into());
    }
    for c in &s.commands {
        if c.at_ms >= end_ms {
            return bad(format!(
                "command `{}` at {} ms is after the end",
                c.send, c.at_ms
            ));
        }
    }
    for e in &s.expects {
        if e.from_ms > e.to_ms || e.to_ms > end_ms {
            return bad(format!(
                "`{}`: span {}..={} ms is not inside the run (0..={end_ms} ms)",
                e.what, e.from_ms, e.to_ms
            ));
        }
        let known = states();
        if let Some(st) = e.state.iter().find(|st| !known.contains(&st.as_str())) {
            return bad(format!(
                "`{}`: unknown state {st} (one of {known:?})",
                e.what
            ));
        }
        if let Some(f) = e
            .fault
            .as_deref()
            .filter(|f| FaultCode::from_token(f).is_none())
        {
            let words: Vec<&str> = FaultCode::ALL.iter().map(|f| f.token()).collect();
            return bad(format!(
                "`{}`: unknown fault {f} (one of {words:?})",
                e.what
            ));
        }
        let windows = e.window.values().map(|w| [w[0] as f64, w[1] as f64]);
        if e.telemetry_hz
            .into_iter()
            .chain(windows)
            .any(|[lo, hi]| lo > hi)
        {
            return bad(format!("`{}`: a window with lo > hi", e.what));
        }
        if e.state.is_empty()
            && e.fault.is_none()
            && e.telemetry_hz.is_none()
            && e.window.is_empty()
        {
            return bad(format!("`{}` expects nothing", e.what));
        }
    }
    Ok(s)
}

impl Scenario {
    /// The commands as `bowl serve --command AT_MS:WORDS` values, in file order: `bowl serve`
    /// numbers them 1, 2, ... in this order, and [`answers`] reads the answers by those ids.
    pub fn serve_commands(&self) -> Vec<String> {
        self.commands
            .iter()
            .map(|c| {
                let words: Vec<&str> = c.send.split_whitespace().collect();
                format!("{}:{}", c.at_ms, words.join(","))
            })
            .collect()
    }
}

/// The answer to each of `count` scripted commands, by the ids `bowl serve` gave them (1..),
/// decoded from the raw capture with the shared decoder.
pub fn answers(capture: &[u8], count: usize) -> Vec<Answer> {
    let mut out = vec!["no answer".to_string(); count];
    let mut decoder = Decoder::new();
    decoder.push_slice(capture, |frame, _| {
        let Ok(frame) = frame else { return };
        let Some(id) = frame.answer_id() else { return };
        let Some(slot) = usize::from(id).checked_sub(1).and_then(|i| out.get_mut(i)) else {
            return;
        };
        *slot = match frame {
            Frame::Reject { reason, .. } => reason.token().to_string(),
            _ => "done".to_string(),
        };
    });
    out
}

/// The telemetry rows of a `bowl replay --csv` file (event rows left out).
/// Decodes a raw capture of the rig's output with `bowl replay --csv` into `csv` and reads
/// its telemetry rows (one place for both runners; `what` names the run in a failure).
pub fn replay_rows(capture: &Path, csv: &Path, what: &str) -> Vec<Row> {
    let out = super::common::bowl(&[
        "replay",
        capture.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "bowl replay of {what}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    telemetry_rows(csv)
}

pub fn telemetry_rows(csv: &Path) -> Vec<Row> {
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_path(csv)
        .unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    let header = reader.headers().expect("a header").clone();
    reader
        .records()
        .map(|r| r.expect("a CSV record"))
        .map(|r| {
            header
                .iter()
                .zip(r.iter())
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect::<Row>()
        })
        .filter(|r| r.get("event").is_none_or(|e| e.is_empty()))
        .collect()
}

/// One column's test and what it expected, in words.
type CellCheck = (String, Box<dyn Fn(&str) -> bool>, String);

/// The column [`rebase`] marks the frames of a half-done step with.
const IN_TRANSIT: &str = "in_transit";

fn time_ms(row: &Row) -> u32 {
    row.get("device_time_ms")
        .and_then(|t| t.parse().ok())
        .unwrap_or(u32::MAX)
}

/// Every way the run missed the scenario, in words; empty when it passed. `actual_at_ms`
/// gives, where known, the device time each command really went out (a board driven by
/// `bowl send` is late by the command's transit); `None` for the host rig's exact times.
pub fn check(
    file: &str,
    s: &Scenario,
    rows: &[Row],
    answers: &[Answer],
    actual_at_ms: Option<&[u32]>,
) -> Vec<String> {
    let mut failures = Vec::new();
    for (i, (c, got)) in s.commands.iter().zip(answers).enumerate() {
        if !c.answer.eq_ignore_ascii_case(got) {
            let sent = actual_at_ms.map_or(c.at_ms, |a| a[i]);
            failures.push(format!(
                "{file}: at {sent} ms, command `{}`: expected the answer {}, got {got}",
                c.send, c.answer
            ));
        }
    }
    for e in &s.expects {
        let span: Vec<&Row> = rows
            .iter()
            .filter(|r| (e.from_ms..=e.to_ms).contains(&time_ms(r)))
            .collect();
        let head = format!("{file}: `{}` ({}..={} ms)", e.what, e.from_ms, e.to_ms);
        if span.is_empty() {
            failures.push(format!(
                "{head}: expected telemetry, got no frame in the span"
            ));
            continue;
        }
        // Rows sent while a command was in transit are not judged: the command (a SET of the
        // telemetry rate, say) may or may not have taken effect yet.
        let judged: Vec<&Row> = span
            .iter()
            .copied()
            .filter(|r| !r.contains_key(IN_TRANSIT))
            .collect();
        if let Some([lo, hi]) = e.telemetry_hz {
            // Frames per second from the intervals between neighbouring frames that were both
            // sent outside a command's transit, on the rig's own clock: a transit (a SET of the
            // rate in flight, a harness late on a loaded machine) is left out, frames and time.
            let clock = |r: &Row| {
                r.get("board_time_ms")
                    .and_then(|t| t.parse::<u32>().ok())
                    .unwrap_or_else(|| time_ms(r))
            };
            let gaps: Vec<u32> = span
                .windows(2)
                .filter(|w| !w[0].contains_key(IN_TRANSIT) && !w[1].contains_key(IN_TRANSIT))
                .map(|w| clock(w[1]).saturating_sub(clock(w[0])))
                .collect();
            let secs = f64::from(gaps.iter().sum::<u32>()) / 1000.0;
            if gaps.is_empty() || secs <= 0.0 {
                failures.push(format!(
                    "{head}: expected {lo}..={hi} telemetry frames/s, got no two neighbouring \
                     frames outside the commands' transit: no rate to measure"
                ));
            } else {
                let hz = gaps.len() as f64 / secs;
                if !(lo..=hi).contains(&hz) {
                    failures.push(format!(
                        "{head}: expected {lo}..={hi} telemetry frames/s, got {hz:.1} ({} \
                         intervals over {secs} s)",
                        gaps.len()
                    ));
                }
            }
        }
        let mut field_checks: Vec<CellCheck> = Vec::new();
        if !e.state.is_empty() {
            let allowed = e.state.clone();
            field_checks.push((
                "state".into(),
                Box::new(move |c| allowed.iter().any(|a| a == c)),
                format!("state {}", e.state.join(" or ")),
            ));
        }
        if let Some(f) = &e.fault {
            let want = f.clone();
            field_checks.push((
                "fault".into(),
                Box::new(move |c| c == want),
                format!("fault {f}"),
            ));
        }
        for (col, &[lo, hi]) in &e.window {
            field_checks.push((
                col.clone(),
                Box::new(move |c| c.parse::<i64>().is_ok_and(|v| (lo..=hi).contains(&v))),
                format!("{col} in [{lo}, {hi}]"),
            ));
        }
        for (col, ok, expected) in &field_checks {
            let bad: Vec<&&Row> = judged
                .iter()
                .filter(|r| !r.get(col).is_some_and(|c| ok(c)))
                .collect();
            if let Some(first) = bad.first() {
                let got = first.get(col).map_or("no such column", |c| {
                    if c.is_empty() { "an empty cell" } else { c }
                });
                failures.push(format!(
                    "{head}: at {} ms expected {expected}, got {got} ({} of {} frames in the span miss it)",
                    time_ms(first),
                    bad.len(),
                    judged.len()
                ));
            }
        }
    }
    failures
}

/// Puts a board's telemetry on the scenario's clock. A board driven by `bowl send` gets each
/// command later than the scenario says (the command's transit, in the board's time).
/// `sent_ms[i]` is the board time from just before command `i` (file order) was sent to just
/// after its answer came. Commands due at the same scenario time are one step: the frames
/// from its scenario time until its last answer came are put at the step's time and marked
/// `in_transit` (the step was due or half done: counted in the telemetry rate, judged by
/// nothing else), and the frames after its last answer are moved back to follow the step's
/// scenario time (those before the first step by the first step's delay; any that would fall
/// before 0 dropped). So every expectation is judged from when its step was complete: on a
/// board, a time bound after a command is looser by that command's transit than on the host
/// rig. The board's own time stays in the column `board_time_ms` (the telemetry rate is
/// measured on it).
pub fn rebase(s: &Scenario, rows: &mut Vec<Row>, sent_ms: &[(u32, u32)]) {
    // (scenario time, board time the step began, board time it was complete)
    let mut steps: Vec<(u32, u32, u32)> = Vec::new();
    for (c, &(before, after)) in s.commands.iter().zip(sent_ms) {
        match steps.iter_mut().find(|st| st.0 == c.at_ms) {
            Some(st) => {
                st.1 = st.1.min(before);
                st.2 = st.2.max(after);
            }
            None => steps.push((c.at_ms, before, after)),
        }
    }
    steps.sort();
    rows.retain_mut(|row| {
        let t = time_ms(row);
        let begun = steps.iter().take_while(|st| st.1 <= t).count();
        let mut scenario_ms = match begun.checked_sub(1).map(|i| steps[i]) {
            Some((at, _, done)) if t <= done => {
                row.insert(IN_TRANSIT.into(), "1".into());
                at
            }
            Some((at, _, done)) => at + 1 + (t - done),
            None => match steps.first() {
                Some(&(at, _, done)) if t + at < done => return false,
                Some(&(at, _, done)) => t + at - done,
                None => t,
            },
        };
        // Due but not yet sent (the harness was late for the next step): half done as well.
        if let Some(&(next_at, _, _)) = steps.get(begun)
            && scenario_ms >= next_at
        {
            row.insert(IN_TRANSIT.into(), "1".into());
            scenario_ms = next_at;
        }
        row.insert("board_time_ms".into(), t.to_string());
        row.insert("device_time_ms".into(), scenario_ms.to_string());
        true
    });
}
