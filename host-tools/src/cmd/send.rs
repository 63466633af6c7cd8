//! `bowl send PORT COMMAND ...`: send one command, print the rig's answer. Exit status as in
//! `exit_code`: 0 done, 1 refused (by the rig or the local check), 3 link problem, 4 no answer.

use std::time::Duration;

use anyhow::Result;
use model_core::wire::{Frame, split_words};
use rig_client::command_words::local_refusal;
use rig_client::lines::{command_line, describe, explain};
use rig_client::link::Link;
use rig_client::refusal;
use rig_client::request::transact;
use rig_client::watchdog;

use crate::exit_code;

/// Flags of `bowl send`.
#[derive(clap::Args)]
pub struct Args {
    /// The serial port or pseudo-terminal of the rig.
    port: String,
    /// The command and its arguments, e.g. `speed 1800 2100` (precession and spin, mrad/s),
    /// `rtime cori 2500` (a residence time, ms), `start`, `stop`, `clear`, `set MU_PPM 29000`,
    /// `status`, `params`, `models`, `commission`, `inject sensor2` (see docs/protocol.md). Whole
    /// numbers in the unit the name or the protocol gives (mrad/s, ms, ppm). A negative number is
    /// a value, judged by the protocol's rules.
    #[arg(required = true, num_args = 1.., allow_negative_numbers = true)]
    command: Vec<String>,
    /// Baud rate.
    #[arg(long, default_value_t = 115_200, value_parser = clap::value_parser!(u32).range(50..=12_000_000))]
    baud: u32,
    /// Request id echoed by the rig (default: a fresh one from the clock; leave it out unless
    /// you resend). The same id with the same words within 60 s is a resend to the rig: it
    /// answers again ("ok") but does not do it again, even with other commands in between, and
    /// its answer is the same either way, so `bowl send` cannot tell you. Give each new
    /// command a new id. 1 to 65533: 0 is the id of the rig's answers to a line typed at its
    /// console, 65534 and 65535 are the monitor's own.
    #[arg(long, value_parser = own_id)]
    id: Option<u16>,
    /// How long to wait for the answer, ms (1..=60000: the rig remembers a command for 60 s to
    /// know its copies, so resends must end before that).
    #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u64).range(1..=60_000))]
    timeout_ms: u64,
}

/// The `--id` flag: an id no one else's answer comes with. With 0, the rig's `UNREADABLE` to a
/// frame of this very command that lost its `$` was taken for the command's refusal; with
/// 65535, the monitor's heartbeat's ack for this command's.
fn own_id(text: &str) -> Result<u16, String> {
    let id: u16 = text.trim().parse().map_err(|_| {
        format!("`{text}` is not a request id: give a whole number from 1 to 65533")
    })?;
    match id {
        0 => Err(
            "0 is the id the rig gives its answers to lines typed at its console (and to \
                  damaged ones), which would pass for this command's: give 1 to 65533"
                .into(),
        ),
        65_534.. => Err(format!(
            "{id} is the id of `bowl monitor`'s own commands (its heartbeat, its status), whose \
             answers would pass for this command's: give 1 to 65533"
        )),
        id => Ok(id),
    }
}

/// Runs `bowl send`; returns the process exit status.
pub fn run(args: &Args) -> Result<i32> {
    let id = args.id.unwrap_or_else(rig_client::request::fresh_id);
    // The words as the rig's console reads them (one reader: the refusal's particulars pick
    // the values by position).
    let words: Vec<String> = split_words(&args.command).map(str::to_owned).collect();
    let line = match command_line(id, &words) {
        Ok(line) => line,
        Err(reason) => {
            // A command line that cannot be right on any rig: a usage error, said in words.
            println!(
                "rejected locally: {} - {} (not sent)",
                reason.token(),
                explain(reason)
            );
            println!("  {}", local_refusal(&words, reason));
            return Ok(exit_code::USAGE);
        }
    };
    let mut link = Link::open(&args.port, args.baud)?;
    let timeout = Duration::from_millis(args.timeout_ms);
    match transact(&mut link, id, &line, timeout)? {
        Ok(frame) => {
            println!("{}", describe(&frame));
            if !matches!(frame, Frame::Reject { .. })
                && watchdog::starts_motors(&words)
                && let Some(note) = watchdog::note(&mut link, &args.port, id, timeout)
            {
                println!("{note}");
            }
            if let Frame::Reject { reason, .. } = frame
                && let Some(why) =
                    refusal::particulars(Some(&mut link), id, &words, reason, timeout)
            {
                println!("  {}", refusal::on_port(&why, &args.port));
            }
            Ok(if matches!(frame, Frame::Reject { .. }) {
                exit_code::REFUSED
            } else {
                exit_code::OK
            })
        }
        Err(unanswered) => {
            println!(
                "timeout: no answer to id {id} within {} ms ({})",
                args.timeout_ms,
                unanswered.advice()
            );
            Ok(exit_code::TIMEOUT)
        }
    }
}
