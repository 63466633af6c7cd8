//! The one reader of the results file and its speed traces, tolerant of what a spreadsheet does
//! to a CSV file: in a comma-decimal locale it saves `;`-separated cells with decimal commas
//! (`1,07`), sometimes after a first line `sep=;`; headers may come back uppercase or padded
//! with spaces, cells with trailing spaces, and an emptied row as `,,,,,,`; two files pasted
//! one under the other repeat the header line (skipped), and a units row under the header is
//! skipped too. Every error names
//! one line (the file's own numbering, header line included) and the column, in words.

use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::csv_lines::Lines;

/// A table read from a file: its header and its non-blank rows.
pub struct Sheet {
    /// The file, as errors name it.
    file: String,
    /// The separator found (`,`, `;` or a tab).
    sep: u8,
    /// The header's names, trimmed and lowercased (matched case-insensitively).
    columns: Vec<String>,
    /// The same names as the file spells them (written back out as they came in).
    names: Vec<String>,
    /// The header's line (after a `sep=` line or blank lines, not the first).
    header_line: usize,
    /// Each row's line number and its trimmed cells.
    rows: Vec<(usize, Vec<String>)>,
}

/// One row of a [`Sheet`], read cell by cell with the errors in words.
pub struct Cells<'a> {
    sheet: &'a Sheet,
    /// The line the row starts on.
    pub line: usize,
    cells: &'a [String],
}

/// The separator a `sep=X` first line names (Excel writes it, sometimes quoted).
fn sep_line(line: &str) -> Option<u8> {
    let l = line.trim().trim_matches('"');
    let rest = l.get(..4).filter(|h| h.eq_ignore_ascii_case("sep="))?;
    let sep = &l.as_bytes()[rest.len()..];
    (sep.len() == 1).then(|| sep[0])
}

/// Text with no digit but in a power (`rad/s`, `m/s^2`, `%`): a unit, not a value.
fn unit_like(cell: &str) -> bool {
    let mut power = false;
    cell.chars().all(|ch| match ch {
        '^' => {
            power = true;
            true
        }
        '0'..='9' => power,
        '-' => true,
        _ => {
            power = false;
            true
        }
    })
}

/// The separator of a header line: the most frequent of `,`, `;` and tab (the header's names
/// hold none of them), `,` when none occurs.
fn detect(header: &str) -> u8 {
    [b',', b';', b'\t']
        .into_iter()
        .max_by_key(|&c| (header.bytes().filter(|&b| b == c).count(), c == b','))
        .unwrap_or(b',')
}

impl Sheet {
    /// Reads `path` (`what`: what the file is, for the errors).
    pub fn read(path: &Path, what: &str) -> Result<Self> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).with_context(|| format!("cannot read {what} {file}"))?;
        let Ok(text) = String::from_utf8(bytes) else {
            bail!(
                "{file}: {what} is not UTF-8 text: save it as \"CSV UTF-8\" from the spreadsheet"
            );
        };
        Self::parse(&text, file)
    }

    /// Reads the text of a file named `file`.
    pub fn parse(text: &str, file: String) -> Result<Self> {
        // A spreadsheet's UTF-8 export may start with a byte-order mark.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        // Lines end at LF, CRLF or a lone CR (an old Mac's files): `str::lines` would take a
        // whole CR file for its first line, and count the separators of every row.
        let mut lines = text.split(['\r', '\n']);
        let first = lines.next().unwrap_or("");
        // With `sep=X` the table starts on line 2.
        let (sep, body) = match sep_line(first) {
            Some(sep) => {
                let rest = &text[first.len()..];
                let rest = rest.strip_prefix("\r").unwrap_or(rest);
                (sep, rest.strip_prefix('\n').unwrap_or(rest))
            }
            None => {
                let header = std::iter::once(first)
                    .chain(lines)
                    .find(|l| !l.trim().is_empty())
                    .unwrap_or("");
                (detect(header), text)
            }
        };
        // Lines counted on the whole text, records placed by their byte offset (the reader's
        // own line count is one short after a CRLF file's first row).
        let lines = Lines::of(text.as_bytes());
        let skipped = (text.len() - body.len()) as u64;
        let line_at = |p: Option<&csv::Position>| {
            p.map_or(0, |p| {
                lines.record_line(text.as_bytes(), skipped + p.byte())
            })
        };
        let mut reader = csv::ReaderBuilder::new()
            .delimiter(sep)
            .has_headers(false)
            .flexible(true)
            .from_reader(body.as_bytes());
        let mut records = Vec::new();
        for rec in reader.records() {
            let rec = rec.map_err(|e| {
                let line = line_at(e.position());
                anyhow::anyhow!("{file}, line {line}: not readable as CSV ({e})")
            })?;
            let line = line_at(rec.position());
            let cells: Vec<String> = rec.iter().map(|c| c.trim().to_string()).collect();
            records.push((line, cells));
        }
        let mut records = records.into_iter();
        let Some((header_line, header)) = records.next() else {
            bail!("{file}: the file is empty (no header line)");
        };
        let columns: Vec<String> = header.iter().map(|h| h.to_lowercase()).collect();
        let names = header;
        for (i, c) in columns.iter().enumerate() {
            if let Some(j) = columns[..i].iter().position(|d| !c.is_empty() && d == c) {
                bail!(
                    "{file}, line {header_line}: columns {} and {} are both named {c} (names \
                     match whatever their case): keep one",
                    j + 1,
                    i + 1
                );
            }
        }
        // A row emptied in a spreadsheet comes back as separators only: not a row. Two files
        // pasted one under the other repeat the header: a name row, not a row of values.
        let repeats_header = |cells: &[String]| {
            cells.len() >= columns.len()
                && cells
                    .iter()
                    .zip(&columns)
                    .all(|(c, name)| c.eq_ignore_ascii_case(name))
        };
        // A spreadsheet's second header line, the units (`rad/s`, `m`, `s`) under the names:
        // the row right below the header with two or more cells and no digit but in a power
        // (`m/s^2`). A row of values always has digits (its run number).
        let units = |cells: &[String]| {
            cells.iter().filter(|c| !c.is_empty()).count() >= 2
                && cells.iter().all(|c| unit_like(c))
        };
        let mut records = records.peekable();
        records.next_if(|(_, cells)| units(cells));
        let rows = records
            .filter(|(_, cells)| cells.iter().any(|c| !c.is_empty()) && !repeats_header(cells))
            .collect();
        Ok(Self {
            file,
            sep,
            columns,
            names,
            header_line,
            rows,
        })
    }

    /// Refuses a header without one of `names`, listing every one missing.
    pub fn require(&self, names: &[&str], what: &str) -> Result<()> {
        let missing: Vec<&str> = names
            .iter()
            .copied()
            .filter(|n| self.index(n).is_none())
            .collect();
        if !missing.is_empty() {
            bail!(
                "{}: no column {} in the header (it has {}): {what} has the columns {}",
                self.file,
                missing.join(", "),
                self.columns.join(", "),
                names.join(", ")
            );
        }
        Ok(())
    }

    fn index(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }

    /// The separator found (`,`, `;` or a tab).
    pub fn sep(&self) -> u8 {
        self.sep
    }

    /// The line the header is on.
    pub fn header_line(&self) -> usize {
        self.header_line
    }

    /// The header's names as the file spells them (trimmed).
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The rows, each checked to have no more cells than the header names (spare empty cells,
    /// which spreadsheets add, are let through).
    pub fn rows(&self) -> impl Iterator<Item = Result<Cells<'_>>> {
        self.each_row().map(move |c| match c.too_wide() {
            Some(why) => bail!("{}, line {}: {why}", self.file, c.line),
            None => Ok(c),
        })
    }

    /// The rows unchecked, for a reader that reports each bad row and goes on.
    pub fn each_row(&self) -> impl Iterator<Item = Cells<'_>> {
        self.rows.iter().map(move |(line, cells)| Cells {
            sheet: self,
            line: *line,
            cells,
        })
    }
}

