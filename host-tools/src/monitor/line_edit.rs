//! The monitor's command line as a lab engineer expects it from a shell: Up/Down walk through
//! the commands sent before, Tab completes the command word and its first argument (parameter
//! names, residence models, injections).

use rig_client::command_words::{all_words, first_arguments};

/// How many sent commands Up can bring back.
const HISTORY_MAX: usize = 200;

/// The text being typed, with the history of sent commands.
#[derive(Default)]
pub struct LineEdit {
    pub text: String,
    history: Vec<String>,
    /// Where Up/Down stand in the history (`None`: on the new line).
    at: Option<usize>,
    /// What was typed before Up was first pressed, given back by Down past the newest.
    draft: String,
    /// The candidates of the last Tab that was not unique, shown under the line.
    pub candidates: Vec<String>,
}

impl LineEdit {
    /// Starts a new, empty line (the history stays).
    pub fn open(&mut self) {
        self.text.clear();
        self.at = None;
        self.candidates.clear();
    }

    /// Takes the typed line to send, and remembers it (not twice in a row).
    pub fn take(&mut self) -> String {
        let text = std::mem::take(&mut self.text);
        let trimmed = text.trim();
        if !trimmed.is_empty() && self.history.last().is_none_or(|last| last != trimmed) {
            self.history.push(trimmed.to_string());
            if self.history.len() > HISTORY_MAX {
                self.history.remove(0);
            }
        }
        self.at = None;
        self.candidates.clear();
        text
    }

    pub fn push(&mut self, c: char) {
        self.text.push(c);
        self.candidates.clear();
    }

    pub fn backspace(&mut self) {
        self.text.pop();
        self.candidates.clear();
    }

    /// Up: the command sent before the one shown.
    pub fn older(&mut self) {
        let at = match self.at {
            None if self.history.is_empty() => return,
            None => {
                self.draft = self.text.clone();
                self.history.len() - 1
            }
            Some(i) => i.saturating_sub(1),
        };
        self.at = Some(at);
        self.text = self.history[at].clone();
    }

    /// Down: the command sent after the one shown, then the line being typed.
    pub fn newer(&mut self) {
        match self.at {
            None => {}
            Some(i) if i + 1 < self.history.len() => {
                self.at = Some(i + 1);
                self.text = self.history[i + 1].clone();
            }
            Some(_) => {
                self.at = None;
                self.text = std::mem::take(&mut self.draft);
            }
        }
    }

    /// Tab: completes the word being typed (the command, or its first argument) as far as it is
    /// unique; with more than one way on, lists them in `candidates`.
    pub fn complete(&mut self) {
        let text = self.text.clone();
        let words: Vec<&str> = text.split_whitespace().collect();
        let typing_new_word = text.is_empty() || text.ends_with(' ');
        let (index, partial) = match (words.len(), typing_new_word) {
            (0, _) => (0, ""),
            (n, true) => (n, ""),
            (n, false) => (n - 1, words[n - 1]),
        };
        let options: Vec<String> = match index {
            0 => all_words(),
            1 => first_arguments(&words[0].to_ascii_lowercase()),
            _ => Vec::new(),
        };
        let lower = partial.to_ascii_lowercase();
        let mut fits: Vec<String> = options
            .into_iter()
            .filter(|o| o.starts_with(&lower))
            .collect();
        fits.sort();
        let Some(first) = fits.first() else {
            self.candidates.clear();
            return;
        };
        // The longest prefix all candidates share.
        let common = fits.iter().fold(first.clone(), |acc, f| {
            acc.chars()
                .zip(f.chars())
                .take_while(|(a, b)| a == b)
                .map(|(a, _)| a)
                .collect()
        });
        let keep = self.text.len() - partial.len();
        self.text.truncate(keep);
        // Parameter names are typed in capitals in the docs (`set MU_PPM 29000`).
        let upper = index == 1 && words[0].eq_ignore_ascii_case("set");
        let case = |s: &str| {
            if upper {
                s.to_ascii_uppercase()
            } else {
                s.to_string()
            }
        };
        self.text.push_str(&case(&common));
        if fits.len() == 1 {
            self.text.push(' ');
            self.candidates.clear();
        } else {
            self.candidates = fits.iter().map(|f| case(f)).collect();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn typed(text: &str) -> LineEdit {
        let mut e = LineEdit::default();
        for c in text.chars() {
            e.push(c);
        }
        e
    }

    #[test]
    fn tab_completes_commands_and_parameter_names() {
        let mut e = typed("sp");
        e.complete();
        assert_eq!(e.text, "speed ");
        let mut e = typed("s");
        e.complete();
        assert_eq!(e.text, "s");
        assert_eq!(e.candidates, ["set", "speed", "start", "status", "stop"]);
        let mut e = typed("set mu");
        e.complete();
        assert_eq!(e.text, "set MU_PPM ");
        let mut e = typed("set TEE");
        e.complete();
        assert_eq!(e.text, "set TEETH");
        assert_eq!(e.candidates, ["TEETH1", "TEETH2"]);
        let mut e = typed("inject sen");
        e.complete();
        assert_eq!(e.text, "inject sensor");
        let mut e = typed("rtime c");
        e.complete();
        assert_eq!(e.text, "rtime cori ");
        // Nothing fits: the line stays as it is.
        let mut e = typed("set XYZ");
        e.complete();
        assert_eq!(e.text, "set XYZ");
        assert!(e.candidates.is_empty());
    }

    #[test]
    fn up_and_down_walk_the_history_and_give_back_the_draft() {
        let mut e = LineEdit::default();
        for sent in ["status", "speed 1800 2100", "speed 1800 2100", "start"] {
            e.open();
            for c in sent.chars() {
                e.push(c);
            }
            e.take();
        }
        e.open();
        e.push('s');
        e.older();
        assert_eq!(e.text, "start");
        e.older();
        assert_eq!(e.text, "speed 1800 2100", "a repeat is kept once");
        e.older();
        e.older();
        assert_eq!(e.text, "status", "stays at the oldest");
        e.newer();
        e.newer();
        assert_eq!(e.text, "start");
        e.newer();
        assert_eq!(e.text, "s", "the draft comes back");
    }
}
