//! `bowl predict --batch IN --out OUT`: every row of a CSV file, written whole or not at all.
//!
//! Input: a header row naming at least `model,w_rad_s,mu,ri_m,R_m` (any order, any case; `g`
//! and `k2` default to 9.81 and 5/7 when their columns are absent), label columns carried
//! through unchanged. The file is read by the results file's reader ([`Sheet`]), so what a
//! spreadsheet saves reads as it does there: `;` or tab separators with decimal commas (`3,6`),
//! a `sep=;` first line, a BOM, CRLF or lone CR line ends, blank or emptied rows, a units row
//! under the header, and empty columns with no name (the trailing separators of a sheet whose
//! last columns were used once). The output is written in the input's dialect: its separator,
//! decimal commas when that is not a comma, the header's names as the file spells them.
//!
//! Output: the same rows plus `residence_time_s`, `exit_radial_velocity_m_s`,
//! `exit_total_velocity_m_s` in shortest round-trip f64 form (empty when the granule never
//! leaves), `condition_number` (relative condition of T; empty where T is not defined) and
//! `flags`: `ill_conditioned` (more than half of T's digits may be lost: a start just above the
//! equilibrium radius), `near_threshold` (never leaves, but within rounding of the threshold),
//! `never_leaves`, `inaccurate_step` (an integrator more than 1 % off the closed form of the
//! row's scene; also warned on stderr), separated by `;`.
//!
//! A row that fails (more cells than the header names, a value that is not a number, a scene
//! the rig refuses such as a start at or beyond the rim) is reported on stderr with its line
//! number and reason; then nothing is written (the output is built in a temporary file beside
//! OUT and renamed over it only when every row succeeded) and the exit status is 1. With
//! `--keep-going` every row is written, with a last column `status`: `ok` or the refusal in
//! words (its result fields empty), and the exit status is 1 if any row was refused.
//!
//! Line numbers are the file's own (the header's line counted). A column named twice (in any
//! case), or a column that is neither an input nor a label (`label`, `id`, `note`, or a name
//! starting `label_` or `note_`), refuses the file by name: a misspelt `omega` would otherwise
//! leave `w_rad_s` missing or, worse, read from the wrong copy.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use model_core::particle::{Model, Outcome, Scene};

use super::{Ends, Inputs, predict, refusals};
use crate::results::sheet::{Cells, Sheet};

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

/// The input columns, as the batch names them (matched whatever their case, as the results
/// file's are; the rim radius `R_m` is written with its capital in every message).
const INPUTS: [&str; 7] = ["model", "w_rad_s", "mu", "ri_m", "R_m", "g", "k2"];

/// Whether a column (lowercased) is a label carried through unchanged.
fn is_label(name: &str) -> bool {
    matches!(name, "label" | "id" | "note")
        || name.starts_with("label_")
        || name.starts_with("note_")
}

/// Checks the header: every named column an input or a label, every needed input there. A
/// column without a name (a spreadsheet saves its empty columns as trailing separators) is let
/// through only while every cell of it is empty. Returns the columns written out, in order: the
/// named ones.
fn check_columns(sheet: &Sheet) -> Result<Vec<usize>> {
    let mut kept = Vec::new();
    for (i, name) in sheet.names().iter().enumerate() {
        let lower = name.to_lowercase();
        if name.is_empty() {
            if let Some(c) = sheet
                .each_row()
                .find(|c| c.cells().get(i).is_some_and(|x| !x.is_empty()))
            {
                bail!(
                    "column {} has no name in the header, but line {} holds `{}` in it: name it \
                     (label, note or a name starting label_ or note_ to carry it through) or \
                     remove it",
                    i + 1,
                    c.line,
                    c.cells()[i]
                );
            }
            continue;
        }
        if !INPUTS.iter().any(|n| n.to_lowercase() == lower) && !is_label(&lower) {
            bail!(
                "column {} `{name}` is not a column of the batch: inputs are {} (g and k2 \
                 optional); labels carried through are label, id, note or a name starting \
                 label_ or note_ (rename it, or remove it)",
                i + 1,
                INPUTS.join(",")
            );
        }
        kept.push(i);
    }
    let has = |n: &str| sheet.names().iter().any(|h| h.eq_ignore_ascii_case(n));
    if let Some(n) = INPUTS[..5].iter().find(|n| !has(n)) {
        bail!("header row has no `{n}` column (need model,w_rad_s,mu,ri_m,R_m; g,k2 optional)");
    }
    Ok(kept)
}

