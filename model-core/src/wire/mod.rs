//! The serial protocol between the rig and the PC: one text line per frame, shared by the
//! firmware and the host tools. The specification with worked examples is `docs/protocol.md`.
//!
//! A frame is `$`, a kind letter, the protocol version digit, comma-separated fields, `*`, the
//! CRC-32 of the bytes between `$` and `*` in 8 upper-case hex digits, and `\r\n`:
//!
//! ```text
//! $T1,123456,6172,2,0,1800,1796,4521,315,2100,2101,5230,367,3381,2345,2410*9B4507F3\r\n
//! ```
//!
//! Numbers are scaled integers (no float formatting on the MCU). The longest telemetry frame is
//! [`MAX_TELEMETRY_LEN`] bytes: 50 frames/s use 48 % of a 115 200 baud link.
//!
//! - [`types`]: the plain data (telemetry, status, states, reasons);
//! - [`words`]: the states, faults and reset causes in words (tokens for scripts, words for a
//!   person), methods of the types;
//! - [`params`]: the settable parameters, one table (token, unit, range, default);
//! - [`commands`]: the commands, one table (token, fields with units and ranges, answer, the
//!   states that allow it);
//! - [`typed`]: [`Command::from_words`] (the words a person types) and the refusal words;
//! - [`console`]: a command typed at a plain serial console, without `$`, id or CRC;
//! - [`frame`]: a frame in either direction;
//! - [`encode()`] and [`decode`]: the codec and the streaming [`Decoder`];
//! - [`device`]: the rig's side (command dispatch, telemetry pacing) over the [`device::Backend`] trait.

pub mod commands;
pub mod console;
pub mod crc;
pub mod decode;
pub mod device;
pub mod encode;
pub mod frame;
pub mod params;
pub mod stream;
pub mod typed;
pub mod types;
pub mod words;

pub use commands::{
    Answer, COMMAND_COUNT, Command, CommandKind, Field, FieldKind, FieldProblem, MAX_FIELDS, States,
};
pub use decode::{FrameError, decode_frame, parse_command_line, parse_line};
pub use encode::{EncodeError, encode};
pub use frame::Frame;
pub use params::*;
pub use stream::{DecodeStats, Decoder, REORDER_FRAMES};
pub use typed::{Refusal, split_words};
pub use types::*;

/// The protocol version in every frame header (`$T1`): one decimal digit.
pub const PROTOCOL_VERSION: u8 = 1;

/// The first byte of every frame.
pub const FRAME_START: u8 = b'$';

/// The last byte of every frame. Frames are sent with `\r` before it (`\r\n`, so every
/// serial console shows one line per frame); a line may also end at a lone `\r` (Enter typed
/// in a console) or a lone `\n`.
pub const FRAME_END: u8 = b'\n';

/// The carriage return that comes before [`FRAME_END`] in every frame sent, and ends a line on
/// its own too.
pub const LINE_END_CR: u8 = b'\r';

/// The longest frame, `$` to `\n` included (a PARAMS answer is the longest kind). The decoder
/// drops longer lines as oversize.
pub const MAX_FRAME_LEN: usize = 256;

/// The longest telemetry frame: every field at its widest, `\r\n` included.
pub const MAX_TELEMETRY_LEN: usize = 111;

/// The default link: 115 200 baud, 8N1 (10 bits a byte).
pub const DEFAULT_BAUD: u32 = 115_200;

/// Largest telemetry rate that keeps the longest telemetry frames under half of `baud` (8N1).
pub const fn max_telemetry_hz(baud: u32) -> u32 {
    baud / 10 / 2 / MAX_TELEMETRY_LEN as u32
}
