//! The commands as a person types them (`speed 1800 2100`, `set MU_PPM 29000`): their words,
//! what each takes, and a command line refused before it is sent, said in words (which value,
//! which limit, which names are valid). Used by `bowl send`, the monitor's command line and its
//! Tab completion.

use model_core::wire::{Command, Injection, ParamId, Reason, ResidenceModel};

use crate::integer::integer_in;

/// The command word `bowl` types for each command: an exhaustive match, so a new command in the
/// wire protocol cannot be left out without a compile error.
pub fn command_word(c: &Command) -> &'static str {
    match c {
        Command::SetSpeeds { .. } => "speed",
        Command::SetResidence { .. } => "rtime",
        Command::Start => "start",
        Command::Stop => "stop",
        Command::ClearFault => "clear",
        Command::SetParam { .. } => "set",
        Command::GetStatus => "status",
        Command::GetParams => "params",
        Command::Inject(_) => "inject",
        Command::Ping => "ping",
        Command::Commission => "commission",
        Command::GetModels => "models",
        Command::Release => "release",
    }
}

/// One command of each kind, for [`command_word`] to name.
const EVERY_COMMAND: [Command; 13] = [
    Command::SetSpeeds {
        precession_mrad_s: 0,
        spin_mrad_s: 0,
    },
    Command::SetResidence {
        model: ResidenceModel::Coriolis,
        time_ms: 1,
    },
    Command::Start,
    Command::Stop,
    Command::ClearFault,
    Command::SetParam {
        id: ParamId::TelemetryHz,
        value: 0,
    },
    Command::GetStatus,
    Command::GetParams,
    Command::Inject(Injection::None),
    Command::Ping,
    Command::Commission,
    Command::GetModels,
    Command::Release,
];

/// Every command word, in the order of docs/protocol.md's table.
pub fn all_words() -> Vec<&'static str> {
    EVERY_COMMAND.iter().map(command_word).collect()
}

/// The words that may follow `command` as its first argument, lower case.
pub fn first_arguments(command: &str) -> Vec<String> {
    match command {
        "set" => ParamId::ALL
            .iter()
            .map(|p| p.token().to_ascii_lowercase())
            .collect(),
        "rtime" => vec!["cori".into(), "flat".into()],
        "inject" => Injection::ALL
            .iter()
            .map(|i| i.token().to_ascii_lowercase())
            .collect(),
        _ => Vec::new(),
    }
}

/// What `command` takes after its word, and an example.
fn usage(command: &str) -> (usize, &'static str) {
    match command {
        "speed" => (
            2,
            "speed W1 W2: the precession and spin speeds in mrad/s, each 0..=its SPEED_MAX \
             (e.g. `speed 1800 2100`)",
        ),
        "rtime" => (
            2,
            "rtime MODEL MS: cori or flat, then the residence time in ms, 1..=9999999 \
             (e.g. `rtime cori 2500`)",
        ),
        "set" => (
            2,
            "set NAME VALUE: a parameter and its value, an integer in the parameter's unit \
             (e.g. `set MU_PPM 29000`)",
        ),
        "inject" => (1, "inject WHAT: none, sensor1, sensor2, stall1 or stall2"),
        _ => (0, "takes nothing after its word"),
    }
}

