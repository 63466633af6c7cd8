//! `bowl predict --batch` given what spreadsheets write: LF, CRLF and CR line ends, a column
//! named twice or not known, and `--keep-going` (every row written with its status).

mod common;

use std::process::Output;

use common::run_batch;

/// Runs the batch on `text` with `extra` flags: the output, the written file's text, stderr.
fn batch(name: &str, text: &str, extra: &[&str]) -> (Output, String, String) {
    let (out, written) = run_batch(name, text, extra);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (out, written, err)
}

/// A blank line 3, a word for a number on line 4, a start beyond the rim on line 5.
const ROWS: [&str; 6] = [
    "label,model,w_rad_s,mu,ri_m,R_m",
    "a,flat,3.6,0.01,0.03,0.1",
    "",
    "b,flat,fast,0.01,0.03,0.1",
    "c,flat,3.6,0.01,0.2,0.1",
    "d,coriolis,3.6,0.01,0.03,0.1",
];

#[test]
fn line_numbers_are_right_for_lf_crlf_and_cr() {
    for (name, end) in [("lf", "\n"), ("crlf", "\r\n"), ("cr", "\r")] {
        let text = ROWS.join(end) + end;
        let (out, written, err) = batch(name, &text, &[]);
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(
            err.contains("line 4: `w_rad_s` = \"fast\""),
            "{name}: {err}"
        );
        assert!(
            err.contains("line 5: column ri_m = 0.2 m"),
            "the column, not a flag: {name}: {err}"
        );
        assert!(err.contains("--keep-going"), "{name}: {err}");
        assert!(
            written.is_empty(),
            "{name}: nothing written without --keep-going"
        );
    }
}

#[test]
fn keep_going_writes_every_row_with_its_status_and_fails() {
    let (out, written, err) = batch("keep", &(ROWS.join("\r\n") + "\r\n"), &["--keep-going"]);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("2 of 4 row(s)") && err.contains("refused"),
        "{err}"
    );
    let mut rdr = csv::Reader::from_reader(written.as_bytes());
    assert_eq!(rdr.headers().unwrap().iter().next_back(), Some("status"));
    let rows: Vec<csv::StringRecord> = rdr.records().map(|r| r.unwrap()).collect();
    let status: Vec<&str> = rows.iter().map(|r| r.iter().next_back().unwrap()).collect();
    assert_eq!(status[0], "ok");
    assert!(status[1].starts_with("refused: `w_rad_s` = \"fast\" is not a number"));
    assert!(status[2].contains("not inside the rim"), "{}", status[2]);
    assert_eq!(status[3], "ok");
    assert!(rows[0][6].parse::<f64>().unwrap() > 0.0);
    assert_eq!(&rows[1][6], "", "a refused row has no result");
    // All good: exit 0, every status ok.
    let (out, written, _) = batch(
        "keep-ok",
        "model,w_rad_s,mu,ri_m,R_m\nflat,3.6,0.01,0.03,0.1\n",
        &["--keep-going"],
    );
    assert!(out.status.success());
    assert!(
        written.lines().nth(1).unwrap().ends_with(",ok"),
        "{written}"
    );
}

#[test]
fn a_column_named_twice_is_refused_by_name() {
    let (out, written, err) = batch(
        "dup",
        "model,w_rad_s,mu,ri_m,R_m,mu\nflat,3.6,0.01,0.03,0.1,0.5\n",
        &[],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("column `mu` appears twice (columns 3 and 6)"),
        "{err}"
    );
    assert!(written.is_empty());
}

#[test]
fn an_unknown_column_is_refused_by_name() {
    let (out, _, err) = batch(
        "unknown",
        "model,w_rad_s,Mu,mu,ri_m,R_m\nflat,3.6,0.5,0.01,0.03,0.1\n",
        &[],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("column 3 `Mu` is not a column of the batch"),
        "{err}"
    );
    // Labels are carried through.
    let (out, written, err) = batch(
        "labels",
        "id,note_batch,model,w_rad_s,mu,ri_m,R_m\n7,x,flat,3.6,0.01,0.03,0.1\n",
        &[],
    );
    assert!(out.status.success(), "{err}");
    assert!(
        written.lines().nth(1).unwrap().starts_with("7,x,flat"),
        "{written}"
    );
}

/// A spreadsheet's `;`-separated file (comma-decimal locale, BOM, CRLF) is told as such, with
/// what to save instead; it was "column 1 `model;w_rad_s;mu;ri_m;R_m` is not a column of the
/// batch".
#[test]
fn a_semicolon_file_is_told_what_to_save() {
    for (name, sep, said) in [("semicolons", ";", "`;`"), ("tabs", "\t", "tabs")] {
        let text = format!(
            "\u{feff}model{sep}w_rad_s{sep}mu{sep}ri_m{sep}R_m\r\nflat{sep}3,6{sep}0,01{sep}0,03{sep}0,1\r\n"
        );
        let (out, written, err) = batch(name, &text, &[]);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.contains(&format!("line 1: the cells are separated by {said}")),
            "{err}"
        );
        assert!(
            err.contains("field delimiter , and the decimal separator ."),
            "{err}"
        );
        assert!(!err.contains("is not a column of the batch"), "{err}");
        assert!(written.is_empty());
    }
}
