//! `bowl predict`: its flags; the predictions and their printing are the lab's
//! ([`lab::predict`]), over the typed [`lab::predict::Inputs`] these flags give.

use anyhow::Result;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use lab::predict::{
    self as lp, BowlInputs, Given, Inputs, MethodChoice, ModelChoice, RollingInputs, RunsOn,
};

/// A choice among named values, each with its help line: the typed value of the lab's enum.
type Choices<T> = &'static [(&'static str, &'static str, T)];

/// `--model`'s values.
const MODELS: Choices<ModelChoice> = &[
    (
        "auto",
        "The chooser picks the least model the scene needs (the tolerance from --tolerance or \
         --uncertainty) and says why; with the tilted bowl's flags (--precession-rad-s, \
         --spin-rad-s, --axes-angle-deg or --rig-file) over the whole hierarchy: incline, \
         rolling, rolling-or-sliding, bowl (--tolerance, default 0.01)",
        ModelChoice::Auto,
    ),
    (
        "flat",
        "Paper Eq. 5 to 7: no Coriolis term",
        ModelChoice::Flat,
    ),
    (
        "coriolis",
        "Paper Eq. 9 to 11 with the corrected A, B",
        ModelChoice::Coriolis,
    ),
    ("both", "Both, side by side", ModelChoice::Both),
    (
        "rolling",
        "The granule rolling on the tilted, precessing bowl (docs/model.md §9): needs \
         --precession-rad-s, --spin-rad-s and --axes-angle-deg",
        ModelChoice::Rolling,
    ),
    (
        "bowl",
        "The granule rolling or sliding in the real bowl, wall and lip included (docs/model.md \
         §10): the rolling model's flags and --sliding-mu, --wall-angle-deg, --wall-height-m, \
         --fillet-radius-m, --restitution, --max-time-s",
        ModelChoice::Bowl,
    ),
];

/// `--method`'s values.
const METHODS: Choices<MethodChoice> = &[
    (
        "closed",
        "The closed forms (log1p / bracketed Newton): exact to rounding",
        MethodChoice::Closed,
    ),
    (
        "euler",
        "Explicit Euler with fixed step --step-s",
        MethodChoice::Euler,
    ),
    (
        "semi-implicit",
        "Semi-implicit (symplectic) Euler with fixed step --step-s",
        MethodChoice::SemiImplicit,
    ),
    (
        "rk4",
        "Classical Runge-Kutta 4 with fixed step --step-s",
        MethodChoice::Rk4,
    ),
    (
        "dp54",
        "Adaptive Dormand-Prince 5(4) with tolerance --tol, dense-output event location",
        MethodChoice::Dp54,
    ),
];

/// `--target`'s values.
const TARGETS: Choices<RunsOn> = &[
    ("host", "The PC, f64, priced in nanoseconds", RunsOn::Host),
    (
        "mcu",
        "The Cortex-M4F, f32, priced in executed instructions",
        RunsOn::Mcu,
    ),
];

/// The parser of one of `table`'s names, to its value (clap lists the names and their help).
fn choice<T: Copy + Send + Sync + 'static>(table: Choices<T>) -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(
        table
            .iter()
            .map(|&(name, help, _)| PossibleValue::new(name).help(help)),
    )
    .map(move |name: String| {
        table
            .iter()
            .find(|(n, ..)| *n == name)
            .map(|&(.., v)| v)
            .expect("clap accepts only the table's names")
    })
}

