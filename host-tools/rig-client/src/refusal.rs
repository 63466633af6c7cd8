//! Why the rig refused a command, in particulars: which value and its limit (`RANGE`), which
//! state it is in (`STATE`), which residence times it can give (`INFEASIBLE`).
//!
//! The wire's refusal is one token; the particulars come from what the PC knows (the command
//! it sent, the one parameter table) and from asking the rig right after (STATUS, PARAMS), the
//! way a motor-controller console reads the error registers after a refused request.

use std::time::Duration;

use model_core::binding::{ParamRole, config_from_params, scene_from_params, table_from_params};
use model_core::bowl::MotorSpeeds;
use model_core::control::estimator::lowest_speed_rad_s;
use model_core::control::{BowlSpeedForResidence, Controller, ControllerConfig, InverseFailure};
use model_core::particle::speed_table::SpeedTable;
use model_core::particle::{Model, Scene, omega_for_residence_time};
use model_core::wire::{CommandKind, Frame, ParamId, ParamValues, Reason, Status};

use crate::lines::command_line;
use crate::link::Link;
use crate::request::transact;

mod set;
pub(crate) use set::set_range;

/// `text` (particulars, a note) with its `bowl send PORT ...` suggestions naming `port`, the
/// port the command was given, so a suggestion can be pasted as it stands.
pub fn on_port(text: &str, port: &str) -> String {
    text.replace("bowl send PORT", &format!("bowl send {port}"))
}

/// What the particulars of a refusal need to know of the rig, beyond the command itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Question {
    /// Its parameters (limits, the residence-time table).
    Params,
    /// Its state and fault.
    Status,
}

impl Question {
    /// The command that asks it.
    pub fn word(self) -> &'static str {
        match self {
            Question::Params => "params",
            Question::Status => "status",
        }
    }
}

/// What the rig must be asked for the particulars of a refusal of `words` (the command as
/// typed) for `reason`; `None` when they need nothing from it, or there are none.
pub fn question(words: &[String], reason: Reason) -> Option<Question> {
    let word = words.first()?.to_ascii_lowercase();
    match (reason, word.as_str()) {
        (Reason::State | Reason::Unsupported, "release") => None,
        (Reason::State, _) => Some(Question::Status),
        (Reason::Range, "set" | "speed") | (Reason::Range | Reason::Infeasible, "rtime") => {
            Some(Question::Params)
        }
        _ => None,
    }
}

/// The particulars of a refusal of `words` (the command as typed), asking the rig what it
/// needs through `link`; `None` when there is nothing to add to the reason's own words.
pub fn particulars(
    link: Option<&mut Link>,
    id: u16,
    words: &[String],
    reason: Reason,
    timeout: Duration,
) -> Option<String> {
    let answer = match (question(words, reason), link) {
        (Some(q), Some(link)) => ask(link, id, q.word(), timeout),
        _ => None,
    };
    particulars_given(words, reason, answer.as_ref())
}

/// The particulars of a refusal of `words` for `reason`, given the rig's `answer` to its
/// [`question`] (a PARAMS or STATUS frame; `None`: not asked, or not answered): for a console
/// that asks in its own time, as the monitor does.
pub fn particulars_given(
    words: &[String],
    reason: Reason,
    answer: Option<&Frame>,
) -> Option<String> {
    let word = words.first()?.to_ascii_lowercase();
    let params = match answer {
        Some(Frame::Params { values, .. }) => Some(values),
        _ => None,
    };
    match (reason, word.as_str()) {
        (Reason::Range, "set") => set_range(words, params),
        (Reason::State, "release") => Some(
            "the last release is not over: a simulated rig still has its granule in the bowl \
             (wait for its exit gate event), the Black Pill's solenoid is still energised \
             (40 ms)"
                .into(),
        ),
        (Reason::Unsupported, "release") => Some(
            "this rig has no release solenoid: drop the granule by hand (the release gate still \
             times it once wired)"
                .into(),
        ),
        (Reason::State, _) => match answer? {
            Frame::Status { status, .. } => Some(state_words(status, &word, words)),
            _ => None,
        },
        (Reason::Range, "speed") => speed_limits(words, params?),
        (Reason::Infeasible, "rtime")
            if words
                .get(1)
                .is_some_and(|m| m.eq_ignore_ascii_case("table")) =>
        {
            Some(table_refusal(words, params?))
        }
        (Reason::Range | Reason::Infeasible, "rtime") => residence_range(words, params?),
        _ => None,
    }
}