/// Reads one row's scene. `optional`: whether the file has the `g` and `k2` columns (a cell
/// left empty in a column that is there is refused, not taken for the default).
fn parse_row(row: &Cells, optional: [bool; 2]) -> Result<(Model, Scene<f64>)> {
    if let Some(why) = row.too_wide() {
        bail!("{why}");
    }
    let field = |name: &str| -> Result<Option<f64>> {
        row.read_number(&name.to_lowercase())
            .map_err(|why| anyhow!("column {name}: {why}"))
    };
    let needed = |name: &str| -> Result<f64> {
        field(name)?.ok_or_else(|| anyhow!("column {name}: empty (a number is needed here)"))
    };
    let model = match row.text("model").to_ascii_lowercase().as_str() {
        "flat" => Model::Flat,
        "coriolis" => Model::Coriolis,
        "" => bail!("column model: empty (flat or coriolis is needed here)"),
        m => bail!("column model: {m:?} is not a model of the batch: expected flat or coriolis"),
    };
    let scene = Scene {
        omega_rad_s: needed("w_rad_s")?,
        mu: needed("mu")?,
        g_m_s2: if optional[0] { needed("g")? } else { 9.81 },
        k2: if optional[1] {
            needed("k2")?
        } else {
            5.0 / 7.0
        },
        ri_m: needed("ri_m")?,
        rim_radius_m: needed("R_m")?,
    };
    refusals::check_named(&scene, &refusals::COLUMNS)?;
    Ok((model, scene))
}

/// The five result fields of one outcome.
fn result_fields(o: &Outcome<f64>, format_f64: &dyn Fn(f64) -> String) -> [String; 5] {
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
    let sheet = Sheet::read(input, "the batch file")?;
    let kept = check_columns(&sheet)
        .with_context(|| format!("{}: line {}", input.display(), sheet.header_line()))?;
    let has = |n: &str| sheet.names().iter().any(|h| h.eq_ignore_ascii_case(n));
    let optional = [has("g"), has("k2")];
    // The output in the input's dialect: a `;`-separated file (a comma-decimal locale's
    // spreadsheet) gets `;` and decimal commas back, so that spreadsheet opens it as it wrote it.
    let sep = sheet.sep();
    let number = |x: f64| {
        let text = format_f64(x);
        if sep == b',' {
            text
        } else {
            text.replace('.', ",")
        }
    };
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
    let mut writer = csv::WriterBuilder::new()
        .delimiter(sep)
        .from_path(&partial.path)
        .with_context(|| format!("cannot create a file beside {}", output.display()))?;
    let mut out_header: Vec<&str> = kept.iter().map(|&i| sheet.names()[i].as_str()).collect();
    out_header.extend(RESULT_COLUMNS);
    if args.keep_going {
        out_header.push("status");
    }
    writer.write_record(&out_header)?;
    let (mut failed, mut rows) = (0usize, 0usize);
    let mut scenes = Vec::new();
    let how = args.method_settings();
    for row in sheet.each_row() {
        let line = row.line;
        rows += 1;
        let result = parse_row(&row, optional).and_then(|(model, scene)| {
            let p = predict(&scene, model, &how)?;
            if args.throughput {
                scenes.push((model, scene));
            }
            Ok(p)
        });
        // The row's named cells as read (a row that ends early padded with empty cells).
        let mut out: Vec<String> = kept
            .iter()
            .map(|&i| row.cells().get(i).cloned().unwrap_or_default())
            .collect();
        match result {
            Ok(p) if failed == 0 || args.keep_going => {
                let mut fields = result_fields(&p.outcome, &number);
                if let Some(w) = p.check.as_ref().and_then(super::ode::StepCheck::warning) {
                    eprintln!("{}: line {line}: warning: {w}", input.display());
                    let flags = &mut fields[4];
                    if !flags.is_empty() {
                        flags.push(';');
                    }
                    flags.push_str("inaccurate_step");
                }
                out.extend(fields);
                if args.keep_going {
                    out.push("ok".into());
                }
                writer.write_record(&out)?;
            }
            Ok(_) => {}
            Err(e) => {
                failed += 1;
                eprintln!("{}: line {line}: {e:#}", input.display());
                if args.keep_going {
                    out.extend(RESULT_COLUMNS.map(|_| String::new()));
                    out.push(format!("refused: {e:#}"));
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
