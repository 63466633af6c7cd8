//! `bowl serve`: the virtual rig on a pseudo-terminal speaking the protocol in real time
//! (`--pty`), or a capture file written faster than real time with exactly the bytes the rig
//! would send (`--capture FILE --seconds S`).

#[cfg(unix)]
use std::io::Write;
use std::path::PathBuf;
#[cfg(unix)]
use std::time::Duration;

use anyhow::{Context, Result, bail};
use rig_client::command_words;
use rig_client::lines::{command_line, explain};
use virtual_rig::VirtualRig;
#[cfg(unix)]
use virtual_rig::serve::{Backlog, Pacing, Pty, serve_on_pty};
use virtual_rig::serve::{LineNoise, Scheduled, capture, check_seconds};

use crate::exit_code::usage;

/// Flags of `bowl serve`.
#[derive(clap::Args)]
pub struct Args {
    /// Serve the virtual rig on a new pseudo-terminal; its path is printed on the first line.
    #[arg(long, conflicts_with = "capture")]
    pty: bool,
    /// Also make this symlink point at the pseudo-terminal (a link already there is replaced;
    /// removed at the end unless another `serve --link` took it over meanwhile).
    #[arg(long, requires = "pty")]
    link: Option<PathBuf>,
    /// Run faster than real time and write the rig's output bytes to this file.
    #[arg(long, requires = "seconds", value_parser = crate::cmd::file_to_write)]
    capture: Option<PathBuf>,
    /// Simulated seconds to run (with --pty: stop after this many real seconds).
    #[arg(long, value_parser = crate::cmd::number)]
    seconds: Option<f64>,
    /// Commands fed to the rig as if from the PC, `AT_MS:WORDS` (AT_MS: the device time to send
    /// it, ms; WORDS: as `bowl send` takes them, commas or spaces between), e.g. `0:speed,1800,2100`
    /// (mrad/s) `0:start` `5000:inject,sensor2` (repeatable; the answers appear in the output).
    #[arg(long = "command", value_name = "AT_MS:WORDS")]
    commands: Vec<String>,
    /// Seed of the simulated plant's noise (and of the line noise).
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Serve this rig instead of the nominal one: a rig file (docs/rigs/*.toml, keys in
    /// docs/rigs/nominal.toml); its own `seed` key then seeds the plant's tooth offsets and jitter,
    /// its `[particle]` table the granules RELEASE drops. The virtual rig commissions itself on
    /// it before it answers.
    #[arg(long, value_name = "RIG.toml")]
    rig_file: Option<PathBuf>,
    /// A noisy line: this percentage of the bytes sent is replaced by a different random byte
    /// (what the PC receives, to try the decoder and the counters).
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 0.0)]
    line_noise_percent: f64,
}

/// The `--command AT_MS:WORDS` flags, judged before the rig starts (usage errors in the words
/// `bowl send` gives), in time order. `run_ms`: the run's length, when it has one; a command
/// due at or after its end would never be sent.
fn parse_commands(specs: &[String], run_ms: Option<f64>) -> Result<Vec<Scheduled>> {
    let mut out = Vec::new();
    for (i, spec) in specs.iter().enumerate() {
        let (at, words) = spec.split_once(':').ok_or_else(|| {
            usage(format!(
                "--command {spec}: expected AT_MS:WORDS, the device time in ms, a colon, then the \
                 command's words separated by commas or spaces (e.g. 0:speed,1800,2100)"
            ))
        })?;
        let at_ms: u32 = at.parse().map_err(|_| {
            usage(format!(
                "--command {spec}: `{at}` is not a time: give whole milliseconds from the rig's \
                 start, 0 to {} (e.g. 5000:start)",
                u32::MAX
            ))
        })?;
        // The words as `bowl send` and the rig's console read them: commas or spaces.
        let split: Vec<String> = model_core::wire::split_words(&[words])
            .map(str::to_owned)
            .collect();
        let id = u16::try_from(i + 1).unwrap_or(u16::MAX);
        let line = command_line(id, &split).map_err(|reason| {
            usage(format!(
                "--command {spec}: rejected locally: {} - {}: {}",
                reason.token(),
                explain(reason),
                command_words::local_refusal(&split, reason)
            ))
        })?;
        if let Some(run_ms) = run_ms
            && f64::from(at_ms) >= run_ms
        {
            return Err(usage(format!(
                "--command {spec}: due at {at_ms} ms, but the run ends at {run_ms} ms (--seconds \
                 {}): it would never be sent; give a time before the end or a longer --seconds",
                run_ms / 1000.0
            )));
        }
        out.push(Scheduled { at_ms, line });
    }
    out.sort_by_key(|s| s.at_ms);
    Ok(out)
}

/// Runs `bowl serve`.
pub fn run(args: &Args) -> Result<()> {
    // Every flag and the rig file are judged before anything starts (or a pty path is printed
    // that a script would take for a running rig).
    if let Some(seconds) = args.seconds {
        check_seconds(seconds).map_err(usage)?;
    }
    let commands = parse_commands(&args.commands, args.seconds.map(|s| s * 1000.0))?;
    let noise = LineNoise::new(args.line_noise_percent, args.seed).map_err(usage)?;
    let new_rig = || match &args.rig_file {
        None => VirtualRig::new(args.seed),
        Some(path) => {
            let rigs = rig_file::load(path)?;
            let [rig] = rigs.as_slice() else {
                bail!(
                    "{} holds {} rigs ([[plant]] tables); bowl serve runs one: give a rig file \
                     with one rig",
                    path.display(),
                    rigs.len()
                );
            };
            VirtualRig::with_plant(rig.params, rig.particle.unwrap_or_default(), rig.seed)
                .with_context(|| format!("the rig in {}", path.display()))
        }
    };
    if !args.pty && args.capture.is_none() {
        return Err(usage(
            "say --pty (serve on a pseudo-terminal) or --capture FILE --seconds S (write to a file)",
        ));
    }
    let rig = new_rig()?;
    if let Some(path) = &args.capture {
        let seconds = args.seconds.unwrap_or(0.0);
        return capture(path, seconds, commands, rig, noise);
    }
    #[cfg(not(unix))]
    if args.pty {
        bail!(
            "--pty needs a Unix system (Linux, macOS); on Windows use --capture FILE --seconds S"
        );
    }
    #[cfg(unix)]
    if args.pty {
        // Ctrl-C or a `kill` ends the serving loop, so the `--link` below is removed rather
        // than left pointing at a pseudo-terminal that is gone (or soon another program's).
        // Installed before the path is printed: a script may signal as soon as it reads it.
        let interrupted = crate::interrupt::flag();
        let pty = Pty::open()?;
        let pty_path = pty.path.clone();
        if let Some(link) = &args.link {
            make_link(link, &pty_path)?;
        }
        println!("{}", pty.path);
        std::io::stdout().flush()?;
        let served = serve_on_pty(
            pty,
            rig,
            Pacing {
                device_ms_per_wall_ms: 1.0,
                stop: interrupted,
                stop_after: args.seconds.map(Duration::from_secs_f64),
                backlog: Backlog::DropWhenUnread,
            },
            commands,
            noise,
        );
        if let Some(link) = &args.link {
            remove_link(link, &pty_path);
        }
        return served.map(|_| ());
    }
    Ok(())
}

/// Points `link` at `pty`. A link already there is replaced (a rig served before, gone or
/// not); anything else is refused untouched: `--link notes.txt` must not delete a file.
#[cfg(unix)]
fn make_link(link: &std::path::Path, pty: &str) -> Result<()> {
    if let Ok(meta) = std::fs::symlink_metadata(link) {
        if !meta.file_type().is_symlink() {
            return Err(crate::exit_code::usage(format!(
                "--link {}: the path exists and is not a symlink, so it was left as it is; give \
                 a new path for the link (e.g. /tmp/rig)",
                link.display()
            )));
        }
        std::fs::remove_file(link)
            .with_context(|| format!("cannot replace the link {}", link.display()))?;
    }
    std::os::unix::fs::symlink(pty, link)
        .with_context(|| format!("cannot link {} to {pty}", link.display()))
}

/// Removes `link` at the end if it still points at `pty`: another `serve --link` of the same
/// path took it over meanwhile, and its rig is still there.
#[cfg(unix)]
fn remove_link(link: &std::path::Path, pty: &str) {
    if std::fs::read_link(link).is_ok_and(|to| to == std::path::Path::new(pty)) {
        let _ = std::fs::remove_file(link);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scheduled_commands_run_in_time_order_and_bad_ones_are_named() {
        let specs = ["5000:start".to_string(), "0:speed,1800,2100".to_string()];
        let cmds = parse_commands(&specs, None).unwrap();
        assert_eq!(cmds.iter().map(|c| c.at_ms).collect::<Vec<_>>(), [0, 5000]);
        let first = String::from_utf8(cmds[0].line.clone()).unwrap();
        assert!(first.contains("SPEED"), "{first}");
        for bad in ["start", "soon:start"] {
            let err = parse_commands(&[bad.to_string()], None)
                .err()
                .expect("refused");
            assert!(format!("{err:#}").contains(bad), "{err:#}");
        }
    }
}
