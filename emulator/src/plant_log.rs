//! The simulated plant's own record on the emulated board's semihosting console: the truth the
//! end-to-end tests check the rig's telemetry against.

/// One line of the plant's semihosting log: the simulation's truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantSample {
    /// Simulation time, ms.
    pub t_ms: u32,
    /// True speeds `[precession, spin]`, rad/s.
    pub speed_rad_s: [f32; 2],
    /// Duties the plant was driven with.
    pub duty: [f32; 2],
}

/// The `plant t_ms=.. w1=.. w2=.. d1=.. d2=..` lines of the semihosting console.
pub fn plant_truth(console: &[String]) -> Vec<PlantSample> {
    console
        .iter()
        .filter_map(|l| l.strip_prefix("plant "))
        .filter_map(|l| {
            let v: Vec<f32> = l
                .split_whitespace()
                .filter_map(|kv| kv.split_once('=').and_then(|(_, v)| v.parse().ok()))
                .collect();
            (v.len() == 5).then(|| PlantSample {
                t_ms: v[0] as u32,
                speed_rad_s: [v[1], v[2]],
                duty: [v[3], v[4]],
            })
        })
        .collect()
}