impl Cells<'_> {
    /// Why the row has more cells than the header has names (spare empty cells, which
    /// spreadsheets add, are not counted), in words; `None` when it has not.
    pub fn too_wide(&self) -> Option<String> {
        let (cells, width) = (self.cells, self.sheet.columns.len());
        if cells[width.min(cells.len())..].iter().all(String::is_empty) {
            return None;
        }
        let hint = if self.sheet.sep == b',' {
            " (a decimal comma in a ,-separated file splits a number in two: use a decimal \
             point, or a ;-separated file)"
        } else {
            ""
        };
        Some(format!(
            "{} cells, but the header names {width} columns{hint}",
            cells.len()
        ))
    }

    /// The row's trimmed cells, in the header's order (fewer than the header's names when the
    /// row ends early).
    pub fn cells(&self) -> &[String] {
        self.cells
    }

    /// The trimmed cell of column `name` (empty where the column or the cell is absent).
    pub fn text(&self, name: &str) -> &str {
        self.sheet
            .index(name)
            .and_then(|i| self.cells.get(i))
            .map_or("", String::as_str)
    }

    /// An error on this row's cell of `name`.
    fn refuse(&self, name: &str, what: &str) -> anyhow::Error {
        anyhow::anyhow!(
            "{}, line {}, column {name}: {what}",
            self.sheet.file,
            self.line
        )
    }

    /// A cell that must not be empty.
    pub fn needed(&self, name: &str) -> Result<&str> {
        match self.text(name) {
            "" => Err(self.refuse(name, "empty (a value is needed here)")),
            s => Ok(s),
        }
    }

    /// A number, or `None` for an empty cell. In a file separated by `;` or tabs a decimal
    /// comma is a decimal point (the separator cannot be a comma there).
    pub fn number_or_empty(&self, name: &str) -> Result<Option<f64>> {
        self.read_number(name)
            .map_err(|why| self.refuse(name, &why))
    }

    /// As [`Self::number_or_empty`], the error being only why the cell is not a number (for a
    /// reader that names the file and line its own way).
    pub fn read_number(&self, name: &str) -> std::result::Result<Option<f64>, String> {
        let cell = self.text(name);
        if cell.is_empty() {
            return Ok(None);
        }
        let decimal_comma = self.sheet.sep != b',' && !cell.contains('.');
        let read = if decimal_comma {
            cell.replacen(',', ".", 1).parse::<f64>()
        } else {
            cell.parse::<f64>()
        };
        read.map(Some).map_err(|_| {
            let hint = if self.sheet.sep == b',' && cell.contains(',') {
                "use a decimal point, or a ;-separated file"
            } else {
                "a number such as 1.07 (or 1,07 in a ;-separated file), without thousands \
                 separators or units"
            };
            format!("\"{cell}\" is not a number ({hint})")
        })
    }

    /// A number that must be there.
    pub fn number(&self, name: &str) -> Result<f64> {
        self.number_or_empty(name)?
            .ok_or_else(|| self.refuse(name, "empty (a number is needed here)"))
    }

    /// A whole number 0 or more that must be there.
    pub fn whole(&self, name: &str) -> Result<usize> {
        let cell = self.needed(name)?;
        cell.parse::<usize>().map_err(|_| {
            self.refuse(
                name,
                &format!("\"{cell}\" is not a whole number (a count: 1, 2, 3 ...)"),
            )
        })
    }
}

#[cfg(test)]
mod tests {
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
}
