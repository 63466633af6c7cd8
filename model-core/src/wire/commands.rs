//! The commands: ONE table. Each row gives the command's name in the code, its token on the
//! wire (and, lower case, the word a person types), its fields (name with unit, unit, range or
//! tokens, words for people), the answer it gets, the controller states that allow it and what
//! it does; [`Command`], [`CommandKind`], the encoder's and the decoder's command fields,
//! [`Command::from_words`] and the refusal words ([`Refusal`](super::Refusal), both in [`super::typed`]) and
//! docs/protocol.md's command table (checked by `model-core/tests/wire_doc.rs`) are made from
//! it. To add a command, add a row (the device's `execute` and the host's callers are
//! exhaustive `match`es, so the compiler points there).
//!
//! A field's range is the protocol's: a value outside it is refused whatever the rig's settings
//! (`RANGE`, never clamped), on the rig by the decoder and on the PC before sending. A field
//! with a `limit` is further bounded by that parameter's value in force, which only the rig
//! knows and checks.

use super::params::ParamId;
use super::types::{DeviceState, Injection, RESIDENCE_MAX_MS, ResidenceModel};

mod parse;
pub use parse::{FieldProblem, parse_int};

/// How a command field is written and which values it takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldKind {
    /// A canonical integer in `min..=max`; with `limit`, the rig also refuses values above that
    /// parameter's value in force.
    Int {
        /// The smallest value.
        min: i64,
        /// The largest value.
        max: i64,
        /// The parameter that bounds it further on the rig, if any.
        limit: Option<ParamId>,
    },
    /// One of these tokens (its value is the position in the list).
    Choice(&'static [&'static str]),
    /// A parameter's token (its value is [`ParamId::index`]).
    ParamName,
    /// An integer in the range of the parameter named by the field before it.
    ParamValue,
}

/// One field of a command, after its word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    /// Its name in the code, with its unit (`precession_mrad_s`).
    pub name: &'static str,
    /// Its unit (`mrad/s`), empty for a token.
    pub unit: &'static str,
    /// What it is, in words (`the precession speed`, `a residence model`).
    pub what: &'static str,
    /// What it takes.
    pub kind: FieldKind,
}

/// The most fields a command has.
pub const MAX_FIELDS: usize = 2;

/// The answer a command gets when it is carried out (any command may instead be refused with
/// an `R` frame when [`CommandKind::refusable`], or when its fields are wrong).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Answer {
    /// `A`: done.
    Ack,
    /// `W`: the residence target was set: the model that answered and the setpoints chosen.
    ResidenceSet,
    /// `S`: the status.
    Status,
    /// `P`: every parameter value.
    Params,
    /// `M`: the motor models and loop gains.
    Models,
}

impl Answer {
    /// The frame's kind letter.
    pub const fn letter(self) -> u8 {
        match self {
            Answer::Ack => b'A',
            Answer::ResidenceSet => b'W',
            Answer::Status => b'S',
            Answer::Params => b'P',
            Answer::Models => b'M',
        }
    }
}

/// A set of controller states, one bit per [`DeviceState`] code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct States(u8);

impl States {
    /// Every state.
    pub const ANY: States = States(0b11_1111);
    /// Where a setpoint may change: idle (taken at START), changing speed, running.
    pub const SETPOINT: States = States::of(&[
        DeviceState::Idle,
        DeviceState::ChangingSpeed,
        DeviceState::Running,
    ]);
    /// Idle only.
    pub const IDLE: States = States::of(&[DeviceState::Idle]);
    /// Faulted only.
    pub const FAULTED: States = States::of(&[DeviceState::Faulted]);

    /// The set of these states.
    pub const fn of(states: &[DeviceState]) -> States {
        let mut bits = 0u8;
        let mut i = 0;
        while i < states.len() {
            bits |= 1 << states[i] as u8;
            i += 1;
        }
        States(bits)
    }

    /// Whether `state` is in the set.
    pub const fn contains(self, state: DeviceState) -> bool {
        self.0 & (1 << state as u8) != 0
    }
}

/// A Rust type a command field holds, and its value on the way through the table (an integer,
/// a token's position, a parameter's index).
pub trait FieldType: Copy {
    /// The value as the table handles it.
    fn to_value(self) -> i64;
    /// The field from a value the table has checked; `None` if it does not fit.
    fn from_value(value: i64) -> Option<Self>;
}

