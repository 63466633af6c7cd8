//! The results file's reader against what spreadsheets write.

use super::*;

fn sheet(text: &str) -> Sheet {
    Sheet::parse(text, "r.csv".into()).unwrap()
}

#[test]
fn finds_the_separator_from_the_header_or_a_sep_line() {
    assert_eq!(sheet("a,b\n1,2\n").sep, b',');
    assert_eq!(sheet("a;b\n1,5;2\n").sep, b';');
    assert_eq!(sheet("a\tb\n1\t2\n").sep, b'\t');
    let s = sheet("sep=;\nA ; B\n1,5;2\n");
    assert_eq!(s.sep, b';');
    assert_eq!(s.columns, ["a", "b"]);
    assert_eq!(s.rows[0].0, 3, "line numbers count the sep= line");
    assert_eq!(sheet("\"sep=;\"\na;b\n1;2\n").sep, b';');
    // One column, no separator at all: a comma file.
    assert_eq!(sheet("a\n1\n").sep, b',');
}

#[test]
fn reads_decimal_commas_trims_and_skips_blank_rows() {
    let s = sheet("\u{feff}sep=;\n Run ;RESIDENCE_S; note \n1 ; 1,07 ;x \n;;\n2;2.5;\n");
    let rows: Vec<Cells> = s.rows().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0].line, 3);
    assert_eq!(rows[0].whole("run").unwrap(), 1);
    assert_eq!(rows[0].number("residence_s").unwrap(), 1.07);
    assert_eq!(rows[0].text("note"), "x");
    assert_eq!(
        (rows[1].line, rows[1].number("residence_s").unwrap()),
        (5, 2.5)
    );
    assert_eq!(rows[1].number_or_empty("note").unwrap(), None);
    let s = sheet("a,b\n1,2\n,,,,\n");
    assert_eq!(s.rows().count(), 1);
    // Two files pasted together: the second header (any case) is skipped, the lines keep
    // the file's numbering.
    let s = sheet("run,t\n1,2\nRun,T\n3,4\n");
    let lines: Vec<usize> = s.rows().map(|r| r.unwrap().line).collect();
    assert_eq!(lines, [2, 4]);
}

/// A spreadsheet's file as Excel on Windows saves it: CRLF line ends, a units row under the
/// header, spare empty columns. The units row is skipped, and each row keeps its own line
/// (with CRLF the rows after the first were named one line too early: line 2 for line 3).
#[test]
fn a_crlf_file_with_a_units_row_keeps_its_lines() {
    let text = "run;residence_s;g;status;;\r\n;s;m/s^2;;;\r\n1;1,07;9,8;ok;;\r\n2;;9,8;ok;;\r\n3;0,9;9,8;ok;;\r\n";
    let s = sheet(text);
    let rows: Vec<Cells> = s.rows().map(Result::unwrap).collect();
    let lines: Vec<usize> = rows.iter().map(|r| r.line).collect();
    assert_eq!(lines, [3, 4, 5]);
    assert_eq!(rows[0].number("residence_s").unwrap(), 1.07);
    let e = rows[1].number("residence_s").unwrap_err().to_string();
    assert!(
        e.starts_with("r.csv, line 4, column residence_s: empty"),
        "{e}"
    );
    // Without the units row, CRLF alone, and with a sep= line.
    let s = sheet("sep=;\r\nrun;t\r\n1;2\r\n\r\n3;4\r\n");
    let lines: Vec<usize> = s.rows().map(|r| r.unwrap().line).collect();
    assert_eq!(lines, [3, 5]);
    // A first row of values is never taken for units, even with its numbers missing.
    let s = sheet("run,status,t\n,ok,\n");
    assert_eq!(s.rows().count(), 1);
}

/// Lone CR line ends (an old Mac's files): the separator is found from the header line
/// alone; it was counted over the whole file, where the decimal commas outnumber the `;`.
/// A spreadsheet user's note between runs: a line starting with `#` is skipped (it stopped
/// the fit as `column run: empty`), and a note typed alone on a line, without the `#`, is
/// named as the line's one text (it was refused as that empty column, the note unsaid).
#[test]
fn a_comment_line_is_skipped_and_a_lone_note_is_named() {
    let s = sheet("run;t\r\n1;2,5\r\n# gate wiped; run 2 redone\r\n;# moved\r\n2;3\r\n");
    let rows: Vec<_> = s.each_row().collect();
    assert_eq!(rows.len(), 2);
    assert_eq!((rows[0].line, rows[1].line), (2, 5));
    assert_eq!(rows[1].number("t").unwrap(), 3.0);
    let s = sheet("run;t\n1;2,5\n;gate wiped\n2;3\n");
    let e = s
        .each_row()
        .nth(1)
        .unwrap()
        .whole("run")
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "r.csv, line 3: holds only the text `gate wiped` (in column 2, t) and no other \
         value: a note? start the line with # (such lines are skipped), or delete it"
    );
    // A row with one number left is still a row with a cell missing.
    let s = sheet("run;t\n1;\n");
    let e = s
        .each_row()
        .next()
        .unwrap()
        .number("t")
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 2, column t: empty"), "{e}");
}

#[test]
fn a_cr_file_finds_its_separator_on_the_header_line() {
    let s = sheet("a;b\r1,5;2,5\r3,5;4,5\r");
    assert_eq!(s.sep, b';');
    let rows: Vec<Cells> = s.rows().map(Result::unwrap).collect();
    assert_eq!(rows[1].number("b").unwrap(), 4.5);
    assert_eq!(rows[1].line, 3);
    let s = sheet("sep=;\rA;b\r1,5;2\r");
    assert_eq!((s.sep, s.header_line()), (b';', 2));
    assert_eq!(s.names(), ["A", "b"]);
    assert_eq!(s.rows().next().unwrap().unwrap().line, 3);
}

#[test]
fn names_one_line_and_the_column_in_errors() {
    let s = sheet("run,residence_s\n1,0.5\n2,\"1,07\"\n");
    let e = s.rows().nth(1).unwrap().unwrap();
    let e = e.number("residence_s").unwrap_err().to_string();
    assert_eq!(
        e,
        "r.csv, line 3, column residence_s: \"1,07\" is not a number (use a decimal point, \
         or a ;-separated file)"
    );
    let s = sheet("run;residence_s\nfirst;1.2.3\n");
    let row = s.rows().next().unwrap().unwrap();
    let e = row.whole("run").unwrap_err().to_string();
    assert!(
        e.starts_with("r.csv, line 2, column run: \"first\" is not a whole"),
        "{e}"
    );
    let e = row.number("residence_s").unwrap_err().to_string();
    assert!(
        e.contains("line 2, column residence_s: \"1.2.3\" is not a number"),
        "{e}"
    );
    // An unquoted decimal comma in a comma file: one cell too many, said so.
    let s = sheet("run,residence_s\n1,1,07\n");
    let e = s.rows().next().unwrap().err().unwrap().to_string();
    assert!(
        e.contains("line 2: 3 cells, but the header names 2 columns"),
        "{e}"
    );
    assert!(
        e.contains("use a decimal point, or a ;-separated file"),
        "{e}"
    );
    let e = Sheet::parse("Run,run\n", "r.csv".into())
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("columns 1 and 2 are both named run"), "{e}");
    let e = sheet("run\n")
        .require(&["run", "k2", "status"], "a results file")
        .unwrap_err();
    assert!(
        e.to_string().contains("no column k2, status in the header"),
        "{e}"
    );
}
