//! The charts (docs/model.md section 6): the speed-against-accuracy chart and the paper-style
//! figures, each a figure ([`plot`]) and the numbers behind it ([`table`]); `bowl chart` draws
//! them (host-tools/src/cmd/chart.rs).

use std::path::{Path, PathBuf};

pub mod bowl;
pub mod chooser;
pub mod control;
pub mod costs;
pub mod error_table;
pub mod family;
pub mod figures;
pub mod hierarchy;
pub mod log;
pub mod plot;
pub mod qemu_log;
pub mod reference;
#[cfg(test)]
mod reference_check;
pub mod rolling;
pub mod scipy;
pub mod stability;
pub mod table;
pub mod timing;
pub mod workprec;

/// `FILE.svg` -> `FILE-suffix.svg`.
pub fn suffixed(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!("{stem}-{suffix}.svg"))
}

/// One line to standard output for the reader's information. The files are a chart's product:
/// a reader that went away (`bowl chart ... | head -1`) must not stop the ones still to be
/// written, so a closed pipe only ends what is said (`bowl chart` ignores SIGPIPE).
pub fn say(line: &str) {
    use std::io::Write;
    if let Err(e) = writeln!(std::io::stdout(), "{line}")
        && e.kind() != std::io::ErrorKind::BrokenPipe
    {
        eprintln!("warning: writing to standard output: {e}");
    }
}