fn state_words(s: &Status, command: &str, typed: &[String]) -> String {
    use model_core::wire::DeviceState as D;
    // SET's states are its parameter's, not the command's (the parameter table's roles).
    let param = (command == "set")
        .then(|| {
            typed
                .get(1)
                .and_then(|w| ParamId::from_token(w.to_ascii_uppercase().as_bytes()))
        })
        .flatten();
    if let Some(p) = param
        && !ParamRole::of(p).changes_while_running()
        && matches!(
            s.state,
            D::Running | D::ChangingSpeed | D::Stopping | D::Commissioning
        )
    {
        // A rig that is already stopping needs no `stop`: only time.
        let todo = if s.state == D::Stopping {
            "wait until the rig is idle (`bowl send PORT status`; stopping takes the ramp down, \
             then up to about two seconds until both shafts read at rest)"
        } else {
            "stop the motors first (`bowl send PORT stop`)"
        };
        return format!(
            "the rig is {}: {} changes only while the rig is idle or faulted (it rebuilds the \
             controller); {todo}, then set it",
            s.state.words(),
            p.token()
        );
    }
    // The loop tuning, refused only while commissioning (which runs a loop of its own): the
    // command's states (every one, commissioning too) would contradict the refusal.
    if let Some(p) = param
        && s.state == D::Commissioning
    {
        return format!(
            "the rig is commissioning: {} changes in any state but commissioning (it identifies \
             the motors with a loop of its own); wait until it is idle again (about 45 s; \
             `bowl send PORT status`), then set it",
            p.token()
        );
    }
    // The rig takes the command in the state it answered: it refused it in one it has since
    // left (the monitor's question answered after a `stop` typed next had ended the run).
    // Said as such: the words for the state now contradicted the refusal ("the rig is idle:
    // ... `set` is taken while idle, ...").
    if CommandKind::from_word(command).is_some_and(|kind| kind.states().contains(s.state)) {
        let what = param.map_or_else(
            || command.to_string(),
            |p| format!("{command} {}", p.token()),
        );
        return format!(
            "the rig is {} now, where `{what}` is taken: it refused it in a state it has since \
             left; send it again",
            s.state.words()
        );
    }
    let todo = match s.state {
        D::Running | D::ChangingSpeed if command == "start" => format!(
            "already running (state {}); change speed with `speed`, or `stop` first",
            s.state.token()
        ),
        // A new speed while stopping: STOP is final, and a speed is taken again from idle.
        D::Stopping if matches!(command, "start" | "commission" | "speed" | "rtime") => {
            "wait until the rig is idle (stopping takes the ramp down, then up to about two \
             seconds until both shafts read at rest), then send it again"
                .to_string()
        }
        D::Faulted => format!(
            "{}; clear it first (`bowl send PORT clear`)",
            s.fault.words()
        ),
        // Whatever else the rig is doing, CLEAR is refused for want of a fault.
        _ if command == "clear" => "there is no fault to clear".to_string(),
        D::Commissioning => "wait for commissioning to end".to_string(),
        D::Running | D::ChangingSpeed if command == "commission" => {
            "stop the motors first (`bowl send PORT stop`)".to_string()
        }
        _ => "see docs/protocol.md for what each state allows".to_string(),
    };
    // The states the command table allows it in.
    let allowed = CommandKind::from_word(command).map(|kind| {
        let states: Vec<&str> = (0..=5)
            .filter_map(D::from_code)
            .filter(|&state| kind.states().contains(state))
            .map(D::token)
            .collect();
        format!(" (`{command}` is taken while {})", states.join(", "))
    });
    format!(
        "the rig is {}: {todo}{}",
        s.state.words(),
        allowed.unwrap_or_default()
    )
}

/// The controller's view of the rig's parameters (speed limits, sensor wheels, axes angle).
fn rig_config(params: &ParamValues) -> Option<ControllerConfig> {
    config_from_params(&ControllerConfig::default(), params).ok()
}

