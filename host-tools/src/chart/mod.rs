//! `bowl chart`: the speed-against-accuracy chart and the paper-style figures (issue 3).

pub mod plot;
pub mod reference;
