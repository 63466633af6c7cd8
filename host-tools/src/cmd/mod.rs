//! One module per subcommand: its flags (clap) and `run`, over the libraries.

pub mod commission;
pub mod kinematics;
pub mod ports;
pub mod replay;
pub mod send;
pub mod serve;
pub mod sim;