/// `speed W1 W2` (mrad/s) out of range: which axis, which limit.
fn speed_limits(words: &[String], params: &ParamValues) -> Option<String> {
    let cfg = rig_config(params)?;
    let names = [
        ("precession", ParamId::SpeedMax1MradS),
        ("spin", ParamId::SpeedMax2MradS),
    ];
    let mut out = Vec::new();
    for (i, (axis, max_id)) in names.into_iter().enumerate() {
        let Some(Ok(mrad_s)) = words.get(i + 1).map(|w| w.parse::<i64>()) else {
            continue;
        };
        let w = mrad_s.unsigned_abs() as f64 * 1e-3;
        let a = &cfg.axes[i];
        let lowest = f64::from(lowest_speed_rad_s(a));
        if w > f64::from(a.max_speed_rad_s) {
            out.push(format!(
                "the {axis} speed {w:.3} rad/s is above {} = {:.3} rad/s",
                max_id.token(),
                a.max_speed_rad_s
            ));
        } else if w > 0.0 && w < lowest {
            out.push(format!(
                "the {axis} speed {w:.3} rad/s is below {lowest:.3} rad/s, the lowest its sensor \
                 ({} pulses per revolution) can measure; use 0 or at least {lowest:.3}",
                a.pulses_per_rev
            ));
        }
    }
    (!out.is_empty()).then(|| out.join("; "))
}

/// The scene's inverse as the rig's controller uses it (f32, as on the board).
struct RigInverse {
    scene: Scene<f32>,
    model: Model,
}

impl BowlSpeedForResidence for RigInverse {
    fn omega_rad_s(&self, target_s: f32) -> Result<f32, InverseFailure> {
        omega_for_residence_time(&self.scene, self.model, target_s)
            .map_err(|_| InverseFailure::Unreachable)
    }
}

/// `rtime MODEL MS` refused: the residence times the rig can give. Each candidate time is put
/// to the controller the rig runs (its f32 inverse, its split into motor speeds, each motor
/// between its lowest measurable speed and its limit); the feasible times form one interval
/// (a longer time needs a slower bowl), found by bisection on its two ends.
fn residence_range(words: &[String], params: &ParamValues) -> Option<String> {
    let cfg = rig_config(params)?;
    let model = match words.get(1)?.to_ascii_uppercase().as_str() {
        "FLAT" => Model::Flat,
        _ => Model::Coriolis,
    };
    let inverse = RigInverse {
        scene: scene_from_params::<f32>(params).ok()?,
        model,
    };
    let accepts = |t_s: f64| {
        Controller::new(cfg)
            .ok()
            .and_then(|mut c| c.set_target_residence_time(t_s as f32, &inverse).ok())
    };
    // A feasible time to start from: the one at the bowl's fastest allowed speed or slower.
    let grid = (0..=60).map(|i| 1e-3 * 10f64.powf(f64::from(i) / 10.0));
    let inside = grid.clone().find(|&t| accepts(t).is_some())?;
    let shortest = bisect(inside, 1e-4, &accepts);
    let longest = bisect(inside, 1e6, &accepts);
    let bowl = |t: f64| {
        accepts(t)
            .and_then(|w| {
                let a = cfg.axes_angle_rad;
                model_core::bowl::combined_speed_from_trig(
                    a.cos(),
                    a.sin(),
                    MotorSpeeds {
                        precession_rad_s: w[0],
                        spin_rad_s: w[1],
                    },
                )
                .ok()
            })
            .map(|w| format!(" (bowl at {w:.3} rad/s)"))
            .unwrap_or_default()
    };
    let asked = words
        .get(2)
        .and_then(|w| w.parse::<f64>().ok())
        .map(|ms| format!("{:.3} s asked; ", ms * 1e-3))
        .unwrap_or_default();
    Some(format!(
        "{asked}this rig can give {shortest:.3} s{} to {longest:.3} s{} with the {} model",
        bowl(shortest),
        bowl(longest),
        if model == Model::Flat {
            "flat"
        } else {
            "Coriolis"
        }
    ))
}

/// `t0-t1 s` with as many decimals (3 to 6) as it takes to tell them apart.
fn time_span(t0: f64, t1: f64) -> String {
    let places = (3..=6)
        .find(|&p| format!("{t0:.p$}") != format!("{t1:.p$}"))
        .unwrap_or(6);
    format!("{t0:.places$}-{t1:.places$} s")
}

/// `t0`-`t1` s with its ends rounded inwards (the first decimals where they still differ):
/// every time quoted is one the table takes (0.16773-0.16883 s is `0.1678-0.1688 s`, not
/// `0.168-0.169 s`, whose 0.1689 it refuses).
fn inner_time_span(t0: f64, t1: f64) -> String {
    let rounded = |p: usize| {
        let scale = 10f64.powi(p as i32);
        ((t0 * scale).ceil() / scale, (t1 * scale).floor() / scale)
    };
    let places = (3..=6)
        .find(|&p| {
            let (a, b) = rounded(p);
            a < b
        })
        .unwrap_or(6);
    let (a, b) = rounded(places);
    format!("{a:.places$}-{b:.places$} s")
}