macro_rules! integer_field {
    ($($t:ty),*) => {$(
        impl FieldType for $t {
            fn to_value(self) -> i64 {
                self.into()
            }
            fn from_value(value: i64) -> Option<Self> {
                <$t>::try_from(value).ok()
            }
        }
    )*};
}
integer_field!(i16, i32, u32);

macro_rules! listed_field {
    ($($t:ty),*) => {$(
        impl FieldType for $t {
            fn to_value(self) -> i64 {
                self as i64
            }
            fn from_value(value: i64) -> Option<Self> {
                usize::try_from(value).ok().and_then(|i| <$t>::ALL.get(i)).copied()
            }
        }
    )*};
}
listed_field!(ResidenceModel, Injection, ParamId);

/// A field of integers `min..=max`.
const fn int(min: i64, max: i64) -> FieldKind {
    FieldKind::Int {
        min,
        max,
        limit: None,
    }
}

/// A speed field: 0 (stopped) up to the axis's `SPEED_MAX`, which is at most `i16::MAX`
/// (the limit's own range starts above the lowest speed; a speed of 0 is a stop).
const fn speed(limit: ParamId) -> FieldKind {
    FieldKind::Int {
        min: 0,
        max: limit.range().1 as i64,
        limit: Some(limit),
    }
}

macro_rules! command_table {
    ($(
        $(#[doc = $doc:literal])*
        $variant:ident: $token:literal, answer $answer:ident, refusable $refusable:literal,
        states $states:ident, changes $changes:literal, example $example:literal,
        meaning $meaning:literal
        $({ $(
            $(#[doc = $fdoc:literal])*
            $field:ident: $fty:ty = $kind:expr, $unit:literal, $what:literal;
        )* })?
    )*) => {
        /// A command from the PC (see the module docs for the table).
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub enum Command {
            $(
                $(#[doc = $doc])*
                #[doc = ""]
                #[doc = concat!("Token `", $token, "`, e.g. `", $example, "`.")]
                $variant $({ $(
                    $(#[doc = $fdoc])*
                    $field: $fty,
                )* })?,
            )*
        }

        /// Which command, without its fields: one per row of the table.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub enum CommandKind {
            $(
                #[doc = concat!("`", $token, "`.")]
                $variant,
            )*
        }

        /// Number of commands.
        pub const COMMAND_COUNT: usize = [$(CommandKind::$variant),*].len();

        impl CommandKind {
            /// Every command, in table order.
            pub const ALL: [CommandKind; COMMAND_COUNT] = [$(CommandKind::$variant),*];

            /// The wire token (upper case; a person types it in lower case).
            pub const fn token(self) -> &'static str {
                match self {
                    $(CommandKind::$variant => $token,)*
                }
            }

            /// The fields after the word, in wire order.
            pub const fn fields(self) -> &'static [Field] {
                match self {
                    $(CommandKind::$variant => {
                        const FIELDS: &[Field] = &[$($(Field {
                            name: stringify!($field),
                            unit: $unit,
                            what: $what,
                            kind: $kind,
                        },)*)?];
                        FIELDS
                    })*
                }
            }

            /// The answer when it is carried out.
            pub const fn answer(self) -> Answer {
                match self {
                    $(CommandKind::$variant => Answer::$answer,)*
                }
            }

            /// Whether the rig may refuse it with well-formed fields (state, limits, device).
            pub const fn refusable(self) -> bool {
                match self {
                    $(CommandKind::$variant => $refusable,)*
                }
            }

            /// The controller states in which the rig carries it out (`STATE` in the others).
            pub const fn states(self) -> States {
                match self {
                    $(CommandKind::$variant => States::$states,)*
                }
            }

            /// Whether it changes something on the rig (a query changes nothing, so it is
            /// answered afresh each time, never from the window of recent commands).
            pub const fn changes(self) -> bool {
                match self {
                    $(CommandKind::$variant => $changes,)*
                }
            }

            /// A command line as a person types it.
            pub const fn example(self) -> &'static str {
                match self {
                    $(CommandKind::$variant => $example,)*
                }
            }

            /// What it does, for docs/protocol.md's table.
            pub const fn meaning(self) -> &'static str {
                match self {
                    $(CommandKind::$variant => $meaning,)*
                }
            }
        }

        impl Command {
            /// Which row of the table.
            pub const fn kind(&self) -> CommandKind {
                match self {
                    $(Command::$variant { .. } => CommandKind::$variant,)*
                }
            }

            /// The field values in wire order, as the table handles them (unused slots 0).
            pub fn values(&self) -> [i64; MAX_FIELDS] {
                #[allow(unused_mut)]
                let mut out = [0i64; MAX_FIELDS];
                match *self {
                    $(Command::$variant $({ $($field),* })? => {
                        #[allow(unused_mut, unused_variables)]
                        let mut slots = out.iter_mut();
                        $($(
                            if let Some(slot) = slots.next() {
                                *slot = FieldType::to_value($field);
                            }
                        )*)?
                    })*
                }
                out
            }

            /// The command of `kind` with these values (each already checked against its
            /// field); `None` if one does not fit its type.
            pub fn from_values(kind: CommandKind, values: &[i64; MAX_FIELDS]) -> Option<Command> {
                #[allow(unused_mut, unused_variables)]
                let mut values = values.iter().copied();
                Some(match kind {
                    $(CommandKind::$variant => Command::$variant $({ $(
                        $field: <$fty as FieldType>::from_value(values.next()?)?,
                    )* })?,)*
                })
            }
        }
    };
}

