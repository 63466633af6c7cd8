//! The rig client: everything the PC needs to talk to a rig over its serial line, and nothing
//! about what the rig is for (that is the lab's).
//!
//! From the bottom up: `serial` (the port itself), `unreadable` (an intact line this bowl cannot
//! read), `link` (the port, or the socket of the monitor that holds it), `relay` (the monitor's
//! side of that socket), `request` (the one request loop: id matching, resends), `rig` (the
//! typed rig: `Rig::speed`, `Rig::status`, ...), `lines` (command lines built from words and
//! checked, answers described; the rig's states and faults in words are the types' own,
//! `model_core::wire::words`), `command_words` and `refusal` (a refused command in
//! particulars), `telemetry_csv` (the CSV log), `decode_stats` (the decoder's counters as JSON), `watchdog` (the note that a one-shot
//! `start` will meet the rig's host-silence watchdog).

pub mod command_words;
pub mod decode_stats;
pub mod lines;
pub mod link;
pub mod refusal;
pub mod relay;
pub mod request;
pub mod rig;
pub mod serial;
pub mod telemetry_csv;
pub mod unreadable;
pub mod watchdog;