/// What speed can do with a residence-time table, in words: `at 60 deg tilt T is
/// 0.143-0.144 s at every speed from 0.5 to 3.6 rad/s: speed cannot set it; the tilt or the
/// wall can` when the table is flat ([`SpeedTable::is_flat`]), else the range of T and the
/// speeds that give its ends. The one wording for `bowl predict` and the refusals.
pub fn speed_range_words(tilt_deg: f64, table: &SpeedTable) -> String {
    let (w_lo, w_hi) = table.speed_range_rad_s();
    let (t_lo, t_hi) = table.residence_range_s();
    let (t_lo, t_hi) = (f64::from(t_lo), f64::from(t_hi));
    let t = table.residence_s();
    let speeds = format!("{:.2} to {:.2} rad/s", w_lo, w_hi);
    if table.is_flat() {
        format!(
            "at {tilt_deg} deg tilt T is {} at every speed from {speeds}: speed cannot set it; \
             the tilt or the wall can",
            time_span(t_lo, t_hi)
        )
    } else {
        let slow = f64::from(t[0]);
        let fast = f64::from(t[t.len() - 1]);
        format!(
            "at {tilt_deg} deg tilt T is {} over the speeds from {speeds} ({slow:.4} s at the \
             slowest, {fast:.4} s at the fastest)",
            inner_time_span(t_lo, t_hi)
        )
    }
}

/// `rtime table MS` refused: no table stored, a flat one, or a target outside its times.
fn table_refusal(words: &[String], params: &ParamValues) -> String {
    let tilt_deg = f64::from(params[ParamId::AxesMdeg.index()]) * 1e-3;
    let asked = words
        .get(2)
        .and_then(|w| w.parse::<f64>().ok())
        .map(|ms| format!("{:.3} s asked; ", ms * 1e-3))
        .unwrap_or_default();
    match table_from_params(params) {
        Ok(Some(table)) if table.is_flat() => {
            // A time the rig gives at every speed is not refused for being out of reach: RTIME
            // TABLE chooses a speed, and none is better than another (QA: "168 ms refused
            // inside the range it quotes").
            let (t_lo, t_hi) = table.residence_range_s();
            let given = words
                .get(2)
                .and_then(|w| w.parse::<f64>().ok())
                .filter(|ms| {
                    (f64::from(t_lo) * 1e3 - 0.5..=f64::from(t_hi) * 1e3 + 0.5).contains(ms)
                })
                .map(|_| {
                    "; that is the time the rig gives at any of these speeds: choose the speeds \
                     with `speed` (RTIME TABLE sets a speed only where the speed sets T)"
                })
                .unwrap_or_default();
            format!("{asked}{}{given}", speed_range_words(tilt_deg, &table))
        }
        Ok(Some(table)) => format!(
            "{asked}{}; ask for a time in that range, or change the tilt or the wall",
            speed_range_words(tilt_deg, &table)
        ),
        Ok(None) | Err(_) => format!(
            "{asked}no residence-time table is stored on this rig (RT_W_HI_MRAD_S is 0): \
             compute one for its bowl, tilt and granule and store it with `bowl predict --model \
             bowl --rig-file RIG.toml --store-table PORT`, or use `rtime cori` / `rtime flat` \
             (the paper's 1-D models)"
        ),
    }
}

/// The end of the feasible interval between `inside` (feasible) and `outside` (not), to 1e-4
/// relative, returned on the feasible side.
fn bisect(mut inside: f64, mut outside: f64, accepts: &dyn Fn(f64) -> Option<[f32; 2]>) -> f64 {
    if accepts(outside).is_some() {
        return outside;
    }
    while (outside - inside).abs() > 1e-4 * inside {
        let mid = (inside * outside).sqrt();
        if accepts(mid).is_some() {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    inside
}

fn ask(link: &mut Link, id: u16, word: &str, timeout: Duration) -> Option<Frame> {
    // Far from the refused command's id, so a script's next id is never this question's.
    let query_id = id ^ 0x8000;
    let line = command_line(query_id, &[word.to_string()]).ok()?;
    transact(link, query_id, &line, timeout).ok()?.ok()
}

pub(crate) fn ask_params(link: &mut Link, id: u16, timeout: Duration) -> Option<ParamValues> {
    match ask(link, id, "params", timeout)? {
        Frame::Params { values, .. } => Some(values),
        _ => None,
    }
}

#[cfg(test)]
mod tests;
