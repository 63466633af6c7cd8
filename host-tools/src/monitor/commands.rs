//! Commands typed into the monitor's own command line: sent on the port it holds, matched to
//! their answers by id and kind, resent with the same id when the answer does not come. A
//! refusal's particulars (the limit a value broke, the state that forbids the command) are
//! asked of the rig as `bowl send` asks them, without stopping the monitor: the refusal is
//! shown when the answer to that question comes.

use std::time::Instant;

use model_core::wire::{Frame, Reason, split_words};

use rig_client::command_words::local_refusal;
use rig_client::lines::{command_line, describe, explain};
use rig_client::refusal::{Question, on_port, particulars_given, question};
use rig_client::request::{Request, fresh_id, next_id};
use rig_client::unreadable::UnreadableAnswer;

/// How often a typed command is sent in all when no answer comes (1 s).
const ATTEMPTS: u32 = 5;

/// A typed command in flight: its words and the one request loop's state (id, line, resends).
struct Pending {
    words: String,
    request: Request,
    /// For the question asked about a refusal of `words`: the refusal's words so far, and its
    /// reason. Shown as they are should the question get no answer.
    refusal: Option<(String, Reason)>,
}

/// The monitor's commands in flight.
pub struct Commands {
    next_id: u16,
    pending: Vec<Pending>,
    /// The port the monitor holds, named in the suggestions (`bowl send PORT params`).
    port: String,
}

impl Commands {
    pub fn new(port: &str) -> Self {
        // Ids from the clock, so no tool before this one used them within the rig's memory of
        // recent commands (a late copy of theirs must not look like ours, nor ours like theirs).
        Self {
            next_id: fresh_id(),
            pending: Vec::new(),
            port: port.to_owned(),
        }
    }

    /// Takes a typed line; returns the bytes to send, or the reason it was refused here. With
    /// the port lost (`link` false) nothing is taken: a command kept to send once the port is
    /// back would reach whatever rig is then on it, seconds after it was said not sent.
    pub fn submit(&mut self, text: &str, link: bool) -> Result<Vec<u8>, String> {
        let words: Vec<String> = split_words(&[text]).map(str::to_owned).collect();
        if words.is_empty() {
            return Err("type a command, e.g. `status`, `speed 1800 2100`, `start`".into());
        }
        if !link {
            return Err(format!(
                "`{}` not sent: the link is lost; type it again once the port is reopened",
                text.trim()
            ));
        }
        let id = self.next_id;
        self.next_id = next_id(self.next_id);
        let line = command_line(id, &words).map_err(|r| {
            format!(
                "`{text}` not sent: {} - {} ({})",
                r.token(),
                explain(r),
                local_refusal(&words, r)
            )
        })?;
        let Some(mut request) = Request::from_line(line) else {
            return Err(format!("`{text}` not sent: not a command"));
        };
        let line = request
            .due(Instant::now())
            .map(<[u8]>::to_vec)
            .unwrap_or_default();
        self.pending.push(Pending {
            words: text.trim().to_owned(),
            request,
            refusal: None,
        });
        Ok(line)
    }

    /// An answer for one of ours: the text to show (none yet for a refusal whose particulars
    /// are being asked of the rig).
    pub fn on_frame(&mut self, frame: &Frame) -> Option<String> {
        frame.answer_id()?;
        let i = self
            .pending
            .iter()
            .position(|p| p.request.answered_by(frame))?;
        let p = self.pending.remove(i);
        let words: Vec<String> = split_words(&[&p.words]).map(str::to_owned).collect();
        let (text, reason, answer) = match p.refusal {
            // The answer to the question about a refusal.
            Some((text, reason)) => (text, reason, Some(frame)),
            None => {
                let text = format!("{} -> {}", p.words, describe(frame));
                let Frame::Reject { reason, .. } = frame else {
                    return Some(text);
                };
                match question(&words, *reason) {
                    Some(q) => match self.ask(&p.words, q, text, *reason) {
                        Ok(()) => return None,
                        Err(text) => (text, *reason, None),
                    },
                    None => (text, *reason, None),
                }
            }
        };
        Some(match particulars_given(&words, reason, answer) {
            Some(more) => format!("{text} ({})", on_port(&more, &self.port)),
            None => text,
        })
    }

    /// Asks the rig `q` (PARAMS, STATUS) for the particulars of the refusal `text` of
    /// `words`, sent by the next [`Commands::due`]; the text back should it not be asked.
    fn ask(
        &mut self,
        words: &str,
        q: Question,
        text: String,
        reason: Reason,
    ) -> Result<(), String> {
        let id = self.next_id;
        self.next_id = next_id(self.next_id);
        let Some(request) = command_line(id, &[q.word().to_string()])
            .ok()
            .and_then(Request::from_line)
        else {
            return Err(text);
        };
        self.pending.push(Pending {
            words: words.to_owned(),
            request,
            refusal: Some((text, reason)),
        });
        Ok(())
    }

