//! `bowl commission PORT`: run the motor identification on the rig from the PC.
//!
//! Sends COMMISSION, follows the rig's telemetry (or, if the rig sends none, polls STATUS) until
//! the state leaves "commissioning", then asks MODELS and PARAMS and prints the identified motor
//! models and the speed-loop gains that follow from them, as text or `--json`.
//!
//! Exit status (`exit_code`): 0 done, 1 the rig refused COMMISSION (the reason and its
//! particulars are printed), commissioning ended in a fault (the rig's fault code is printed;
//! the motors are off), the rig reset meanwhile or it went idle with the very models it had
//! before (a STOP from another console: nothing was identified), 3 the link failed, 4 no answer or
//! commissioning did not end within `--timeout-s`, 130 Ctrl-C or SIGTERM (STOP sent first).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use model_core::wire::{AxisModel, DeviceState, FaultCode, Frame, ParamId, ParamValues, Reason};
use rig_client::lines::explain;
use rig_client::rig::{NoAnswer, Reply, Rig};
use serde::Serialize;

use crate::exit_code;

/// How long one command waits for its answer.
const ANSWER_TIMEOUT: Duration = Duration::from_millis(1000);
/// Without telemetry for this long, the state is polled with STATUS.
const POLL_AFTER: Duration = Duration::from_millis(500);

/// Flags of `bowl commission`.
#[derive(clap::Args)]
pub struct Args {
    /// The serial port or pseudo-terminal of the rig.
    port: String,
    /// Baud rate.
    #[arg(long, default_value_t = 115_200, value_parser = clap::value_parser!(u32).range(50..=12_000_000))]
    baud: u32,
    /// Give up when commissioning has not ended after this many seconds (the rig's own routine
    /// faults after 120 s).
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 180.0)]
    timeout_s: f64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// One axis's result, in SI units.
#[derive(Serialize)]
struct AxisReport {
    axis: &'static str,
    /// Identified by this run (false: the rig kept its stored or nominal model).
    identified: bool,
    back_emf_v_per_rad_s: f64,
    friction_duty: f64,
    time_constant_s: f64,
    /// The speed loop's bandwidth, from the rig's parameters (PARAMS).
    #[serde(skip_serializing_if = "Option::is_none")]
    bandwidth_rad_s: Option<f64>,
    /// Why the bandwidth is not reported (never a bare null).
    #[serde(skip_serializing_if = "Option::is_none")]
    bandwidth_unknown: Option<&'static str>,
    kp_duty_per_rad_s: f64,
    ki_duty_per_rad: f64,
}

/// The whole outcome, as `--json` prints it.
#[derive(Serialize)]
struct Report {
    /// `ok`, `rejected`, `timeout`, `fault`, `interrupted` (Ctrl-C or SIGTERM: STOP sent),
    /// `restarted` (the rig reset meanwhile) or `stopped` (idle again with the models from
    /// before: a STOP from another console ended it before it identified anything).
    result: &'static str,
    /// Seconds from the rig's acknowledgement to the end of commissioning.
    seconds: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    fault: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<&'static str>,
    /// A refusal's particulars (the rig's state, what to do), as `bowl send` gives them.
    #[serde(skip_serializing_if = "Option::is_none")]
    why: Option<String>,
    axes: Vec<AxisReport>,
    /// Whether the rig took COMMISSION (a `timeout` is then commissioning's, not its answer's).
    #[serde(skip)]
    started: bool,
}

/// Sends STOP; the report says when the rig did not acknowledge it.
fn stop_motors(rig: &mut Rig, report: &mut Report) {
    if !matches!(answered(rig.stop()), Ok(Some(Reply::Done(())))) {
        report.why = Some("STOP not acknowledged".into());
    }
}

/// Heartbeat period (well inside the rig's default link-loss timeout).
const PING_EVERY: Duration = Duration::from_secs(1);

/// The rig's reply, or `None` when no answer came (the caller says what was asked and stops).
fn answered<T>(reply: Result<Reply<T>>) -> Result<Option<Reply<T>>> {
    match reply {
        Ok(r) => Ok(Some(r)),
        Err(e) if e.downcast_ref::<NoAnswer>().is_some() => Ok(None),
        Err(e) => Err(e),
    }
}

