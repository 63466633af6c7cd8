//! `bowl predict --batch IN --out OUT`: every row of a CSV file, written whole or not at all.
//!
//! Input: a header row naming at least `model,w_rad_s,mu,ri_m,R_m` (any order; `g` and `k2`
//! default to 9.81 and 5/7 when their columns are absent), any extra columns carried through
//! unchanged. Every row must have as many fields as the header (quote a field that holds a
//! comma). Output: the same rows plus `residence_time_s`, `exit_radial_velocity_m_s`,
//! `exit_total_velocity_m_s` in shortest round-trip f64 form (`inf` and `nan` velocities when the
//! granule never leaves), `condition_number` (relative condition of T; empty where T is not
//! defined) and `flags`: `ill_conditioned` (more than half of T's digits may be lost: a start
//! just above the equilibrium radius), `near_threshold` (never leaves, but within rounding of
//! the threshold), `never_leaves`, `inaccurate_step` (an integrator more than 1 % off the closed
//! form of the row's scene; also warned on stderr), separated by `;`.
//!
//! A row that fails (a field count that is not the header's, a value that is not a number, a
//! scene the rig refuses such as a start at or beyond the rim) is reported on stderr with its
//! line number and reason; then nothing is written (the output is built in a temporary file
//! beside OUT and renamed over it only when every row succeeded) and the exit status is 1.
//! With `--keep-going` every row is written, with a last column `status`: `ok` or the refusal
//! in words (its result fields empty), and the exit status is 1 if any row was refused.
//!
//! Line numbers count LF, CRLF and lone CR line ends alike (the header is line 1). A column
//! named twice, or a column that is neither an input nor a label (`label`, `id`, `note`, or a
//! name starting `label_` or `note_`, carried through unchanged), refuses the file by name: a
//! misspelt `Mu` would otherwise leave `mu` missing or, worse, read from the wrong copy.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use model_core::particle::{Model, Outcome, Scene};

use super::{Ends, Inputs, predict, refusals};
use crate::csv_lines::Lines;

/// Formats an f64 for the batch output: shortest round-trip digits, `inf`, `nan`.
pub fn format_f64(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{x}")
    }
}

/// The columns added to each row.
const RESULT_COLUMNS: [&str; 5] = [
    "residence_time_s",
    "exit_radial_velocity_m_s",
    "exit_total_velocity_m_s",
    "condition_number",
    "flags",
];

/// The columns a batch file must (or may) have.
struct Columns {
    model: usize,
    omega: usize,
    mu: usize,
    ri: usize,
    rim: usize,
    g: Option<usize>,
    k2: Option<usize>,
}

/// The input columns.
const INPUTS: [&str; 7] = ["model", "w_rad_s", "mu", "ri_m", "R_m", "g", "k2"];

/// Whether a column is a label carried through unchanged.
fn is_label(name: &str) -> bool {
    matches!(name, "label" | "id" | "note")
        || name.starts_with("label_")
        || name.starts_with("note_")
}

impl Columns {
    fn find(header: &csv::StringRecord) -> Result<Self> {
        for (i, h) in header.iter().enumerate() {
            let h = h.trim();
            if let Some(j) = header.iter().take(i).position(|o| o.trim() == h) {
                bail!(
                    "column `{h}` appears twice (columns {} and {}): say which one is meant by \
                     removing or renaming the other",
                    j + 1,
                    i + 1
                );
            }
            if !INPUTS.contains(&h) && !is_label(h) {
                bail!(
                    "column {} `{h}` is not a column of the batch: inputs are {} (g and k2 \
                     optional); labels carried through are label, id, note or a name starting \
                     label_ or note_ (rename it, or remove it)",
                    i + 1,
                    INPUTS.join(",")
                );
            }
        }
        let pos = |name: &str| header.iter().position(|h| h.trim() == name);
        let need = |name: &str| {
            pos(name).ok_or_else(|| {
                anyhow!(
                    "header row has no `{name}` column (need model,w_rad_s,mu,ri_m,R_m; g,k2 optional)"
                )
            })
        };
        Ok(Self {
            model: need("model")?,
            omega: need("w_rad_s")?,
            mu: need("mu")?,
            ri: need("ri_m")?,
            rim: need("R_m")?,
            g: pos("g"),
            k2: pos("k2"),
        })
    }
}