command_table! {
    /// Set both motor setpoints, mrad/s (0 or up to the axis's SPEED_MAX).
    SetSpeeds: "SPEED", answer Ack, refusable true, states SETPOINT, changes true,
        example "speed 1800 2100",
        meaning "motor setpoints, each 0..=its `SPEED_MAX1_MRAD_S` / `SPEED_MAX2_MRAD_S`; the \
                 rig may also refuse a non-zero speed below what its sensor can measure (`RANGE`)"
    {
        /// Precession setpoint omega1, mrad/s.
        precession_mrad_s: i16 = speed(ParamId::SpeedMax1MradS), "mrad/s", "the precession speed";
        /// Spin setpoint omega2, mrad/s.
        spin_mrad_s: i16 = speed(ParamId::SpeedMax2MradS), "mrad/s", "the spin speed";
    }
    /// Choose the bowl speed whose predicted residence time is `time_ms`.
    SetResidence: "RTIME", answer ResidenceSet, refusable true, states SETPOINT, changes true,
        example "rtime cori 2500",
        meaning "choose the bowl speed for this residence time; the answer `$W1,id,MODEL,w1,w2` \
                 names the model that answered and the motor setpoints it chose (mrad/s); \
                 `INFEASIBLE` if no speed within the limits gives it. `TABLE`: the table of \
                 times the PC computed with the chosen model and stored in the `RT_*` \
                 parameters, inverted by interpolation; `INFEASIBLE` outside its times, when \
                 speed barely moves them (span under 1 %) or with no table stored"
    {
        /// Which model the target refers to.
        model: ResidenceModel = FieldKind::Choice(&ResidenceModel::TOKENS), "", "a residence model";
        /// Target residence time, ms.
        time_ms: u32 = int(1, RESIDENCE_MAX_MS as i64), "ms", "the residence time";
    }
    /// Run the motors towards the setpoints.
    Start: "START", answer Ack, refusable true, states IDLE, changes true, example "start",
        meaning "run towards the setpoints"
    /// Ramp the motors down (always accepted).
    Stop: "STOP", answer Ack, refusable false, states ANY, changes true, example "stop",
        meaning "ramp down (commissioning: stop at once); always accepted"
    /// Clear a fault (motors stay off).
    ClearFault: "CLEAR", answer Ack, refusable true, states FAULTED, changes true,
        example "clear",
        meaning "clear a fault (motors stay off); refused while the parameters in force are \
                 invalid"
    /// Set one parameter.
    SetParam: "SET", answer Ack, refusable true, states ANY, changes true,
        example "set MU_PPM 29000",
        meaning "set one parameter (table below), each when its part of the rig allows: the \
                 particle scene (`RIM_UM`, `START_UM`, `MU_PPM`, `K2_PPM`), the residence-time table \
                 (`RT_*`) and `TELEM_HZ` in any state, the loop bandwidths (`BWn_MRAD_S`, `PER_PULSEn_MILLI`) in any but \
                 commissioning, the rest while idle or faulted (`STATE` otherwise)"
    {
        /// Which parameter.
        id: ParamId = FieldKind::ParamName, "", "a parameter";
        /// The new value, in the parameter's unit.
        value: i32 = FieldKind::ParamValue, "", "the value";
    }
    /// Answered by a [`Frame::Status`](super::Frame::Status) frame.
    GetStatus: "STATUS", answer Status, refusable false, states ANY, changes false,
        example "status",
        meaning "state, fault, reset cause and counter, uptime, telemetry rate, flags"
    /// Answered by a PARAMS frame with every value.
    GetParams: "PARAMS", answer Params, refusable false, states ANY, changes false,
        example "params",
        meaning "every parameter value, in table order"
    /// A heartbeat; keeps the rig's host-silence watchdog from faulting.
    Ping: "PING", answer Ack, refusable false, states ANY, changes false, example "ping",
        meaning "heartbeat: keeps the host-silence watchdog from faulting (any command counts \
                 too)"
    /// Run the motor identification routine (from Idle).
    Commission: "COMMISSION", answer Ack, refusable true, states IDLE, changes true,
        example "commission",
        meaning "run the motor identification routine; follow it in telemetry (state `1` \
                 commissioning, back to `0` idle when done, `5` faulted if it failed)"
    /// Answered by a [`Frame::Models`](super::Frame::Models) frame: the motor models and loop
    /// gains in force.
    GetModels: "MODELS", answer Models, refusable true, states ANY, changes false,
        example "models",
        meaning "the motor models and speed-loop gains in force, per axis (added in a \
                 backwards-compatible way: a rig without it answers `UNKNOWN`)"
    /// Drop one granule at the start radius (the release solenoid; on a simulated rig, a
    /// simulated granule). The gates report its release and exit as `E` frames.
    Release: "RELEASE", answer Ack, refusable true, states ANY, changes true,
        example "release",
        meaning "drop one granule at the start radius; the gates then send `E` frames (release, \
                 then exit when it leaves). Simulated rigs (`bowl serve`, from the rig file's \
                 `[particle]` truth) drop a simulated granule, `STATE` while one is still in the \
                 bowl; the Black Pill energises its release solenoid for 40 ms, `STATE` while it \
                 is energised; a rig without a release solenoid answers `UNSUPPORTED`"
    /// Make the simulated rig misbehave.
    Inject: "INJECT", answer Ack, refusable true, states ANY, changes true,
        example "inject sensor2",
        meaning "virtual rig only: `SENSORn` withholds that sensor's pulses from the controller, \
                 `STALLn` cuts that motor's drive (its duty no longer reaches the simulated \
                 motor), `NONE` clears both; real hardware answers `UNSUPPORTED`"
    {
        /// What to inject.
        what: Injection = FieldKind::Choice(&Injection::TOKENS), "", "something to inject";
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_consistent() {
        for (i, kind) in CommandKind::ALL.into_iter().enumerate() {
            assert_eq!(kind as usize, i);
            assert_eq!(CommandKind::from_token(kind.token().as_bytes()), Some(kind));
            assert!(kind.fields().len() <= MAX_FIELDS, "{kind:?}");
            for field in kind.fields() {
                if let FieldKind::Int { min, max, .. } = field.kind {
                    assert!(min <= max, "{kind:?} {}", field.name);
                    // Units in names: the field's name ends in its unit.
                    assert!(!field.unit.is_empty(), "{kind:?} {}", field.name);
                }
            }
            // A query changes nothing and is never refused for the state.
            if !kind.changes() {
                assert_eq!(kind.states(), States::ANY, "{kind:?}");
            }
        }
        for (i, model) in ResidenceModel::ALL.into_iter().enumerate() {
            assert_eq!(ResidenceModel::TOKENS[i], model.token());
        }
        for (i, what) in Injection::ALL.into_iter().enumerate() {
            assert_eq!(Injection::TOKENS[i], what.token());
        }
    }
}
