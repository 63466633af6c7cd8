//! The frame of the batch closed forms ([`super::residence_times_s`]): a cheap pass that
//! settles most scenes in SIMD lanes, then a model's costly lanes for the rest.
//!
//! In the paper's range most scenes never leave (about 96 % of random ones: mu up to the
//! paper's 0.4 holds the granule at every start inside the equilibrium radius `a = mu g /
//! omega^2`, docs/model.md §4). Deciding that needs no division: `ri <= a` is
//! `ri omega^2 <= mu g`, three products. The cheap pass computes, for [`LANES`] scenes at once
//! with no branch, whether each is valid, at the rim, or held with a margin of 8 epsilons
//! (which covers the roundings of both sides: `a` carries three, `ri omega^2` two; in f64 the
//! [`magnitude_limits`](super::magnitude_limits) keep every product a normal number, so the
//! margin is a relative one). Those answers are the one-scene path's bit for bit: 0 at the
//! rim, infinity when held. The rest (the granule may leave) go to the model's costly lanes
//! ([`Costly`]): in place when the whole group may leave, else gathered from group to group
//! into full groups of [`LANES`], so the costly arithmetic runs on full lanes in every regime.
//! A scene the costly lanes cannot answer on their path (invalid, within the margin of the
//! threshold, `x` beyond `1/epsilon`) is answered by the one-scene path itself.

use super::{Model, Scene, SceneError, residence_time_s};
use crate::Real;

/// Scenes per group: two AVX2 registers of f64 (one AVX-512 register), enough to hide the
/// latency of the divisions.
pub(crate) const LANES: usize = 8;

/// A model's costly lanes: the residence times of [`LANES`] scenes, each the one-scene answer
/// bit for bit ([`residence_time_s`] where a lane is off its path: at the rim, held, invalid,
/// near the threshold).
pub(crate) trait Costly {
    /// The model the lanes compute.
    const MODEL: Model;
    /// Every answer of `group` into `out`; returns how many scenes leave on the lanes' path.
    fn lanes<T: Real>(group: &[Scene<T>; LANES], out: &mut [Result<T, SceneError>; LANES])
    -> usize;
}

/// What the cheap pass found for a group, lane by lane, as masks of all ones or all zeros:
/// 64 bits a lane, as wide as an f64 lane, so the masks leave the SIMD registers in whole
/// vectors and come back lane by lane (as bytes they went out in halves and came back as one
/// load, which stalled on store forwarding: 14 % of the paper range's time).
struct Cheap {
    /// Refused or otherwise unusual: the one-scene path answers it (and names the refusal).
    one_scene: [u64; LANES],
    /// Valid and at (or beyond) the rim: T = 0.
    at_rim: [u64; LANES],
    /// Valid, inside the rim, the granule may leave: the costly lanes answer it.
    costly: [u64; LANES],
}

/// All ones for true, zero for false.
#[inline(always)]
fn mask(b: bool) -> u64 {
    u64::from(b).wrapping_neg()
}

/// The cheap pass over one group, with no branch. A valid scene inside the rim that is
/// neither here nor costly is held: T is infinite.
#[inline(always)]
fn cheap<T: Real>(group: &[Scene<T>; LANES]) -> Cheap {
    let mut found = Cheap {
        one_scene: [0; LANES],
        at_rim: [0; LANES],
        costly: [0; LANES],
    };
    let below = T::ONE - T::from_f64(8.0) * T::EPSILON;
    for (i, s) in group.iter().enumerate() {
        let valid = s.is_valid();
        let at_rim = s.ri_m >= s.rim_radius_m;
        // ri <= a = mu g / omega^2 (a infinite at omega = 0), by 8 epsilons. Only where the
        // magnitude limits keep the products normal numbers (f64): in f32, which has none, an
        // underflowing product could turn the margin round, so its costly lanes decide.
        let push = s.ri_m * s.omega_rad_s * s.omega_rad_s;
        let hold = s.mu * s.g_m_s2;
        let held = ((push < hold * below) & !T::is_single_precision()) | (s.omega_rad_s == T::ZERO);
        found.one_scene[i] = mask(!valid);
        found.at_rim[i] = mask(valid & at_rim);
        found.costly[i] = mask(valid & !at_rim & !held);
    }
    found
}

