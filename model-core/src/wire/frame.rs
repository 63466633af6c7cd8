//! One frame, in either direction: the plain data of [`super::types`], a command of
//! [`super::commands`] or the parameter values of [`super::params`] with its kind letter.

use super::commands::Command;
use super::params::ParamValues;
use super::types::{
    AxisModel, GateEvent, Hello, Reason, ResidenceModel, Status, Telemetry, Wrapping16,
};

/// One decoded frame, in either direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Frame {
    /// `$T1`: periodic telemetry (device to PC).
    Telemetry(Telemetry),
    /// `$H1`: boot announcement (device to PC).
    Hello(Hello),
    /// `$C1`: a command with its request id (PC to device).
    Command {
        /// Request id chosen by the PC, echoed in the answer.
        id: Wrapping16,
        /// The command.
        command: Command,
    },
    /// `$A1`: the command with this id was done.
    Ack {
        /// Request id.
        id: Wrapping16,
    },
    /// `$R1`: the command with this id was rejected and changed nothing.
    Reject {
        /// Request id (0 if the command was too broken to read one).
        id: Wrapping16,
        /// Why.
        reason: Reason,
    },
    /// `$S1`: the answer to STATUS.
    Status {
        /// Request id.
        id: Wrapping16,
        /// The status.
        status: Status,
    },
    /// `$P1`: the answer to PARAMS, every value in [`ParamId::ALL`](super::ParamId::ALL) order.
    Params {
        /// Request id.
        id: Wrapping16,
        /// The values.
        values: ParamValues,
    },
    /// `$E1`: a gate event (device to PC).
    Event(GateEvent),
    /// `$W1`: the answer to RTIME: the model that answered (`FLAT`, `CORI` or `TABLE`) and the motor
    /// setpoints it chose, mrad/s.
    ResidenceSet {
        /// Request id.
        id: Wrapping16,
        /// The model that answered.
        model: ResidenceModel,
        /// Precession setpoint, mrad/s.
        precession_mrad_s: i16,
        /// Spin setpoint, mrad/s.
        spin_mrad_s: i16,
    },
    /// `$M1`: the answer to MODELS, precession then spin.
    Models {
        /// Request id.
        id: Wrapping16,
        /// Per axis, precession then spin.
        axes: [AxisModel; 2],
    },
}

impl Frame {
    /// The request id this frame answers, if it is an answer.
    pub fn answer_id(&self) -> Option<Wrapping16> {
        match *self {
            Frame::Ack { id }
            | Frame::Reject { id, .. }
            | Frame::Status { id, .. }
            | Frame::Params { id, .. }
            | Frame::ResidenceSet { id, .. }
            | Frame::Models { id, .. } => Some(id),
            _ => None,
        }
    }
}