/// How commissioning ended.
enum End {
    Idle,
    Fault(FaultCode),
    OtherState(DeviceState),
    Timeout,
    /// Ctrl-C or SIGTERM on this command.
    Interrupted,
    /// The rig reset meanwhile (a Hello, or its clock started again): its idle state after
    /// the reset says nothing of the identification, which the reset ended.
    Restarted,
}

/// Follows the rig until it leaves the commissioning state (its telemetry, or STATUS when it
/// sends none), through the rig client's typed [`Rig`].
fn follow(rig: &mut Rig, timeout: Duration, quiet: bool, interrupted: &AtomicBool) -> Result<End> {
    let start = Instant::now();
    let mut last_seen = Instant::now();
    let mut last_report = Instant::now();
    let mut last_ping = Instant::now();
    let restarts = rig.restarts();
    loop {
        if start.elapsed() > timeout {
            return Ok(End::Timeout);
        }
        if interrupted.load(Ordering::SeqCst) {
            return Ok(End::Interrupted);
        }
        // Telemetry out is not presence: the rig's link-loss timeout needs bytes from us.
        if last_ping.elapsed() >= PING_EVERY {
            last_ping = Instant::now();
            answered(rig.ping())?;
        }
        let mut state = None;
        rig.listen(Duration::from_millis(50))?;
        // A Hello, or the device clock starting again (the decoder's one rule).
        if rig.restarts() > restarts {
            return Ok(End::Restarted);
        }
        // Telemetry (and what came while a command waited for its answer).
        while let Some(frame) = rig.arrived.pop_front() {
            if let Frame::Telemetry(t) = frame {
                state = Some((t.state, t.fault));
                last_seen = Instant::now();
                if !quiet && last_report.elapsed() >= Duration::from_secs(1) {
                    last_report = Instant::now();
                    // In the units of the result: rad/s and duty (a fraction of full).
                    eprintln!(
                        "  {:5.1} s  precession {:7.3} rad/s duty {:+.4}   spin {:7.3} rad/s duty {:+.4}",
                        start.elapsed().as_secs_f64(),
                        f64::from(t.precession.measured_mrad_s) * 1e-3,
                        f64::from(t.precession.duty_bp) * 1e-4,
                        f64::from(t.spin.measured_mrad_s) * 1e-3,
                        f64::from(t.spin.duty_bp) * 1e-4
                    );
                }
            }
        }
        if state.is_none() && last_seen.elapsed() > POLL_AFTER {
            // No telemetry (TELEM_HZ 0?): ask.
            if let Some(Reply::Done(status)) = answered(rig.status())? {
                state = Some((status.state, status.fault));
            }
            last_seen = Instant::now();
        }
        match state {
            None | Some((DeviceState::Commissioning, _)) => {}
            Some((DeviceState::Idle, _)) => return Ok(End::Idle),
            Some((DeviceState::Faulted, fault)) => return Ok(End::Fault(fault)),
            Some((other, _)) => return Ok(End::OtherState(other)),
        }
    }
}

fn axis_report(
    axis: &'static str,
    m: &AxisModel,
    params: Option<&ParamValues>,
    bw: ParamId,
) -> AxisReport {
    let si = |v: u32| f64::from(v) / 1e6;
    AxisReport {
        axis,
        identified: m.identified,
        back_emf_v_per_rad_s: si(m.back_emf_uv_per_rad_s),
        friction_duty: si(m.friction_ppm),
        time_constant_s: si(m.time_constant_us),
        bandwidth_rad_s: params.map(|p| f64::from(p[bw.index()]) * 1e-3),
        bandwidth_unknown: params
            .is_none()
            .then_some("the rig did not answer PARAMS (asked 3 times)"),
        kp_duty_per_rad_s: si(m.kp_ppm_per_rad_s),
        ki_duty_per_rad: si(m.ki_ppm_per_rad),
    }
}

/// Whether the STOP sent at the end was acknowledged, in words.
fn stop_words(report: &Report) -> &'static str {
    if report.why.is_some() {
        ", but the rig did not acknowledge it: check that the motors are off"
    } else {
        ", the motors are off"
    }
}