/// A command line refused before it was sent (`reason`, from the shared decoder and the
/// protocol's rules), in words: what was wrong, with which value, the limit or the valid names.
pub fn local_refusal(words: &[String], reason: Reason) -> String {
    // The words as the decoder saw them: split at spaces and commas.
    let words: Vec<String> = words
        .iter()
        .flat_map(|w| w.split(','))
        .filter(|w| !w.is_empty())
        .map(str::to_string)
        .collect();
    let Some(command) = words.first().map(|w| w.to_ascii_lowercase()) else {
        return "no command given".into();
    };
    let args = &words[1..];
    if reason == Reason::UnknownCommand {
        return format!(
            "`{command}` is not a command; the commands: {}",
            all_words().join(", ")
        );
    }
    if reason == Reason::UnknownParam {
        let names: Vec<&str> = ParamId::ALL.iter().map(|p| p.token()).collect();
        return format!(
            "`{}` is not a parameter; the parameters: {} (docs/protocol.md)",
            args.first().map_or("", String::as_str),
            names.join(", ")
        );
    }
    let (count, usage) = usage(&command);
    if args.len() != count {
        return format!(
            "`{command}` takes {count} value{} after it, got {}: {usage}",
            if count == 1 { "" } else { "s" },
            args.len()
        );
    }
    match (command.as_str(), reason) {
        ("speed", _) => {
            for (arg, (axis, limit)) in args.iter().zip([
                ("precession", ParamId::SpeedMax1MradS),
                ("spin", ParamId::SpeedMax2MradS),
            ]) {
                if let Some(why) = speed_value(arg, axis, limit) {
                    return why;
                }
            }
        }
        ("rtime", _) => {
            if !matches!(args[0].to_ascii_lowercase().as_str(), "cori" | "flat") {
                return format!("`{}` is not a residence model: cori or flat", args[0]);
            }
            if let Some(why) = integer_in(&args[1], "the residence time", 1, 9_999_999, "ms") {
                return why;
            }
        }
        ("set", _) => {
            if let Some(why) = crate::refusal::set_range(&words) {
                return why;
            }
        }
        ("inject", _) => {
            return format!(
                "`{}` is not something to inject: {}",
                args[0],
                first_arguments("inject").join(", ")
            );
        }
        _ => {}
    }
    format!("{}: {usage}", words.join(" "))
}

/// A speed value judged by the protocol's rule (0..=SPEED_MAX, and SPEED_MAX is at most
/// 32 767): `None` if it passes.
fn speed_value(arg: &str, axis: &str, limit: ParamId) -> Option<String> {
    let max = limit.range().1;
    match arg.parse::<i64>() {
        Ok(v) if v < 0 => Some(format!(
            "the {axis} speed {v} mrad/s is below 0: a speed is 0 (stopped) up to {} (at most \
             {max} mrad/s); the motors turn one way",
            limit.token()
        )),
        _ => integer_in(
            arg,
            &format!("the {axis} speed"),
            0,
            i64::from(max),
            "mrad/s",
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refused(line: &str) -> String {
        let words: Vec<String> = line.split_whitespace().map(str::to_string).collect();
        let reason = crate::lines::command_line(1, &words).expect_err(line);
        local_refusal(&words, reason)
    }

    #[test]
    fn every_command_word_is_one_the_rig_takes() {
        for word in all_words() {
            let line = crate::lines::command_line(1, &[word.to_string()]);
            // The bare word may lack its arguments, but it is never an unknown command.
            assert_ne!(line.err(), Some(Reason::UnknownCommand), "{word}");
        }
    }

    #[test]
    fn a_refusal_names_the_value_the_limit_and_the_valid_names() {
        let text = refused("speed -1 2100");
        assert!(
            text.contains("precession speed -1 mrad/s is below 0"),
            "{text}"
        );
        assert!(text.contains("SPEED_MAX1_MRAD_S"), "{text}");
        let text = refused("speed 1800 40000");
        assert!(
            text.contains("spin speed 40000 mrad/s is outside its range 0..=32767"),
            "{text}"
        );
        let text = refused("speed abc 2100");
        assert!(text.contains("`abc` is not an integer"), "{text}");
        let text = refused("speed 1800");
        assert!(text.contains("takes 2 values after it, got 1"), "{text}");
        let text = refused("set FOO 1");
        assert!(text.contains("`FOO` is not a parameter"), "{text}");
        assert!(
            text.contains("MU_PPM") && text.contains("TELEM_HZ"),
            "{text}"
        );
        let text = refused("set TEETH1 0");
        assert!(
            text.contains("TEETH1 0 pulses/rev is outside its range 1..=255"),
            "{text}"
        );
        let text = refused("jump");
        assert!(
            text.contains("`jump` is not a command") && text.contains("speed, rtime"),
            "{text}"
        );
        let text = refused("rtime fast 2500");
        assert!(
            text.contains("`fast` is not a residence model: cori or flat"),
            "{text}"
        );
        let text = refused("inject fire");
        assert!(
            text.contains("`fire` is not something to inject: none, sensor1"),
            "{text}"
        );
        let text = refused("speed 01800 2100");
        assert!(text.contains("write `01800` as `1800`"), "{text}");
    }
}
