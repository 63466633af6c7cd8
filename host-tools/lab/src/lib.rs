//! The lab: what the rig is for. Predictions of the particle model (`predict`), charts
//! (`chart`), a plan of granule releases on a rig or the simulated one (`experiment`), the
//! rolling resistance and model choice fitted to measured residence times (`fit`), reports on the
//! controller against the simulated plant (`sim_reports`, `sim`), rig families (`family_file`).
//!
//! Built on model-core, the rig client (a rig on a serial line) and the virtual rig.

pub mod chart;
pub mod csv_lines;
pub mod experiment;
pub mod family_file;
pub mod fit;
pub mod number;
pub mod parallel;
pub mod predict;
pub mod results;
pub mod sim_reports;
pub mod usage;