/// Prints the report; the suggestions in its words (`bowl send PORT clear`) name `port`, so
/// they can be pasted as they stand.
fn print(report: &Report, json: bool, port: &str) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string(report)?);
        return Ok(());
    }
    let head = match report.result {
        "ok" => format!("commissioning done in {:.1} s", report.seconds),
        "fault" => format!(
            "commissioning FAILED after {:.1} s: fault {} (motors off; `bowl send PORT clear` clears it)",
            report.seconds,
            report.fault.as_deref().unwrap_or("?")
        ),
        "rejected" => {
            let mut text = format!(
                "COMMISSION rejected: {} - {}",
                report.reason.unwrap_or("?"),
                report
                    .reason
                    .and_then(|t| Reason::from_token(t.as_bytes()))
                    .map_or("", explain)
            );
            if let Some(why) = &report.why {
                text.push_str(&format!("\n  {why}"));
            }
            text
        }
        "interrupted" if !report.started => {
            "commissioning interrupted before it started: COMMISSION was not sent".to_string()
        }
        "interrupted" => format!(
            "commissioning interrupted after {:.1} s: STOP sent{}; the motor models in force are \
             the ones from before (`bowl send PORT models`)",
            report.seconds,
            stop_words(report)
        ),
        "timeout" if report.started => format!(
            "commissioning did NOT end within --timeout-s {:.1} s (it takes about 45 s; the rig \
             gives up itself after 120 s): STOP sent{}; the motor models in force are the ones \
             from before (`bowl send PORT models`); give a longer --timeout-s",
            report.seconds,
            stop_words(report)
        ),
        "timeout" => format!(
            "commissioning not started: {}",
            report.why.as_deref().unwrap_or("no answer to COMMISSION")
        ),
        "restarted" => format!(
            "commissioning did NOT finish: the rig reset after {:.1} s (it sent a Hello, or its \
             clock started again), which ended the identification; the motor models in force \
             are the ones it booted with. Look at why it reset (`bowl send PORT status`: \
             reset_cause), then run `bowl commission` again",
            report.seconds
        ),
        "stopped" => format!(
            "commissioning did NOT finish: the rig went back to idle after {:.1} s with the very \
             motor models it had before, so nothing was identified (a STOP from another console, \
             the monitor's command line or `bowl send PORT stop`, ends commissioning at once); \
             run `bowl commission` again",
            report.seconds
        ),
        other => format!("commissioning: {other} after {:.1} s", report.seconds),
    };
    println!("{}", rig_client::refusal::on_port(&head, port));
    for a in &report.axes {
        println!(
            "{:10} {}  Ke {:.4} V/(rad/s)  friction {:.4} duty  tau {:.4} s  |  bandwidth {}  Kp {:.4} duty/(rad/s)  Ki {:.4} duty/rad",
            a.axis,
            if a.identified {
                "identified"
            } else {
                "not identified (stored/nominal)"
            },
            a.back_emf_v_per_rad_s,
            a.friction_duty,
            a.time_constant_s,
            a.bandwidth_rad_s.map_or_else(
                || format!("unknown ({})", a.bandwidth_unknown.unwrap_or("")),
                |b| format!("{b:.3} rad/s")
            ),
            a.kp_duty_per_rad_s,
            a.ki_duty_per_rad
        );
    }
    Ok(())
}