/// The costly lanes' answers: a regular lane's `time`, every other one the one-scene path's;
/// returns how many were regular. Two stores, not one of a merged value: the merge went
/// through the stack byte by byte and stalled every store after it.
#[inline(always)]
pub(crate) fn answer<T: Real>(
    group: &[Scene<T>; LANES],
    out: &mut [Result<T, SceneError>; LANES],
    time: [T; LANES],
    regular: [bool; LANES],
    model: Model,
) -> usize {
    let mut answered = 0;
    for (((scene, answer), time), regular) in group.iter().zip(out).zip(time).zip(regular) {
        if regular {
            *answer = Ok(time);
            answered += 1;
        } else {
            *answer = residence_time_s(scene, model);
        }
    }
    answered
}

/// The one-scene answer, out of the lanes' way (a lane that is refused or unusual).
#[cold]
#[inline(never)]
fn one_scene<T: Real>(scene: &Scene<T>, model: Model) -> Result<T, SceneError> {
    residence_time_s(scene, model)
}

/// Scenes waiting for a full group of costly lanes, and where their answers go.
struct Pending<T> {
    scenes: [Scene<T>; LANES],
    at: [usize; LANES],
    count: usize,
}

impl<T: Real> Pending<T> {
    /// The costly lanes over the waiting scenes (the unused lanes hold earlier or default
    /// scenes, whose answers are dropped), answers to their places in `out`.
    #[inline(always)]
    fn flush<C: Costly>(&mut self, out: &mut [Result<T, SceneError>]) {
        let mut answers = [Ok(T::ZERO); LANES];
        C::lanes(&self.scenes, &mut answers);
        for (&at, answer) in self.at.iter().zip(answers).take(self.count) {
            if let Some(slot) = out.get_mut(at) {
                *slot = answer;
            }
        }
        self.count = 0;
    }
}

/// [`residence_time_s`] with `C::MODEL` for every scene, into `out` (as many answers as both
/// have). Inlined so that a caller compiled for wider SIMD (the host's AVX2 path) compiles the
/// lanes for it too.
#[inline(always)]
pub(crate) fn times_s<T: Real, C: Costly>(scenes: &[Scene<T>], out: &mut [Result<T, SceneError>]) {
    let n = scenes.len().min(out.len());
    let (scenes, out) = (&scenes[..n], &mut out[..n]);
    let mut pending = Pending {
        scenes: [Scene::default(); LANES],
        at: [0; LANES],
        count: 0,
    };
    // While whole groups leave on the costly lanes' path, the next group goes to them first:
    // there the cheap pass would only add its work (2 ns a flat scene). A group with a scene
    // off that path (answered by the one-scene path) sends the frame back to the cheap pass.
    let mut leaving = false;
    let mut base = 0;
    while let Some(group) = scenes
        .get(base..)
        .and_then(|rest| rest.first_chunk::<LANES>())
    {
        let in_place = out
            .get_mut(base..)
            .and_then(|rest| rest.first_chunk_mut::<LANES>());
        if leaving && let Some(answers) = in_place {
            leaving = C::lanes(group, answers) == LANES;
            base += LANES;
            continue;
        }
        let found = cheap(group);
        if found.costly.iter().fold(u64::MAX, |all, &c| all & c) != 0 {
            if let Some(answers) = out
                .get_mut(base..)
                .and_then(|rest| rest.first_chunk_mut::<LANES>())
            {
                leaving = C::lanes(group, answers) == LANES;
            }
        } else {
            for (i, scene) in group.iter().enumerate() {
                let at = base + i;
                if found.costly[i] != 0 {
                    pending.scenes[pending.count] = *scene;
                    pending.at[pending.count] = at;
                    pending.count += 1;
                    if pending.count == LANES {
                        pending.flush::<C>(out);
                    }
                } else if found.one_scene[i] != 0 {
                    out[at] = one_scene(scene, C::MODEL);
                } else {
                    out[at] = Ok(if found.at_rim[i] != 0 {
                        T::ZERO
                    } else {
                        T::INFINITY
                    });
                }
            }
        }
        base += LANES;
    }
    if pending.count > 0 {
        pending.flush::<C>(out);
    }
    for (scene, answer) in scenes[base..].iter().zip(&mut out[base..]) {
        *answer = one_scene(scene, C::MODEL);
    }
}