/// Flags of `bowl predict`.
#[derive(clap::Args)]
pub struct Args {
    /// Combined bowl speed omega (paper Eq. 2), rad/s, of the paper's level-bowl models
    /// [default: 3]. The tilted bowl's models take --precession-rad-s and --spin-rad-s instead.
    #[arg(long, value_parser = crate::cmd::number, visible_alias = "w-rad-s")]
    omega_rad_s: Option<f64>,
    /// Effective rolling resistance coefficient mu (the paper's literal 0.4 makes nothing move)
    /// [default: 0.029, or with --rig-file its [particle] mu].
    #[arg(long, value_parser = crate::cmd::number)]
    mu: Option<f64>,
    /// Start radius ri, m (the particle starts at rest) [default: 0.05, or with --rig-file its
    /// [particle] release_radius_m].
    #[arg(long, value_parser = crate::cmd::number)]
    ri_m: Option<f64>,
    /// Rim radius R, m (0.1 m: a 200 mm bowl, reading the paper's sizes as diameters)
    /// [default: 0.1]. A rig file sets it (its [bowl] rim_radius_m): not both.
    #[arg(long, value_parser = crate::cmd::number, visible_alias = "r-m")]
    rim_radius_m: Option<f64>,
    /// Gravity, m/s^2.
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 9.81)]
    g: f64,
    /// k2 = m rp^2 / (I + m rp^2): 5/7 solid sphere, 3/5 hollow [default: 5/7, or with
    /// --rig-file its [particle] k2].
    #[arg(long, value_parser = crate::cmd::number)]
    k2: Option<f64>,
    /// Model: auto (the chooser), flat, coriolis, both or rolling.
    #[arg(long, value_parser = choice(MODELS), default_value = "auto")]
    model: ModelChoice,
    /// The chooser: relative tolerance on T (0.01 = 1 %).
    #[arg(long, value_parser = crate::cmd::number, conflicts_with = "uncertainty")]
    tolerance: Option<f64>,
    /// The chooser: the parameters' uncertainty, `mu=REL,radius_m=M,omega=REL` (default
    /// mu=0.2,radius_m=0.001,omega=0.01); the tolerance is a tenth of the spread it causes in T.
    #[arg(long, value_name = "mu=REL,radius_m=M,omega=REL")]
    uncertainty: Option<String>,
    /// The bowl speed from a logged run (bowl monitor --log, bowl replay --csv): the chooser
    /// decides between the closed form at the mean speed and an integrator over the trace.
    #[arg(long, value_name = "RUN.csv")]
    omega_trace: Option<std::path::PathBuf>,
    /// With --omega-trace: the device time of the release, ms (default: the log's first row).
    #[arg(long, value_parser = crate::cmd::number, requires = "omega_trace")]
    release_at_ms: Option<f64>,
    /// A spin-up, as a tuned speed loop drives it: the bowl starts at this speed, rad/s, and
    /// approaches --omega-rad-s with --time-constant-s; the particle is released at t = 0.
    /// The chooser picks the model and the integrator (from its precomputed error table when
    /// --tolerance is given).
    #[arg(
        long,
        value_parser = crate::cmd::number,
        requires = "time_constant_s",
        conflicts_with_all = ["omega_trace", "batch", "target_time_s"]
    )]
    spin_up_from_rad_s: Option<f64>,
    /// With --spin-up-from-rad-s: the spin-up's time constant, s.
    #[arg(long, value_parser = crate::cmd::number, requires = "spin_up_from_rad_s")]
    time_constant_s: Option<f64>,
    /// Method: closed form or one of the integrators [default: closed; the rolling
    /// and bowl models: dp54].
    #[arg(long, value_parser = choice(METHODS))]
    method: Option<MethodChoice>,
    /// Fixed step of euler / semi-implicit / rk4, s (default: 0.01 / omega; with the rolling
    /// model's rk4 0.001 s, the bowl model's 0.0001 s).
    #[arg(long, value_parser = crate::cmd::number, visible_alias = "step")]
    step_s: Option<f64>,
    /// Relative tolerance of dp54.
    #[arg(long, value_parser = crate::cmd::number, default_value_t = 1e-9)]
    tol: f64,
    /// Instead of the residence time: the bowl speed that gives this residence time, s.
    #[arg(long, value_parser = crate::cmd::number)]
    target_time_s: Option<f64>,
    /// The chooser: where the chosen plan runs: host (f64, priced in ns) or mcu (the
    /// Cortex-M4F: f32, priced in instructions).
    #[arg(long, value_parser = choice(TARGETS), default_value = "host")]
    target: RunsOn,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Batch mode: read scenes from this CSV file, one per row under a header naming the columns
    /// `model` (flat or coriolis), `w_rad_s` (the combined bowl speed, rad/s), `mu`, `ri_m` and
    /// `R_m` (the start and rim radii, m), optionally `g` (m/s^2) and `k2`, and any `label`,
    /// `id`, `note`, `label_*` or `note_*` columns (carried through).
    #[arg(long, requires = "out")]
    batch: Option<std::path::PathBuf>,
    /// Batch mode: write results to this CSV file.
    #[arg(long, requires = "batch", value_parser = crate::cmd::file_to_write)]
    out: Option<std::path::PathBuf>,
    /// Batch mode: also measure the closed forms' throughput over the file's scenes (the time
    /// alone, ns per scene on one thread and on every core; JSON on standard output).
    #[arg(long, requires = "batch")]
    throughput: bool,
    /// Batch mode: write every row, with a `status` column (`ok` or why the row was refused),
    /// instead of nothing when a row is refused; the exit status is still 1 if any row was.
    #[arg(long, requires = "batch")]
    keep_going: bool,
    /// The rolling model's own flags.
    #[command(flatten)]
    rolling: RollingArgs,
    /// The bowl model's own flags.
    #[command(flatten)]
    bowl: BowlArgs,
}

