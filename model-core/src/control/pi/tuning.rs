//! The start's and the step-down's tuning: how hard a shaft at rest is pushed, when it counts
//! as stuck or quiet, what the integral keeps of what started it, and which first windows read
//! the load. Each value says what it was measured against (the rules are [`super`]'s "Breaking
//! stiction").
/// Duty the push adds above the kick's level by the time the expected-edge watch would fault
/// (from [`STUCK_PITCHES`] to the watch's pitches of model travel): it rises in proportion to
/// the reference, slowly where pulses are sparse and there is time, fast where the watch is
/// quick, so a healthy shaft carrying material the model does not know starts before the watch
/// faults it. What the push adds after a loaded shaft breaks away, until its first edge, is
/// this rate times that time (seed 7 p24's spin: broke away at 0.43 duty 1.60 s into the
/// start, its first edge at 1.97 s): at 0.12 that spin peaked 19 % past 1 rad/s, at 0.09
/// 11 %. 0.09 still starts every loaded shaft of family-60, seeds 3..9, 14, 21 and 22 before
/// the watch (no false fault in any start or step-down, docs/control.md, "The push's span").
pub const PUSH_SPAN_DUTY: f32 = 0.09;
/// The shaft counts as stuck once the plant model has turned this many pitches since the last
/// edge without a new one (a shaft following the model would have given one).
pub const STUCK_PITCHES: f32 = 1.2;
/// A shaft that moved counts as quiet (see `quiet` in
/// [`SpeedLoop::step`](super::SpeedLoop::step)) once the plant model has turned this many
/// pitches since the last edge: at most half the model's speed. At
/// [`STUCK_PITCHES`] it also pushed shafts dipping 15..20 % under 0.5 rad/s after a step-down,
/// whose next edge was coming (family-60 4 -> 0.5: 5 % settled <= 10 s 100 -> 97.5 %).
pub const QUIET_PITCHES: f32 = 1.5;
/// Share of what started the shaft (the push, or the kick) the integral keeps once it moves.
pub const PUSH_KEPT: f32 = 0.5;
/// The shortest window after a crawl that reads the load, s: a crawl (a shaft below a third
/// of its setpoint, the first two edges at least a second apart at 0.5 rad/s and 12 pulses a
/// revolution) against the windows of a start at 3 rad/s (0.17 s) or of a shaft that ran with
/// the ramp (0.5 s), through which the shaft was still accelerating: read as load, that
/// inertia cost overshoot (an unseen family's worst 4.3 -> 7.1 % at 3 rad/s).
pub const CRAWL_READ_MIN_S: f32 = 0.6;
/// The shortest first window of a kick-started shaft that reads the load (`take_start_load`),
/// s: a pitch of a 12-pulse wheel at up to 1 rad/s (0.52 s; the first measurement there spans
/// one pitch at the ~0.9 rad/s the shaft has reached, 0.55-0.6 s). At the crawl's 0.6 s most
/// of those windows were left to the loop, whose bandwidth at 1 rad/s (about 1 rad/s) took the
/// last 5 % of an unknown load 2-4 s to remove: family-60 0 -> 1 rad/s within 2 % by 3 s on
/// 72.5 % of axes, 80.8 % at 0.5 s (0.4 s: 79.2 %; docs/control.md, "The spin released at the
/// precession's first edge"). Since the kick is in the correction's history, 0.4 s: the
/// 0.4-0.5 s windows are those of light shafts the kick drove past 1 rad/s before their first
/// measurement, and read they take the kept kick away at once (family-60 p29's rod, 2 % settled
/// at 4.6 -> 2.6 s; docs/control.md, "The kick in the start's first window"). Windows at 2 rad/s
/// and above (0.26 s or less) are still left to the loop: the shaft may still accelerate
/// through them (0.25 s measured worse at 0 -> 2 and 0 -> 3 rad/s).
pub const START_READ_MIN_S: f32 = 0.4;
/// The least share of a start's first window that the shaft's mismatch against its model at
/// its first edge (decaying through the identified lag from there) makes up, for the start's
/// second reading (`read_second_window`): heavy shafts, whose first window is mostly their
/// start's transient. Below it the second reading is the second window read alone, which on
/// light shafts is the eccentric load's and the teeth's noise (every start's second window read
/// as a first: family-60 within 2 % by 3 s 100 -> 96.7 %; docs/control.md, "The start's second
/// reading"). At 0.15 and 0.25 the eleven families' shares summed 1074.1 and 1075.0, at 0.35
/// 1076.7 (1069.9 without the second reading).
pub const SECOND_READING_MISMATCH_SHARE: f32 = 0.35;
/// The least mismatch share for the start's second reading where it changes the load read by
/// more than [`SECOND_READING_CHANGE_SHARE`] of the reference: between this and
/// [`SECOND_READING_MISMATCH_SHARE`] a first window that read a rod running ahead of its model
/// (the kick's leap) as no load, or as a negative one, is read again, and a reading that moves
/// by no more than a window's noise is left to the loop. With current sense a heavy rod's
/// first window there read -0.077 rad/s where it needed +0.02 (seed 5 p48, `b1` 0.346), and
/// the loop took a second per e-fold of it: 2 % settled at 3.43 s (docs/control.md, "The
/// start's second reading where it moves the load"). From rest to 1 rad/s, summed shares
/// within 2 % by 3 s on the eleven families: with current sense 1083.4 -> 1088.4 (98 % on 8 ->
/// 10 of them), pulses only 1080.9 -> 1080.1; every second reading from 0.25 on, regardless
/// of what it changes: 1085.0 and 1080.1, more axes moved both ways.
pub const SECOND_READING_LESSER_MISMATCH_SHARE: f32 = 0.25;
/// How far the start's second reading must move the load read from the first alone, as a share
/// of the reference, where the mismatch share is below [`SECOND_READING_MISMATCH_SHARE`]: a few
/// percent is what a window of a light shaft reads from its eccentric load and its teeth.
pub const SECOND_READING_CHANGE_SHARE: f32 = 0.03;
/// The time constant the loop's model follows the reference with where the identified shaft
/// is slower (`lead` in [`SpeedLoop::step`](super::SpeedLoop::step)), s: the feedforward leads
/// the reference by `(tau / REFERENCE_TAU_S - 1) (r - r_p)`, which drives a shaft of lag `tau`
/// along a model of lag `REFERENCE_TAU_S` (wpilib's `kA` feedforward, on a first-order
/// reference). A heavy rod (tau 0.44 s) followed its own lag to 1 rad/s, within 2 % of the
/// model only after 1.7 s, and with the load its first window read still to come it settled
/// at 3.7 s. From rest to 1 rad/s on the eleven families the shares within 2 % by 3 s summed
/// 1076.7 without the lead, 1077.5 at 0.3 s, 1080.9 at 0.2 s and 1076.7 at 0.12 s, where the
/// worst overshoot on family-60 rose 2.7 -> 6.1 % (a lead on an identified lag longer than the
/// shaft's own drives it past; docs/control.md, "The reference's lead").
pub const REFERENCE_TAU_S: f32 = 0.2;
/// The duty the lead leaves below the duty limit: the feedback's room to correct.
pub const LEAD_MARGIN_DUTY: f32 = 0.05;
