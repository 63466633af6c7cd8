//! The commands as a person types them (`speed 1800 2100`, `set MU_PPM 29000`): their words
//! and first arguments for Tab completion, and a command line refused before it is sent, said
//! in words. All of it follows the command table (`model_core::wire::commands`); used by
//! `bowl send`, the monitor's command line and its Tab completion.

use model_core::wire::{Command, CommandKind, FieldKind, ParamId, Reason};

/// Every command word, lower case (the wire token as a person types it), in the order of the
/// command table (docs/protocol.md).
pub fn all_words() -> Vec<String> {
    CommandKind::ALL
        .iter()
        .map(|k| k.token().to_ascii_lowercase())
        .collect()
}

/// The words that may follow `command` as its first argument, lower case (from the command
/// table: a choice's tokens, or the parameter names).
pub fn first_arguments(command: &str) -> Vec<String> {
    let Some(first) = CommandKind::from_word(command).and_then(|k| k.fields().first()) else {
        return Vec::new();
    };
    match first.kind {
        FieldKind::Choice(tokens) => tokens.iter().map(|t| t.to_ascii_lowercase()).collect(),
        FieldKind::ParamName => ParamId::ALL
            .iter()
            .map(|p| p.token().to_ascii_lowercase())
            .collect(),
        FieldKind::Int { .. } | FieldKind::ParamValue => Vec::new(),
    }
}

/// A command line refused before it was sent, in words: what was wrong, with which value, the
/// limit or the valid names (the command table's words, `model_core::wire::Refusal`). `reason`
/// is what the local check answered; the words say more.
pub fn local_refusal(words: &[String], reason: Reason) -> String {
    match Command::from_words(words) {
        Err(refusal) => refusal.to_string(),
        Ok(_) => format!("{}: {}", words.join(" "), crate::lines::explain(reason)),
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
            let line = crate::lines::command_line(1, std::slice::from_ref(&word));
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
            text.contains("`fast` is not a residence model: flat, cori or table"),
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
