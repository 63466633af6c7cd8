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
        // A line whose first cell starts with `#` is a comment (a note typed between runs):
        // it stopped the fit as `column run: empty`.
        let comment = |cells: &[String]| {
            cells
                .iter()
                .find(|c| !c.is_empty())
                .is_some_and(|c| c.starts_with('#'))
        };
        let rows = records
            .filter(|(_, cells)| {
                cells.iter().any(|c| !c.is_empty()) && !repeats_header(cells) && !comment(cells)
            })
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

    /// An error on this row's cell of `name`; on a row that holds one text and nothing else,
    /// the row's own: a note typed on a line of its own is not a row of values (it was refused
    /// as `column run: empty`, the note unmentioned).
    fn refuse(&self, name: &str, what: &str) -> anyhow::Error {
        let mut given = self.cells.iter().enumerate().filter(|(_, c)| !c.is_empty());
        if let (Some((i, note)), None) = (given.next(), given.next())
            && note.replacen(',', ".", 1).parse::<f64>().is_err()
        {
            let column = self.sheet.names.get(i).map_or("", String::as_str);
            return anyhow::anyhow!(
                "{}, line {}: holds only the text `{note}` (in column {}, {column}) and no other \
                 value: a note? start the line with # (such lines are skipped), or delete it",
                self.sheet.file,
                self.line,
                i + 1
            );
        }
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
mod tests;
