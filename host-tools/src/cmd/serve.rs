//! `bowl serve`: the virtual rig on a pseudo-terminal speaking the protocol in real time
//! (`--pty`), or a capture file written faster than real time with exactly the bytes the rig
//! would send (`--capture FILE --seconds S`).

#[cfg(unix)]
use std::io::Write;
use std::path::PathBuf;
#[cfg(unix)]
use std::sync::atomic::AtomicBool;
#[cfg(unix)]
use std::time::Duration;

use anyhow::{Context, Result, bail};
use rig_client::lines::command_line;
use virtual_rig::VirtualRig;
#[cfg(unix)]
use virtual_rig::serve::{Backlog, Pacing, Pty, serve_on_pty};
use virtual_rig::serve::{LineNoise, Scheduled, capture};

/// Flags of `bowl serve`.
#[derive(clap::Args)]
pub struct Args {
    /// Serve the virtual rig on a new pseudo-terminal; its path is printed on the first line.
    #[arg(long, conflicts_with = "capture")]
    pty: bool,
    /// Also make this symlink point at the pseudo-terminal (replaced if it exists).
    #[arg(long, requires = "pty")]
    link: Option<PathBuf>,
    /// Run faster than real time and write the rig's output bytes to this file.
    #[arg(long, requires = "seconds")]
    capture: Option<PathBuf>,
    /// Simulated seconds to run (with --pty: stop after this many real seconds).
    #[arg(long)]
    seconds: Option<f64>,
    /// Commands fed to the rig as if from the PC, `AT_MS:WORDS`, e.g. `0:speed,1800,2100`
    /// `0:start` `5000:inject,sensor2` (repeatable; the answers appear in the output).
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
    /// (what the PC receives, to try the decoder and the counters; default 0).
    #[arg(long, default_value_t = 0.0)]
    line_noise_percent: f64,
}

fn parse_commands(specs: &[String]) -> Result<Vec<Scheduled>> {
    let mut out = Vec::new();
    for (i, spec) in specs.iter().enumerate() {
        let (at, words) = spec
            .split_once(':')
            .with_context(|| format!("--command {spec}: expected AT_MS:WORDS"))?;
        let at_ms: u32 = at
            .parse()
            .with_context(|| format!("--command {spec}: bad time"))?;
        let id = u16::try_from(i + 1).unwrap_or(u16::MAX);
        let line = command_line(id, &[words.to_string()])
            .map_err(|r| anyhow::anyhow!("--command {spec}: rejected locally ({})", r.token()))?;
        out.push(Scheduled { at_ms, line });
    }
    out.sort_by_key(|s| s.at_ms);
    Ok(out)
}

/// Runs `bowl serve`.
pub fn run(args: &Args) -> Result<()> {
    let commands = parse_commands(&args.commands)?;
    let noise = LineNoise::new(args.line_noise_percent, args.seed)?;
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
    if let Some(path) = &args.capture {
        let seconds = args.seconds.unwrap_or(0.0);
        return capture(path, seconds, commands, new_rig()?, noise);
    }
    #[cfg(not(unix))]
    if args.pty {
        bail!(
            "--pty needs a Unix system (Linux, macOS); on Windows use --capture FILE --seconds S"
        );
    }
    #[cfg(unix)]
    if args.pty {
        let pty = Pty::open()?;
        if let Some(link) = &args.link {
            let _ = std::fs::remove_file(link);
            std::os::unix::fs::symlink(&pty.path, link)
                .with_context(|| format!("cannot link {} to {}", link.display(), pty.path))?;
        }
        println!("{}", pty.path);
        std::io::stdout().flush()?;
        let never = AtomicBool::new(false);
        let served = serve_on_pty(
            pty,
            new_rig()?,
            Pacing {
                device_ms_per_wall_ms: 1.0,
                stop: &never,
                stop_after: args.seconds.map(Duration::from_secs_f64),
                backlog: Backlog::DropWhenUnread,
            },
            commands,
            noise,
        );
        if let Some(link) = &args.link {
            let _ = std::fs::remove_file(link);
        }
        return served.map(|_| ());
    }
    bail!("say --pty (serve on a pseudo-terminal) or --capture FILE --seconds S (write to a file)")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scheduled_commands_run_in_time_order_and_bad_ones_are_named() {
        let specs = ["5000:start".to_string(), "0:speed,1800,2100".to_string()];
        let cmds = parse_commands(&specs).unwrap();
        assert_eq!(cmds.iter().map(|c| c.at_ms).collect::<Vec<_>>(), [0, 5000]);
        let first = String::from_utf8(cmds[0].line.clone()).unwrap();
        assert!(first.contains("SPEED"), "{first}");
        for bad in ["start", "soon:start"] {
            let err = parse_commands(&[bad.to_string()]).err().expect("refused");
            assert!(format!("{err:#}").contains(bad), "{err:#}");
        }
    }
}