/// Flags of the rolling model (the shared ones: `--mu` is its rolling resistance, `--ri-m`,
/// `--rim-radius-m`, `--g`, `--k2`, `--method`, `--tol`, `--step-s`, `--json`).
#[derive(clap::Args, Debug, Clone)]
pub struct RollingArgs {
    /// Rolling model: precession speed omega1 of the bowl's axis about the vertical, rad/s.
    #[arg(long, value_parser = crate::cmd::number, allow_negative_numbers = true)]
    precession_rad_s: Option<f64>,
    /// Rolling model: spin speed omega2 of the bowl about its own axis, rad/s (negative: the
    /// other way, e.g. --spin-rad-s -2.7).
    #[arg(long, value_parser = crate::cmd::number, allow_negative_numbers = true)]
    spin_rad_s: Option<f64>,
    /// Rolling model: angle between the bowl's axis and the vertical, degrees (paper Eq. 2).
    #[arg(long, value_parser = crate::cmd::number)]
    axes_angle_deg: Option<f64>,
    /// Rolling model: granule radius a, m [default: 0.003]. A rig file sets it (its [bowl]
    /// particle_radius_m): not both.
    #[arg(long, value_parser = crate::cmd::number)]
    particle_radius_m: Option<f64>,
    /// Rolling model: the rod's horizontal offset L, the distance of the bowl's centre from the
    /// precession axis, m. Not the rod's length: a rod of length l at angle th from the
    /// vertical gives L = l sin(th) (l overstates L by 15 % at 60 deg). `--rod-length-m` is
    /// this flag's old name, kept as an alias.
    #[arg(long, value_parser = crate::cmd::number, visible_alias = "rod-length-m", default_value_t = 0.0)]
    rod_offset_m: f64,
    /// Rolling model: release azimuth from the downhill direction, degrees, or `all` (mean, min
    /// and max over 0, 30, ..., 330), or a list `B1,B2,..`.
    // Hyphen values: a list of negative azimuths (`-30,-60`) is not a number, so clap's
    // negative-number rule took it for a flag ("unexpected argument '-3'").
    #[arg(long, default_value = "all", allow_hyphen_values = true)]
    release_azimuth_deg: String,
    /// Rolling model: the friction coefficient the contact can give (slip beyond it is reported)
    /// [default: 0.4, or with --rig-file its [particle] sliding_mu].
    #[arg(long, value_parser = crate::cmd::number)]
    sliding_mu: Option<f64>,
    /// Rolling model: every member of the model hierarchy on this scene, its mean residence
    /// time and its difference from the full model, and the cheapest member within this
    /// relative tolerance (e.g. 0.05).
    #[arg(long, value_parser = crate::cmd::number, conflicts_with = "hierarchy_uncertainty_mu")]
    hierarchy_tolerance: Option<f64>,
    /// Rolling model: as --hierarchy-tolerance, the tolerance set by this uncertainty in the
    /// rolling resistance (the change of the full model's mean T when mu moves by it).
    #[arg(long, value_parser = crate::cmd::number)]
    hierarchy_uncertainty_mu: Option<f64>,
    /// Rolling model: with the hierarchy, judge each single release (the worst azimuth), not
    /// the mean over the releases.
    #[arg(long)]
    each_release: bool,
}

