//! One module per subcommand: its flags (clap) and `run`, over the libraries.

pub mod chart;
pub mod commission;
pub mod experiment;
pub mod fit;
pub mod kinematics;
pub mod ports;
pub mod predict;
pub mod replay;
pub mod send;
pub mod serve;
pub mod sim;

/// The parser of every number flag: clap's own read `1e400` as infinity and `1e-400` as 0,
/// which the checks after it then echoed as "inf rad/s" (refused as if negative) or took as a
/// real 0; and it said "invalid float literal" for a value typed with its unit.
pub fn number(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let example = "a decimal number such as 0.05, 3.6 or 2.5e-3 (a decimal point, no unit)";
    let x: f64 = t
        .parse()
        .map_err(|_| format!("`{t}` is not a number: give {example}"))?;
    if x.is_nan() {
        return Err(format!("`{t}` is not a number: give {example}"));
    }
    if x.is_infinite() {
        return Err(format!(
            "{t} is out of range: a number here is finite, less than about 1.8e308 in size"
        ));
    }
    let mantissa = t.split(['e', 'E']).next().unwrap_or(t);
    if x == 0.0 && mantissa.bytes().any(|b| (b'1'..=b'9').contains(&b)) {
        return Err(format!(
            "{t} is out of range: too small to tell from 0 (the smallest size is about \
             5e-324): give 0 if 0 is meant"
        ));
    }
    Ok(x)
}

/// [`number`] for a flag kept in `f32` (the controller's and the simulated plant's precision):
/// beyond `f32` it would turn to infinity or 0 just the same.
pub fn number32(text: &str) -> Result<f32, String> {
    let x = number(text)?;
    let t = text.trim();
    let narrow = x as f32;
    if narrow.is_infinite() {
        return Err(format!(
            "{t} is out of range: a number here is less than about 3.4e38 in size"
        ));
    }
    if narrow == 0.0 && x != 0.0 {
        return Err(format!(
            "{t} is out of range: too small to tell from 0 here (the smallest size is about \
             1e-45): give 0 if 0 is meant"
        ));
    }
    Ok(narrow)
}

/// The parser of every flag naming a file to write (`--out`, `--csv`, `--log`): a directory
/// there was taken as a stem, `bowl chart radial --out /tmp/charts` writing /tmp/charts.svg,
/// .png and .csv beside the directory without a word (or failing late with the system's "Is a
/// directory"); now refused before any work, as a usage error.
pub fn file_to_write(text: &str) -> Result<std::path::PathBuf, String> {
    let path = std::path::PathBuf::from(text);
    if path.is_dir() || text.ends_with(std::path::is_separator) {
        let name = text.trim_end_matches(std::path::is_separator);
        return Err(format!(
            "{text} is a directory: give the name of a file to write, in it or beside it \
             (such as {name}/run.svg for a chart, {name}/run.csv for a table)"
        ));
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::{file_to_write, number, number32};

    #[test]
    fn a_directory_is_no_file_to_write() {
        let dir = std::env::temp_dir();
        let d = dir.to_str().unwrap();
        let e = file_to_write(d).unwrap_err();
        assert!(e.starts_with(&format!("{d} is a directory")), "{e}");
        assert!(
            file_to_write("new-folder/")
                .unwrap_err()
                .contains("is a directory")
        );
        let file = dir.join("qa-no-such-chart.svg");
        assert_eq!(file_to_write(file.to_str().unwrap()), Ok(file));
    }

    #[test]
    fn numbers_out_of_range_are_refused_in_words() {
        assert_eq!(number("3.6"), Ok(3.6));
        assert_eq!(number("-0.5e-3"), Ok(-0.0005));
        assert_eq!(number("0e-999"), Ok(0.0));
        assert_eq!(number("1e30"), Ok(1e30));
        let e = number("1e400").unwrap_err();
        assert!(
            e.starts_with("1e400 is out of range: a number here is finite"),
            "{e}"
        );
        assert!(number("-inf").unwrap_err().contains("out of range"));
        let e = number("1e-400").unwrap_err();
        assert!(e.contains("too small to tell from 0"), "{e}");
        let e = number("NaN").unwrap_err();
        assert!(e.starts_with("`NaN` is not a number"), "{e}");
        let e = number("0.02 kg").unwrap_err();
        assert!(
            e.starts_with("`0.02 kg` is not a number") && e.contains("no unit"),
            "{e}"
        );
        assert_eq!(number32("3.5"), Ok(3.5));
        assert!(
            number32("1e39")
                .unwrap_err()
                .starts_with("1e39 is out of range")
        );
        assert!(number32("1e-50").unwrap_err().contains("too small"));
        assert!(
            number32("1e400")
                .unwrap_err()
                .starts_with("1e400 is out of range")
        );
    }
}
