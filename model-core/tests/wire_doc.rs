//! The worked examples of docs/protocol.md, checked against the codec so the spec cannot drift.

use model_core::wire::crc::crc32;
use model_core::wire::*;

fn doc() -> String {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/protocol.md");
    std::fs::read_to_string(path).expect("docs/protocol.md is readable")
}

/// The lines of every fenced block with this info string.
fn blocks(doc: &str, info: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut current: Option<Vec<String>> = None;
    for line in doc.lines() {
        let fence = line.trim().starts_with("```");
        match current.take() {
            None if line.trim() == format!("```{info}") => current = Some(Vec::new()),
            None => {}
            Some(lines) if fence => out.push(lines),
            Some(mut lines) => {
                lines.push(line.to_string());
                current = Some(lines);
            }
        }
    }
    out
}

fn pairs(block: &[String]) -> Vec<(String, String)> {
    assert!(
        block.len().is_multiple_of(2),
        "examples come in pairs: {block:?}"
    );
    block
        .chunks(2)
        .map(|c| (c[0].clone(), c[1].clone()))
        .collect()
}

#[test]
fn decoded_examples_match_the_doc_and_re_encode_byte_for_byte() {
    let doc = doc();
    let mut checked = 0;
    for block in blocks(&doc, "wire") {
        for (line, meaning) in pairs(&block) {
            // Every frame is sent with `\r\n`, so the doc's lines re-encode with it.
            let bytes = format!("{line}\r\n").into_bytes();
            let frame = decode_frame(&bytes).unwrap_or_else(|e| panic!("{line}: {e:?}"));
            assert_eq!(format!("{frame:?}"), meaning, "meaning of {line}");
            let mut buf = [0u8; MAX_FRAME_LEN];
            let n = encode(&frame, &mut buf).unwrap();
            assert_eq!(&buf[..n], &bytes[..], "re-encoding of {line}");
            checked += 1;
        }
    }
    assert!(checked >= 18, "only {checked} examples found");
}

#[test]
fn rejected_examples_fail_as_the_doc_says() {
    let doc = doc();
    let mut checked = 0;
    for block in blocks(&doc, "reject") {
        for (line, error) in pairs(&block) {
            let got = decode_frame(format!("{line}\n").as_bytes());
            assert_eq!(
                format!("{:?}", got.err()),
                format!("Some({error})"),
                "{line}"
            );
            checked += 1;
        }
    }
    assert!(checked >= 7);
}

#[test]
fn crc_examples_match() {
    let doc = doc();
    let crc_blocks = blocks(&doc, "crc");
    assert!(!crc_blocks.is_empty());
    for block in crc_blocks {
        let payload = block[0].strip_prefix("payload: ").unwrap();
        let crc = block[1].strip_prefix("crc32: ").unwrap();
        assert_eq!(format!("{:08X}", crc32(payload.as_bytes())), crc);
    }
}

#[test]
fn link_budget_figures_in_the_doc_hold() {
    let doc = doc();
    // The longest telemetry frame of the doc is the widest possible one.
    assert!(doc.contains(&format!(
        "| longest telemetry (every field at its widest) | {MAX_TELEMETRY_LEN} |"
    )));
    let rate_hz = 50;
    let bytes_per_s = rate_hz * MAX_TELEMETRY_LEN;
    let link_bytes_per_s = DEFAULT_BAUD as usize / 10;
    assert!(2 * bytes_per_s < link_bytes_per_s);
    assert!(doc.contains(&format!("50 x {MAX_TELEMETRY_LEN} = {bytes_per_s} bytes/s")));
    assert_eq!(max_telemetry_hz(DEFAULT_BAUD), 51);
    assert!(doc.contains("`max_telemetry_hz(115200)` = 51"));
}

/// The parameter table of docs/protocol.md lists the code's table (`wire::params`) in wire
/// order with the same ranges.
#[test]
fn parameter_table_matches_the_code() {
    let doc = doc();
    let rows: Vec<(String, String)> = doc
        .lines()
        .filter(|l| l.starts_with("| ") && l.contains("| `"))
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            // | # | name | unit | range |
            let name = cells.get(2)?.trim_matches('`').to_string();
            let range = cells.get(4)?.replace(' ', "");
            Some((name, range))
        })
        .filter(|(name, _)| ParamId::from_token(name.as_bytes()).is_some())
        .collect();
    let expected: Vec<(String, String)> = ParamId::ALL
        .iter()
        .map(|id| {
            let (lo, hi) = id.range();
            (id.token().to_string(), format!("{lo}..={hi}"))
        })
        .collect();
    assert_eq!(rows, expected);
}

/// The command table of docs/protocol.md as the code's table (`wire::commands`) renders it.
fn command_table_markdown() -> String {
    let state = |s: DeviceState| match s {
        DeviceState::Idle => "idle",
        DeviceState::Commissioning => "commissioning",
        DeviceState::ChangingSpeed => "changing speed",
        DeviceState::Running => "running",
        DeviceState::Stopping => "stopping",
        DeviceState::Faulted => "faulted",
    };
    let all_states = (0..=5).filter_map(DeviceState::from_code);
    let mut out =
        String::from("| word | fields | answer | allowed in | meaning |\n|---|---|---|---|---|\n");
    for kind in CommandKind::ALL {
        let fields: Vec<String> = kind
            .fields()
            .iter()
            .map(|f| {
                let takes = match f.kind {
                    FieldKind::Int { min, max, limit } => {
                        let mut t = format!("{min}..={max} {}", f.unit);
                        if let Some(p) = limit {
                            t += &format!(", at most `{}`", p.token());
                        }
                        t
                    }
                    FieldKind::Choice(tokens) => {
                        let t: Vec<String> = tokens.iter().map(|t| format!("`{t}`")).collect();
                        t.join(" ")
                    }
                    FieldKind::ParamName => "a parameter's name (table below)".into(),
                    FieldKind::ParamValue => "in that parameter's unit and range".into(),
                };
                format!("`{}`: {takes}", f.name)
            })
            .collect();
        let answer = char::from(kind.answer().letter());
        let answer = if kind.refusable() {
            format!("{answer} / R")
        } else {
            answer.to_string()
        };
        let allowed = if kind.states() == States::ANY {
            "any state".to_string()
        } else {
            let s: Vec<&str> = all_states
                .clone()
                .filter(|&s| kind.states().contains(s))
                .map(state)
                .collect();
            s.join(", ")
        };
        let fields = if fields.is_empty() {
            "none".to_string()
        } else {
            fields.join("; ")
        };
        out += &format!(
            "| `{}` | {fields} | {answer} | {allowed} | {} |\n",
            kind.token(),
            kind.meaning()
        );
    }
    out
}

/// docs/protocol.md's command table is exactly the code's table, rendered.
#[test]
fn command_table_matches_the_code() {
    let doc = doc();
    let table = command_table_markdown();
    assert!(
        doc.contains(&table),
        "docs/protocol.md's command table differs from the code's (`wire::commands`); it \
         should read:\n\n{table}"
    );
    assert_eq!(doc.matches("| word |").count(), 1, "one command table");
}