/// The bowl model's own flags (the scene's are the rolling model's; `--mu` is the rolling
/// resistance, `--sliding-mu` the contact's sliding coefficient).
#[derive(clap::Args, Debug, Clone)]
pub struct BowlArgs {
    /// Bowl model: the wall's angle from the bottom plane, degrees (90 = vertical; default 90
    /// or the rig file's).
    #[arg(long, value_parser = crate::cmd::number, allow_negative_numbers = true)]
    wall_angle_deg: Option<f64>,
    /// Bowl model: the wall's height above the bottom, m (0 = a bare rim at --rim-radius-m;
    /// default 0 or the rig file's).
    #[arg(long, value_parser = crate::cmd::number, allow_negative_numbers = true)]
    wall_height_m: Option<f64>,
    /// Bowl model: the fillet's radius between bottom and wall, m (0 = a sharp corner; default
    /// 0 or the rig file's).
    #[arg(long, value_parser = crate::cmd::number, allow_negative_numbers = true)]
    fillet_radius_m: Option<f64>,
    /// Bowl model: coefficient of restitution of the impact with a sharp corner's wall
    /// (default 0.5 or the rig file's).
    #[arg(long, value_parser = crate::cmd::number, allow_negative_numbers = true)]
    restitution: Option<f64>,
    /// Bowl model: follow each release this long, s; still inside then, it has not left.
    #[arg(long, value_parser = crate::cmd::number, allow_negative_numbers = true, default_value_t = 10.0)]
    max_time_s: f64,
    /// Bowl model: the bowl from a rig file's [bowl] table (docs/rigs/nominal.toml): its wall
    /// keys unless given as flags, its tilt unless --axes-angle-deg is given, and its bottom
    /// and granule radii in place of --rim-radius-m and --particle-radius-m.
    #[arg(long, value_name = "RIG.toml")]
    rig_file: Option<std::path::PathBuf>,
    /// Bowl model: also compute what speed can do (T over the rig's speed range and
    /// dT/domega, docs/model.md §11); on by default, `--speed-range false` skips it (ten more
    /// runs of the model).
    #[arg(long, default_value_t = true, action = clap::ArgAction::Set, value_name = "BOOL")]
    speed_range: bool,
    /// Bowl model: compute the residence-time table at the rig's own speed limits and split
    /// (read from PORT) and store it on the rig for `rtime table MS` (docs/model.md §11).
    #[arg(long, value_name = "PORT")]
    store_table: Option<String>,
}

impl Args {
    /// The flags as the lab's typed inputs.
    fn inputs(&self) -> Inputs {
        let r = &self.rolling;
        let b = &self.bowl;
        Inputs {
            omega_rad_s: self.omega_rad_s.unwrap_or(3.0),
            mu: self.mu.unwrap_or(0.029),
            ri_m: self.ri_m.unwrap_or(0.05),
            rim_radius_m: self.rim_radius_m.unwrap_or(0.1),
            g: self.g,
            k2: self.k2.unwrap_or(5.0 / 7.0),
            model: self.model,
            tolerance: self.tolerance,
            uncertainty: self.uncertainty.clone(),
            omega_trace: self.omega_trace.clone(),
            release_at_ms: self.release_at_ms,
            spin_up_from_rad_s: self.spin_up_from_rad_s,
            time_constant_s: self.time_constant_s,
            method: self.method.unwrap_or(MethodChoice::Closed),
            step_s: self.step_s,
            tol: self.tol,
            target_time_s: self.target_time_s,
            target: self.target,
            json: self.json,
            batch: self.batch.clone(),
            out: self.out.clone(),
            throughput: self.throughput,
            keep_going: self.keep_going,
            rolling: RollingInputs {
                precession_rad_s: r.precession_rad_s,
                spin_rad_s: r.spin_rad_s,
                axes_angle_deg: r.axes_angle_deg,
                particle_radius_m: r.particle_radius_m.unwrap_or(0.003),
                rod_offset_m: r.rod_offset_m,
                release_azimuth_deg: r.release_azimuth_deg.clone(),
                sliding_mu: r.sliding_mu.unwrap_or(0.4),
                hierarchy_tolerance: r.hierarchy_tolerance,
                hierarchy_uncertainty_mu: r.hierarchy_uncertainty_mu,
                each_release: r.each_release,
            },
            given: Given {
                omega_rad_s: self.omega_rad_s.is_some(),
                ri_m: self.ri_m.is_some(),
                rim_radius_m: self.rim_radius_m.is_some(),
                particle_radius_m: r.particle_radius_m.is_some(),
                method: self.method.is_some(),
                mu: self.mu.is_some(),
                k2: self.k2.is_some(),
                sliding_mu: r.sliding_mu.is_some(),
            },
            bowl: BowlInputs {
                wall_angle_deg: b.wall_angle_deg,
                wall_height_m: b.wall_height_m,
                fillet_radius_m: b.fillet_radius_m,
                restitution: b.restitution,
                max_time_s: b.max_time_s,
                rig_file: b.rig_file.clone(),
                speed_range: b.speed_range,
                store_table: b.store_table.clone(),
            },
        }
    }
}

/// Runs `bowl predict`.
pub fn run(args: &Args) -> Result<()> {
    lp::run(&args.inputs())
}
