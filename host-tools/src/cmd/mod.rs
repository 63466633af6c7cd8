//! One module per subcommand: its flags (clap) and `run`, over the libraries.

pub mod chart;
pub mod commission;
pub mod experiment;
pub mod fit;
pub mod kinematics;
pub mod ports;
pub mod predict;
pub mod replay;
pub mod send;
pub mod serve;
pub mod sim;