    /// An intact answer this bowl cannot read: the text to show (with the command it answers,
    /// which is then no longer waited for, if it is ours).
    pub fn on_unreadable(&mut self, answer: &UnreadableAnswer) -> String {
        match self
            .pending
            .iter()
            .position(|p| p.request.id() == answer.id)
        {
            Some(i) => {
                let p = self.pending.remove(i);
                match p.refusal {
                    // The question about a refusal: the refusal stands without particulars.
                    Some((text, _)) => text,
                    None => format!("{} -> {answer}", p.words),
                }
            }
            None => answer.to_string(),
        }
    }

    /// The port went away: the commands waiting for an answer are given up (sent again on the
    /// reopened port they could reach another rig, or this one after a reset); the texts to
    /// show, one each.
    pub fn link_lost(&mut self) -> Vec<String> {
        self.pending
            .drain(..)
            .map(|p| match p.refusal {
                // The refusal itself came: shown without its particulars.
                Some((text, _)) => text,
                None => format!(
                    "{} -> no answer before the link was lost (id {}): it may or may not have \
                     reached the rig; its state shows once the port is reopened",
                    p.words,
                    p.request.id()
                ),
            })
            .collect()
    }

    /// Lines to send again (same id) and texts for commands that got no answer at all.
    pub fn due(&mut self) -> (Vec<Vec<u8>>, Vec<String>) {
        let mut resend = Vec::new();
        let mut gave_up = Vec::new();
        let now = Instant::now();
        self.pending.retain_mut(|p| {
            if p.request.next_due().is_some_and(|t| t > now) {
                return true;
            }
            if p.request.sends() >= ATTEMPTS {
                gave_up.push(match p.refusal.take() {
                    Some((text, _)) => text,
                    None => format!(
                        "{} -> no answer (id {}, sent {} times)",
                        p.words,
                        p.request.id(),
                        p.request.sends()
                    ),
                });
                return false;
            }
            resend.extend(p.request.due(now).map(<[u8]>::to_vec));
            true
        });
        (resend, gave_up)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_core::wire::{Command, decode_frame};

    fn id_of(line: &[u8]) -> (u16, Command) {
        match decode_frame(line) {
            Ok(Frame::Command { id, command }) => (id, command),
            other => panic!("{other:?}"),
        }
    }

    /// A refusal whose particulars need the rig's parameters waits for the answer to PARAMS,
    /// asked right away; should that never come, the refusal is shown all the same.
    #[test]
    fn a_refusal_asks_its_particulars_and_is_never_lost() {
        let mut commands = Commands::new("/dev/ttyUSB0");
        let (id, _) = id_of(&commands.submit("speed 5000 5000", true).unwrap());
        let refused = Frame::Reject {
            id,
            reason: Reason::Range,
        };
        assert_eq!(
            commands.on_frame(&refused),
            None,
            "waits for its particulars"
        );
        let (resend, _) = commands.due();
        assert_eq!(resend.len(), 1);
        assert_eq!(id_of(&resend[0]).1, Command::GetParams);
        let lost = commands.link_lost();
        assert_eq!(lost.len(), 1, "{lost:?}");
        assert!(
            lost[0].starts_with(&format!("speed 5000 5000 -> rejected (id {id}): RANGE")),
            "{lost:?}"
        );
    }

    /// A command typed with commas (`speed,5000,5000`, the frame's own separator, which the
    /// rig's console and `bowl send` take) gets its refusal's particulars: before, it was sent
    /// and refused RANGE with no word of the limit (the particulars read its words by
    /// position, and the whole line was one word).
    #[test]
    fn a_command_typed_with_commas_gets_its_particulars() {
        let mut commands = Commands::new("/dev/ttyUSB0");
        let (id, _) = id_of(&commands.submit("speed,5000,5000\r", true).unwrap());
        let refused = Frame::Reject {
            id,
            reason: Reason::Range,
        };
        assert_eq!(commands.on_frame(&refused), None, "asks its particulars");
        let (ask, _) = commands.due();
        let (qid, q) = id_of(&ask[0]);
        assert_eq!(q, Command::GetParams);
        let params = Frame::Params {
            id: qid,
            values: model_core::binding::default_params(),
        };
        let text = commands.on_frame(&params).expect("the refusal is shown");
        assert!(
            text.contains("the precession speed 5.000 rad/s is above SPEED_MAX1_MRAD_S"),
            "{text}"
        );
    }

    /// A command typed while the port is lost is refused at once and never sent later; one
    /// waiting for its answer when the port goes is given up, not sent again on the new port.
    #[test]
    fn nothing_waits_through_a_lost_link() {
        let mut commands = Commands::new("/dev/ttyUSB0");
        let refused = commands.submit("start", false).unwrap_err();
        assert!(
            refused.contains("`start` not sent: the link is lost"),
            "{refused}"
        );
        assert!(commands.submit("stop", true).is_ok());
        let lost = commands.link_lost();
        assert_eq!(lost.len(), 1, "{lost:?}");
        assert!(
            lost[0].starts_with("stop -> no answer before the link was lost"),
            "{lost:?}"
        );
        std::thread::sleep(std::time::Duration::from_millis(1100));
        let (resend, gave_up) = commands.due();
        assert!(resend.is_empty() && gave_up.is_empty(), "{gave_up:?}");
    }
}