/// Runs `bowl commission`; returns the process exit status.
pub fn run(args: &Args) -> Result<i32> {
    if !(args.timeout_s.is_finite() && args.timeout_s > 0.0 && args.timeout_s <= 86_400.0) {
        return Err(crate::exit_code::usage(format!(
            "--timeout-s must be above 0 and at most 86400 s (got {}): give how long to wait for \
             commissioning to end",
            args.timeout_s
        )));
    }
    // Ctrl-C or a `kill` while the motors turn: stop them before ending (below), rather than
    // leave the identification running unattended.
    let interrupted = crate::interrupt::flag();
    let mut rig = Rig::open(&args.port, args.baud, ANSWER_TIMEOUT)?;
    // The models before: a rig that goes back to idle with these very numbers identified
    // nothing (a STOP from another console, through the monitor, ends commissioning at once,
    // and its idle looks like the end of a run). Real identifications never repeat each of
    // their numbers to the last digit: they are measured.
    let before = match answered(rig.models())? {
        Some(Reply::Done(axes)) => Some(axes),
        _ => None,
    };
    let mut report = Report {
        result: "ok",
        seconds: 0.0,
        fault: None,
        reason: None,
        why: None,
        axes: Vec::new(),
        started: false,
    };
    // Ctrl-C while the models were asked: nothing is started.
    if interrupted.load(Ordering::SeqCst) {
        report.result = "interrupted";
        print(&report, args.json, &args.port)?;
        return Ok(exit_code::INTERRUPTED);
    }
    let ack = match rig.commission() {
        Ok(reply) => Some(reply),
        Err(e) => match e.downcast_ref::<NoAnswer>() {
            // Said with what came instead and what to check, as `bowl send` says it.
            Some(no) => {
                report.why = Some(no.to_string());
                None
            }
            None => return Err(e),
        },
    };
    match ack {
        // What came before the acknowledgement tells of the rig before commissioning.
        Some(Reply::Done(())) => {
            rig.arrived.clear();
            report.started = true;
        }
        Some(Reply::Refused(reason)) => {
            report.result = "rejected";
            report.reason = Some(reason.token());
            report.why = rig
                .refusal_particulars(&["commission"], reason)
                .map(|why| rig_client::refusal::on_port(&why, &args.port));
            print(&report, args.json, &args.port)?;
            return Ok(exit_code::REFUSED);
        }
        None => {
            report.result = "timeout";
            print(&report, args.json, &args.port)?;
            return Ok(exit_code::TIMEOUT);
        }
    }
    if !args.json {
        eprintln!(
            "commissioning: the rig drives each motor with open-loop duty steps, then runs both \
             at speed until it has learned both sensor wheels (about 45 s; keep clear)"
        );
    }
    let started = Instant::now();
    let end = follow(
        &mut rig,
        Duration::from_secs_f64(args.timeout_s),
        args.json,
        interrupted,
    )?;
    report.seconds = started.elapsed().as_secs_f64();
    let mut code = match end {
        End::Idle => exit_code::OK,
        End::Fault(fault) => {
            report.result = "fault";
            report.fault = Some(format!("{} (code {})", fault.words(), fault.code()));
            exit_code::REFUSED
        }
        End::OtherState(state) => {
            bail!(
                "commissioning ended with the rig {} (another PC may have sent a command)",
                state.words()
            )
        }
        End::Timeout => {
            report.result = "timeout";
            // Leave the motors off rather than half-way through a duty step.
            stop_motors(&mut rig, &mut report);
            exit_code::TIMEOUT
        }
        End::Interrupted => {
            report.result = "interrupted";
            stop_motors(&mut rig, &mut report);
            exit_code::INTERRUPTED
        }
        End::Restarted => {
            report.result = "restarted";
            exit_code::REFUSED
        }
    };
    if code == exit_code::OK {
        // The JSON's bandwidth comes from here: an answer lost among telemetry is asked again.
        let mut params = None;
        for _ in 0..3 {
            if let Some(Reply::Done(values)) = answered(rig.params())? {
                params = Some(values);
                break;
            }
        }
        match answered(rig.models())? {
            Some(Reply::Done(axes)) if Some(axes) == before => {
                report.result = "stopped";
                code = exit_code::REFUSED;
            }
            Some(Reply::Done(axes)) => {
                report.axes = vec![
                    axis_report(
                        "precession",
                        &axes[0],
                        params.as_ref(),
                        ParamId::Bandwidth1MradS,
                    ),
                    axis_report("spin", &axes[1], params.as_ref(), ParamId::Bandwidth2MradS),
                ];
            }
            Some(Reply::Refused(reason)) => {
                eprintln!(
                    "the rig does not report its models (MODELS: {}); commissioning itself succeeded",
                    reason.token()
                );
            }
            None => eprintln!("no answer to MODELS"),
        }
    }
    print(&report, args.json, &args.port)?;
    Ok(code)
}
