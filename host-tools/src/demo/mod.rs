//! `bowl demo`: the rig without hardware. A simulated rig running the controller (on the
//! emulated board when QEMU and its image are available, otherwise on the host) is driven
//! through the real serial protocol by a scripted session while the live monitor view runs;
//! at the end a summary (JSON and text), the telemetry CSV and charts go to `--out`.

mod analysis;
mod charts;
mod endpoint;
mod frames;
mod physics_check;
mod render;
mod report;
mod script;
mod session;
mod step_response;

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};

use endpoint::{Endpoint, RigChoice};

/// Flags of `bowl demo`.
#[derive(clap::Args)]
pub struct Args {
    /// Length of the scripted session in device seconds (real seconds unless --fast).
    #[arg(long, default_value_t = script::NOMINAL_SECONDS)]
    seconds: f64,
    /// Run the rig faster than real time (for tests and CI).
    #[arg(long)]
    fast: bool,
    /// Output directory for summary.json, telemetry.csv and the charts.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
    /// Which rig to drive.
    #[arg(long, value_enum, default_value_t = RigChoice::Auto)]
    rig: RigChoice,
    /// Plain lines instead of the live dashboard (automatic when stdout is not a terminal).
    #[arg(long)]
    plain: bool,
    /// Seed of the simulated plant's noise (host rig).
    #[arg(long, default_value_t = 1)]
    seed: u32,
}

/// Runs `bowl demo`: its exit code (0, or 130 when Ctrl-C ended it with the motors stopped).
pub fn run(args: &Args) -> Result<i32> {
    if !(args.seconds.is_finite() && (10.0..=3600.0).contains(&args.seconds)) {
        bail!("--seconds must be between 10 and 3600 (the steps need time to settle)");
    }
    let plain = args.plain || !std::io::stdout().is_terminal();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let started = Instant::now();
    // Ctrl-C (or SIGTERM) ends the session with the motors stopped, and the run so far is
    // still summarised and charted (before, the process died where it stood: a telemetry.csv
    // cut mid-row beside an earlier run's summary and charts, a chart cut at 0 bytes).
    let interrupt = crate::interrupt::flag();

    let rig = Endpoint::start(args.rig, args.fast, args.seed, args.seconds)?;
    // Ctrl-C while the rig started (the emulated board boots for seconds): nothing was sent.
    if interrupt.load(std::sync::atomic::Ordering::SeqCst) {
        let _ = rig.shutdown();
        eprintln!("bowl demo: interrupted (Ctrl-C) before the session began: nothing was sent");
        return Ok(crate::exit_code::INTERRUPTED);
    }
    println!("bowl demo: {}", rig.description);
    if let Some(why) = &rig.qemu_note {
        println!("bowl demo: not on the emulated board: {why}; using the host rig");
    }
    println!(
        "bowl demo: a {:.0} s scripted session over the serial protocol; output in {}",
        args.seconds,
        args.out.display()
    );

    let csv_path = args.out.join("telemetry.csv");
    let label = format!("demo [{} rig]  {}", rig.kind, rig.port);
    let session = session::Session::open(&rig.port, label, plain, &csv_path, interrupt);
    let mut session = match session {
        Ok(s) => s,
        Err(e) => {
            let _ = rig.shutdown();
            return Err(e);
        }
    };
    let timing = script::Timing::for_seconds(args.seconds, rig.device_per_wall);
    let boot_limit = std::time::Duration::from_secs(if rig.kind == "host" { 10 } else { 60 });
    let mut rig = rig;
    let outcome = match session.wait_first_telemetry(boot_limit) {
        Ok(()) => match rig.injector() {
            Some(mut inject) => script::run(&mut session, timing, Some(&mut inject)),
            None => script::run(&mut session, timing, None),
        },
        Err(e) => script::Outcome {
            marks: Vec::new(),
            params: None,
            aborted: Some(format!("{e:#}")),
        },
    };
    let (record, stats) = session.finish()?;
    let kind = rig.kind.to_string();
    let description = rig.description.clone();
    let qemu_note = rig.qemu_note.clone();
    let shutdown = rig.shutdown()?;
    let host_bytes_dropped = shutdown.host.map_or(0, |h| h.bytes_dropped);
    let console_from = shutdown.console.len().saturating_sub(10);
    let board_console = shutdown.console[console_from..].to_vec();
    if outcome.aborted.is_some() && !board_console.is_empty() {
        println!("the emulated board's console, last lines:");
        for line in &board_console {
            println!("  {line}");
        }
    }

    if !plain {
        println!("\nsession log:");
        for line in &record.log {
            println!("  {line}");
        }
    }
    let summary = analysis::summarise(
        report::RunInfo {
            rig: kind,
            description,
            qemu_note,
            fast: args.fast,
            wall_s: started.elapsed().as_secs_f64(),
            aborted: outcome.aborted.clone(),
            board_console,
            host_bytes_dropped,
        },
        &record.telemetry,
        &outcome.marks,
        outcome.params.as_ref(),
        &stats,
        record.commands.clone(),
    );
    print!("{}", render::text(&summary));
    let json_path = args.out.join("summary.json");
    std::fs::write(&json_path, serde_json::to_string_pretty(&summary)?)
        .with_context(|| format!("cannot write {}", json_path.display()))?;
    let mut files = vec![json_path, csv_path];
    if record.telemetry.is_empty() {
        println!("no telemetry: no charts");
    } else {
        let (written, skipped) = charts::write(&args.out, &record.telemetry, &outcome.marks)?;
        files.extend(written);
        for why in skipped {
            println!("chart left out: {why}");
        }
    }
    println!("written:");
    for f in &files {
        println!("  {}", f.display());
    }
    if interrupt.load(std::sync::atomic::Ordering::SeqCst) {
        let why = outcome
            .aborted
            .as_deref()
            .unwrap_or("interrupted (Ctrl-C) while the summary and charts were written");
        eprintln!("bowl demo: {why}; the summary and charts above are of the run up to there");
        return Ok(crate::exit_code::INTERRUPTED);
    }
    if let Some(why) = &outcome.aborted {
        bail!("the session ended early: {why}");
    }
    // A demo that did not show what it should is a failure a script can see, not just a line.
    let c = &summary.checks;
    let failed: Vec<&str> = [
        (c.speeds_tracked, "speeds tracked"),
        (c.fault_stopped_both_motors, "fault stopped both motors"),
        (c.residence_split_agrees, "residence split agrees"),
        (c.link_clean, "link clean"),
        (summary.ended_at_rest, "ended at rest"),
    ]
    .into_iter()
    .filter_map(|(ok, name)| (!ok).then_some(name))
    .collect();
    if !failed.is_empty() {
        bail!("the demo's checks failed: {}", failed.join(", "));
    }
    Ok(crate::exit_code::OK)
}
