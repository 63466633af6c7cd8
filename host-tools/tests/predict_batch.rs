//! `bowl predict --batch` given what spreadsheets write: LF, CRLF and CR line ends, `;` files
//! with decimal commas, empty trailing columns, a column
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
            err.contains("line 4: column w_rad_s: \"fast\" is not a number"),
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
    assert!(
        status[1].starts_with("refused: column w_rad_s: \"fast\" is not a number"),
        "{}",
        status[1]
    );
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
    assert!(err.contains("columns 3 and 6 are both named mu"), "{err}");
    assert!(written.is_empty());
}

#[test]
fn an_unknown_column_is_refused_by_name() {
    let (out, _, err) = batch(
        "unknown",
        "model,omega,mu,ri_m,R_m\nflat,3.6,0.01,0.03,0.1\n",
        &[],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("line 1: column 2 `omega` is not a column of the batch"),
        "{err}"
    );
    // The same name in another case is the same column: twice is refused by name.
    let (out, _, err) = batch(
        "twice-cased",
        "model,w_rad_s,Mu,mu,ri_m,R_m\nflat,3.6,0.5,0.01,0.03,0.1\n",
        &[],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(err.contains("columns 3 and 4 are both named mu"), "{err}");
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

/// The result cells of the one row of a batch output (`;` or `,` separated), decimal commas
/// read as points: the columns from `from` on.
fn results_of(written: &str, sep: char, from: usize) -> Vec<String> {
    let row = written
        .lines()
        .nth(1)
        .unwrap_or_else(|| panic!("{written}"));
    row.split(sep)
        .skip(from)
        .map(|c| c.replace(',', "."))
        .collect()
}

/// A spreadsheet's `;`-separated file (comma-decimal locale: decimal commas, BOM, CRLF, a
/// `sep=;` line or a tab, a units row, empty trailing columns) is read as the results file is,
/// and written back in its own dialect; it was refused ("the cells are separated by `;`").
#[test]
fn a_semicolon_file_is_read_and_written_back_alike() {
    let (out, plain, err) = batch(
        "plain",
        "model,w_rad_s,mu,ri_m,R_m\nflat,3.6,0.01,0.03,0.1\n",
        &[],
    );
    assert!(out.status.success(), "{err}");
    let want = results_of(&plain, ',', 5);
    assert!(want[0].parse::<f64>().unwrap() > 0.0, "{plain}");
    for (name, sep, first) in [
        ("semicolons", ";", "\u{feff}"),
        ("sep-line", ";", "sep=;\r\n"),
        ("tabs", "\t", ""),
    ] {
        let text = format!(
            "{first}label{sep}model{sep}w_rad_s{sep}mu{sep}ri_m{sep}R_m{sep}{sep}\r\n\
             {sep}{sep}rad/s{sep}{sep}m{sep}m{sep}{sep}\r\n\
             a{sep}flat{sep}3,6{sep}0,01{sep}0,03{sep}0,1{sep}{sep}\r\n"
        );
        let (out, written, err) = batch(name, &text, &[]);
        assert!(out.status.success(), "{name}: {err}");
        let sep = sep.chars().next().unwrap();
        let header = written.lines().next().unwrap();
        assert!(
            header.starts_with(&format!("label{sep}model{sep}w_rad_s")),
            "{name}: {written}"
        );
        assert!(
            header.ends_with(&format!("R_m{sep}residence_time_s{sep}exit_radial_velocity_m_s{sep}exit_total_velocity_m_s{sep}condition_number{sep}flags")),
            "{name}: the unnamed columns are dropped: {written}"
        );
        assert!(
            written
                .lines()
                .nth(1)
                .unwrap()
                .starts_with(&format!("a{sep}flat{sep}3,6{sep}")),
            "{name}: {written}"
        );
        assert_eq!(results_of(&written, sep, 6), want, "{name}: {written}");
        assert_eq!(
            written.lines().count(),
            2,
            "{name}: the units row is not a row: {written}"
        );
    }
}

/// The empty trailing columns a spreadsheet saves (`,,` after the last name) are let through
/// while empty; it was "column 6 `` is not a column of the batch". A value in one is refused
/// with its line. Header names in another case are the same columns, written back as spelt.
#[test]
fn empty_trailing_columns_and_cased_names_are_read() {
    let (out, written, err) = batch(
        "trailing",
        "MODEL,W_rad_s,Mu,ri_m,R_m,,\r\nflat,3.6,0.01,0.03,0.1,,\r\n,,,,,,\r\ncoriolis,3.6,0.01,0.03,0.1\r\n",
        &[],
    );
    assert!(out.status.success(), "{err}");
    let lines: Vec<&str> = written.lines().collect();
    assert!(
        lines[0].starts_with("MODEL,W_rad_s,Mu,ri_m,R_m,residence_time_s,"),
        "{written}"
    );
    assert_eq!(lines.len(), 3, "the emptied row is not a row: {written}");
    assert!(
        lines[1].starts_with("flat,3.6,0.01,0.03,0.1,0.68"),
        "{written}"
    );
    assert!(lines[2].starts_with("coriolis,3.6,"), "{written}");
    let (out, written, err) = batch(
        "trailing-value",
        "model,w_rad_s,mu,ri_m,R_m,,\nflat,3.6,0.01,0.03,0.1,,\nflat,3.6,0.01,0.03,0.1,,x\n",
        &[],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("line 1: column 7 has no name in the header, but line 3 holds `x` in it"),
        "{err}"
    );
    assert!(written.is_empty());
    // A decimal comma in a comma file: quoted, it is one cell that is not a number; bare, it
    // makes one cell too many. Both say to use a decimal point.
    let (out, _, err) = batch(
        "quoted-comma",
        "model,w_rad_s,mu,ri_m,R_m\nflat,\"3,6\",0.01,0.03,0.1\nflat,3,6,0.01,0.03,0.1\n",
        &[],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("line 2: column w_rad_s: \"3,6\" is not a number (use a decimal point"),
        "{err}"
    );
    assert!(
        err.contains("line 3: 6 cells, but the header names 5 columns (a decimal comma"),
        "{err}"
    );
    // A `g` column that is there needs its cells: an empty one is not the default.
    let (out, _, err) = batch(
        "empty-g",
        "model,w_rad_s,mu,ri_m,R_m,g\nflat,3.6,0.01,0.03,0.1,\n",
        &[],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(err.contains("line 2: column g: empty"), "{err}");
}