fn parse_row(row: &csv::StringRecord, cols: &Columns, width: usize) -> Result<(Model, Scene<f64>)> {
    if row.len() != width {
        bail!(
            "{} fields where the header has {width} (a comma too many or too few? quote a \
             field that holds a comma)",
            row.len()
        );
    }
    let field = |i: usize, name: &str| -> Result<f64> {
        let text = row.get(i).unwrap_or("").trim();
        text.parse::<f64>()
            .map_err(|_| anyhow!("`{name}` = {text:?} is not a number"))
    };
    let model = match row.get(cols.model).map(|s| s.trim().to_ascii_lowercase()) {
        Some(m) if m == "flat" => Model::Flat,
        Some(m) if m == "coriolis" => Model::Coriolis,
        Some(m) => bail!("`model` = {m:?}: expected flat or coriolis"),
        None => bail!("no `model` field"),
    };
    let scene = Scene {
        omega_rad_s: field(cols.omega, "w_rad_s")?,
        mu: field(cols.mu, "mu")?,
        g_m_s2: match cols.g {
            Some(i) => field(i, "g")?,
            None => 9.81,
        },
        k2: match cols.k2 {
            Some(i) => field(i, "k2")?,
            None => 5.0 / 7.0,
        },
        ri_m: field(cols.ri, "ri_m")?,
        rim_radius_m: field(cols.rim, "R_m")?,
    };
    refusals::check_named(&scene, &refusals::COLUMNS)?;
    Ok((model, scene))
}

/// The five result fields of one outcome.
fn result_fields(o: &Outcome<f64>) -> [String; 5] {
    match Ends::from(*o) {
        Ends::Leaves(l) => [
            format_f64(l.residence_time_s),
            format_f64(l.exit_radial_velocity_m_s),
            format_f64(l.exit_total_velocity_m_s),
            format_f64(l.condition_number),
            if l.ill_conditioned {
                "ill_conditioned"
            } else {
                ""
            }
            .into(),
        ],
        Ends::AtRim {
            exit_total_velocity_m_s,
        } => [
            "0".into(),
            "0".into(),
            format_f64(exit_total_velocity_m_s),
            String::new(),
            String::new(),
        ],
        // No time and no exit velocity: empty cells (a spreadsheet reads "inf" or "nan" as
        // text, or worse as a number), the flags column says never_leaves.
        Ends::Never { near_threshold, .. } => [
            String::new(),
            String::new(),
            String::new(),
            String::new(),
            if near_threshold {
                "never_leaves;near_threshold"
            } else {
                "never_leaves"
            }
            .into(),
        ],
    }
}

/// A temporary file beside `output`, removed when dropped unless kept.
struct Partial {
    path: PathBuf,
    kept: bool,
}

