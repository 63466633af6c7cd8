//! One module per subcommand: its flags (clap) and `run`, over the libraries.

pub mod ports;
pub mod send;
pub mod serve;
