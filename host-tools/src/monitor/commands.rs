//! Commands typed into the monitor's own command line: sent on the port it holds, matched to
//! their answers by id and kind, resent with the same id when the answer does not come.

use std::time::{Duration, Instant};

use model_core::wire::Frame;

use rig_client::command_words::local_refusal;
use rig_client::lines::{command_line, describe, explain};
use rig_client::refusal::{on_port, particulars};
use rig_client::request::{Request, fresh_id, next_id};
use rig_client::unreadable::UnreadableAnswer;

/// How often a typed command is sent in all when no answer comes (1 s).
const ATTEMPTS: u32 = 5;

/// A typed command in flight: its words and the one request loop's state (id, line, resends).
struct Pending {
    words: String,
    request: Request,
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
        let words: Vec<String> = text.split_whitespace().map(str::to_owned).collect();
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
        });
        Ok(line)
    }

    /// An answer for one of ours: the text to show.
    pub fn on_frame(&mut self, frame: &Frame) -> Option<String> {
        let id = frame.answer_id()?;
        let i = self
            .pending
            .iter()
            .position(|p| p.request.answered_by(frame))?;
        let p = self.pending.remove(i);
        let mut text = format!("{} -> {}", p.words, describe(frame));
        // The particulars that need no question to the rig (its state is on the screen).
        if let Frame::Reject { reason, .. } = frame {
            let words: Vec<String> = p.words.split_whitespace().map(str::to_owned).collect();
            if let Some(more) = particulars(None, id, &words, *reason, Duration::ZERO) {
                text.push_str(&format!(" ({})", on_port(&more, &self.port)));
            }
        }
        Some(text)
    }

    /// An intact answer this bowl cannot read: the text to show (with the command it answers,
    /// which is then no longer waited for, if it is ours).
    pub fn on_unreadable(&mut self, answer: &UnreadableAnswer) -> String {
        match self
            .pending
            .iter()
            .position(|p| p.request.id() == answer.id)
        {
            Some(i) => format!("{} -> {answer}", self.pending.remove(i).words),
            None => answer.to_string(),
        }
    }

    /// The port went away: the commands waiting for an answer are given up (sent again on the
    /// reopened port they could reach another rig, or this one after a reset); the texts to
    /// show, one each.
    pub fn link_lost(&mut self) -> Vec<String> {
        self.pending
            .drain(..)
            .map(|p| {
                format!(
                    "{} -> no answer before the link was lost (id {}): it may or may not have \
                     reached the rig; its state shows once the port is reopened",
                    p.words,
                    p.request.id()
                )
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
                gave_up.push(format!(
                    "{} -> no answer (id {}, sent {} times)",
                    p.words,
                    p.request.id(),
                    p.request.sends()
                ));
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
        std::thread::sleep(Duration::from_millis(1100));
        let (resend, gave_up) = commands.due();
        assert!(resend.is_empty() && gave_up.is_empty(), "{gave_up:?}");
    }
}