impl Drop for Partial {
    fn drop(&mut self) {
        if !self.kept {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Runs `bowl predict --batch INPUT --out OUTPUT`.
pub fn run(input: &Path, output: &Path, args: &Inputs) -> Result<()> {
    let bytes = std::fs::read(input).with_context(|| format!("cannot open {}", input.display()))?;
    let lines = Lines::of(&bytes);
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_reader(bytes.as_slice());
    let header = reader
        .headers()
        .with_context(|| format!("{}: cannot read the header row", input.display()))?
        .clone();
    // A spreadsheet in a comma-decimal locale saves `;` between cells (and decimal commas):
    // the whole header then reads as one column, which the column check would only call
    // unknown.
    let sep = crate::results::sheet::detect(&header.iter().collect::<Vec<_>>().join(","));
    if sep != b',' {
        bail!(
            "{}: line 1: the cells are separated by {} (a spreadsheet's CSV in a comma-decimal \
             locale), but a batch file is comma-separated with decimal points (3.6, not 3,6): \
             save it as CSV with the field delimiter , and the decimal separator .",
            input.display(),
            if sep == b'\t' {
                "tabs".into()
            } else {
                format!("`{}`", sep as char)
            }
        );
    }
    let cols = Columns::find(&header).with_context(|| format!("{}: line 1", input.display()))?;
    let name = output
        .file_name()
        .ok_or_else(|| anyhow!("--out {} names no file", output.display()))?;
    let mut partial_name = std::ffi::OsString::from(".");
    partial_name.push(name);
    partial_name.push(format!(".partial-{}", std::process::id()));
    let partial = Partial {
        path: output.with_file_name(partial_name),
        kept: false,
    };
    let mut writer = csv::Writer::from_path(&partial.path)
        .with_context(|| format!("cannot create a file beside {}", output.display()))?;
    let mut out_header = header.clone();
    for c in RESULT_COLUMNS {
        out_header.push_field(c);
    }
    if args.keep_going {
        out_header.push_field("status");
    }
    writer.write_record(&out_header)?;
    let (mut failed, mut rows) = (0usize, 0usize);
    let mut scenes = Vec::new();
    let mut record = csv::StringRecord::new();
    let how = args.method_settings();
    loop {
        // Line numbers as a user sees them: the header is line 1, whatever ends the lines.
        let (row, byte) = match reader.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => (Ok(record.clone()), record.position().map(|p| p.byte())),
            Err(e) => (Err(anyhow!("{e}")), e.position().map(|p| p.byte())),
        };
        let line = lines.record_line(&bytes, byte.unwrap_or(reader.position().byte()));
        rows += 1;
        let result = row.and_then(|row| {
            let (model, scene) = parse_row(&row, &cols, header.len())?;
            let p = predict(&scene, model, &how)?;
            if args.throughput {
                scenes.push((model, scene));
            }
            Ok((row, p))
        });
        match result {
            Ok((row, p)) if failed == 0 || args.keep_going => {
                let mut out = row.clone();
                let mut fields = result_fields(&p.outcome);
                if let Some(w) = p.check.as_ref().and_then(super::ode::StepCheck::warning) {
                    eprintln!("{}: line {line}: warning: {w}", input.display());
                    let flags = &mut fields[4];
                    if !flags.is_empty() {
                        flags.push(';');
                    }
                    flags.push_str("inaccurate_step");
                }
                for f in fields {
                    out.push_field(&f);
                }
                if args.keep_going {
                    out.push_field("ok");
                }
                writer.write_record(&out)?;
            }
            Ok(_) => {}
            Err(e) => {
                failed += 1;
                eprintln!("{}: line {line}: {e:#}", input.display());
                if args.keep_going {
                    // The row as read, cut or padded to the header's width, results empty.
                    let mut out = csv::StringRecord::new();
                    for i in 0..header.len() {
                        out.push_field(record.get(i).unwrap_or(""));
                    }
                    for _ in RESULT_COLUMNS {
                        out.push_field("");
                    }
                    out.push_field(&format!("refused: {e:#}"));
                    writer.write_record(&out)?;
                }
            }
        }
    }
    if failed > 0 && !args.keep_going {
        bail!(
            "{failed} of {rows} row(s) of {} failed (see above): {} not written; fix the rows \
             and run again, or give --keep-going to write every row with its status",
            input.display(),
            output.display()
        );
    }
    writer.flush()?;
    drop(writer);
    std::fs::rename(&partial.path, output)
        .with_context(|| format!("cannot write {}", output.display()))?;
    let mut partial = partial;
    partial.kept = true;
    if failed > 0 {
        bail!(
            "{failed} of {rows} row(s) of {} refused (see above and their status column): the \
             other {} written to {}",
            input.display(),
            rows - failed,
            output.display()
        );
    }
    if args.throughput {
        println!("{}", super::throughput::measure(&scenes));
    }
    Ok(())
}
