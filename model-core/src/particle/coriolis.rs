//! Residence time of the Coriolis model (paper Eq. 10, 11 with the corrected A, B of docs/model.md §3).

use super::flat::{acosh_1p_parts, acosh_1p_ratio};
use super::{
    Before, Exit, Model, Scene, SceneError, Shape, ShapeAt, condition, finite_time, phi_expm1,
};
use crate::Real;

/// Iterations allowed; it needs 1 or 2 on the rig's scenes (in f64 mostly 1, see
/// [`local_root_parts`]).
const MAX_NEWTON: u32 = 40;

/// Below this `m/s` the start that is first order in `m` is used; above it the
/// curvature-matched one.
pub(crate) const PERTURBATIVE_M: f64 = 0.25;

/// The start of the iteration for `F(u) = x`.
///
/// With `m = k mu`, `F(u) = A e^u + B e^{-q u} - 1` (`A + B = 1`) expands to first order as
/// `cosh u - 1 + m (sinh u - u e^{-u})`, so `u = u0 - m (1 - u0 e^{-u0} / sinh u0)` with
/// `u0 = acosh(1 + x)` (the flat model's root, exact at `mu = 0`). `sinh u0 = sqrt(x (x + 2))`
/// and `e^{-u0} = 1 / (1 + x + sinh u0)` come with `u0` at no further transcendental cost; the
/// start is off by `O(m^2)`, so on the rig's scenes (`m` below 0.03) one Halley step lands within
/// rounding. For larger `m` the flat root scaled to the same curvature at 0,
/// `acosh(1 + x / (A (1 + q)))`, is the better start (docs/model.md §4).
///
/// Returns the start and an upper end for the bracket: the perturbative start is within
/// rounding of the root, so the bracket starts open above (no square root spent on it); the
/// other start comes with `sqrt(2 x / A)` (`F >= A u^2 / 2`, docs/model.md §4).
fn start<T: Real>(shape: &Shape<T>, x: T) -> (T, T) {
    // m / s, which is m to second order.
    let m = T::TWO * shape.a_coef - T::ONE;
    if m < T::from_f64(PERTURBATIVE_M) {
        let (u0, w) = acosh_1p_parts(x, T::ONE);
        let decay = if w > T::ZERO {
            u0 / ((T::ONE + x + w) * w)
        } else {
            T::ONE
        };
        ((u0 - m * (T::ONE - decay)).max(T::ZERO), T::INFINITY)
    } else {
        let upper = (T::TWO * x / shape.a_coef).sqrt();
        let u = acosh_1p_ratio(x, shape.a_coef * (T::ONE + shape.q)).min(upper);
        (u, upper)
    }
}

/// The root `u = l1 T` of `F(u) = x`, with `F` of [`Shape::eval`], and `expm1(-q u)` at the root
/// (for the exit velocity's identity in [`residence`]).
///
/// `F` is convex and increasing with `F'(0) = 0`. Every iterate is clamped to a bracket of the
/// root (from [`start`]), which shrinks as each evaluation tells on which side its point lies.
///
/// Each step is Halley's, `d / (1 - d F'' / (2 F'))` with the Newton step `d = (F - x) / F'`
/// (the derivatives come with `F` from the same two exponentials). Its error is `C h^3` with
/// `C = F''' / (6 F') - (F'' / (2 F'))^2`: we stop when that is below a quarter of an ulp of `u`.
/// Far from the root (`d F'' / F'` not small) it takes Newton's step; where `F` is a factor off
/// `x` with `u > 1`, `F` behaves like `A e^u` and we step by `ln(x / F)` (`F <= A e^u`,
/// docs/model.md §4's `ln((1 + x) / A)` bound). In f64, where Halley's step is not yet within
/// rounding, the expansion of `F` at the same point usually is ([`local_root_parts`]): one
/// evaluation instead of two on the batch's scenes. An iteration that has not converged is an
/// error, never a result.
pub(crate) fn solve_u<T: Real>(shape: &Shape<T>, x: T) -> Result<(T, T), SceneError> {
    let mut search = Search::new(shape, x);
    loop {
        if let Some(done) = search.step(shape, x) {
            return done;
        }
    }
}

/// One root search of [`solve_u`] between its iterations, so that a batch can advance several
/// scenes' searches in turn ([`times_s`]).
#[derive(Clone, Copy)]
pub(crate) struct Search<T> {
    lower: T,
    upper: T,
    u: T,
    iterations_left: u32,
}

impl<T: Real> Search<T> {
    pub(crate) fn new(shape: &Shape<T>, x: T) -> Self {
        let (u, upper) = start(shape, x);
        Self {
            lower: T::ZERO,
            upper,
            u,
            iterations_left: MAX_NEWTON,
        }
    }

    /// One iteration of [`solve_u`]: `None` while it goes on, then the root and `expm1(-q u)`
    /// there, or the error.
    pub(crate) fn step(&mut self, shape: &Shape<T>, x: T) -> Option<Result<(T, T), SceneError>> {
        if self.iterations_left == 0 {
            return Some(Err(SceneError::NoConvergence));
        }
        self.iterations_left -= 1;
        let far = T::from_f64(4.0);
        let quarter_ulp = T::from_f64(0.25) * T::EPSILON;
        let u = self.u;
        let e = shape.eval_parts(u);
        let (f, fp, fpp) = (e.f, e.fp, e.fpp);
        // F and F' are below F'' + 1 (both exponentials enter F'' with positive weights), so
        // a finite F'' vouches for all three.
        if !fpp.is_finite() {
            return Some(Err(SceneError::OutOfRange));
        }
        if fp <= T::ZERO {
            // Only at u = 0, i.e. x = 0 (R - ri underflowed against ri - a): T = 0.
            return Some(Ok((u, e.decay_m1)));
        }
        if f < x {
            self.lower = u;
        } else {
            self.upper = u;
        }
        if u > T::ONE && (f > far * x || x > far * f) {
            self.u = (u - (f / x).ln()).max(self.lower).min(self.upper);
            return None;
        }
        // One division for the three ratios to F' (a division costs what a dozen products do).
        let per_fp = T::ONE / fp;
        let d = (f - x) * per_fp;
        let half_curv = T::HALF * fpp * per_fp;
        let bend = d * half_curv;
        let halley = bend.abs() < T::HALF;
        let step = if halley { d / (T::ONE - bend) } else { d };
        let next = (u - step).max(self.lower).min(self.upper);
        let converged = if halley {
            let c = (e.fppp * T::from_f64(1.0 / 6.0) * per_fp - half_curv * half_curv).abs();
            c * step * step * step.abs() <= quarter_ulp * next
        } else {
            fpp * d * d <= T::HALF * T::EPSILON * fp * next
        };
        if converged {
            // expm1(-q next) from expm1(-q u): e^{-q next} = e^{-q u} e^{-q (next - u)}, the
            // last factor to third order (the step is below eps^(1/3) u).
            let z = -shape.q * (next - u);
            let em1 = z * (T::ONE + z * (T::HALF + z * T::from_f64(1.0 / 6.0)));
            return Some(Ok((next, e.decay_m1 + (T::ONE + e.decay_m1) * em1)));
        }
        // In f32 (the MCU) Halley's first step is within rounding on the rig's scenes, and the
        // polynomial's code alone costs some 17 Cortex-M4F instructions a call: f64 only.
        if halley
            && !T::is_single_precision()
            && let LocalRoot { root, found: true } =
                local_root_parts(shape, &e, u, f - x, next - u, half_curv)
            && root >= self.lower
            && root <= self.upper
        {
            // As above, the last factor in full (the step may reach 1e-2 u).
            let em1 = phi_expm1(-shape.q * (root - u)).1;
            return Some(Ok((root, e.decay_m1 + (T::ONE + e.decay_m1) * em1)));
        }
        self.u = next;
        None
    }
}

/// What [`local_root_parts`] found.
pub(crate) struct LocalRoot<T> {
    /// The first accepted root (meaningless unless `found`).
    pub root: T,
    /// A root was accepted.
    pub found: bool,
}

/// The root from `F`'s Taylor expansion at `u` to fifth order, where that is within rounding of
/// the root (`found`; otherwise the search evaluates `F` again at Halley's point).
///
/// Every derivative of `F` comes from the two exponentials of the evaluation at `u`
/// (`F^(n) = A (e^u + (-1)^n q^(n-1) e^{-q u})`), so where Halley's step alone is not yet
/// within rounding (a start off by more than about `eps^(1/3)`, the rig's larger `mu`) the
/// polynomial takes the place of a second evaluation: Newton on it from Halley's point
/// (`delta`), `g = F(u) - x`, `half_curv = F'' / (2 F')`. Accepted when Newton's last
/// correction `c` leaves an error `F'' c^2 / (2 F')` and the expansion's remainder `F^(6) delta^6 / 720 / F'` (bounded with
/// `F^(6)` at `u` doubled, for `q |delta| <= 1/2`) both below a quarter of an ulp of the root.
///
/// No branch, for the batch's SIMD lanes as well (`coriolis_batch`): all three Newton
/// corrections are computed and the first accepted one kept (the ones after it do not change
/// it), and the test that `delta` is small enough is folded into `found`.
#[inline(always)]
pub(crate) fn local_root_parts<T: Real>(
    shape: &Shape<T>,
    e: &ShapeAt<T>,
    u: T,
    g: T,
    delta: T,
    half_curv: T,
) -> LocalRoot<T> {
    let (q, a) = (shape.q, shape.a_coef);
    let near = (delta * q.max(T::ONE)).abs() <= T::HALF;
    let q2 = q * q;
    let f4 = a * (e.grow + q2 * e.decay);
    let f5 = a * (e.grow - q2 * q * e.decay);
    let f6 = a * (e.grow + q2 * q2 * e.decay);
    let c2 = T::HALF * e.fpp;
    let c3 = e.fppp * T::from_f64(1.0 / 6.0);
    let c4 = f4 * T::from_f64(1.0 / 24.0);
    let c5 = f5 * T::from_f64(1.0 / 120.0);
    let quarter_ulp = T::from_f64(0.25) * T::EPSILON;
    let mut d = delta;
    let mut found = LocalRoot {
        root: T::ZERO,
        found: false,
    };
    for _ in 0..3 {
        let r = g + d * (e.fp + d * (c2 + d * (c3 + d * (c4 + d * c5))));
        let dr = e.fp
            + d * (T::TWO * c2
                + d * (T::from_f64(3.0) * c3
                    + d * (T::from_f64(4.0) * c4 + d * T::from_f64(5.0) * c5)));
        let c = r / dr;
        d -= c;
        let root = u + d;
        let d3 = d * d * d;
        let remainder = f6 * d3 * d3 * T::from_f64(2.0 / 720.0);
        let limit = quarter_ulp * root;
        let accept =
            !found.found & ((half_curv * c * c).abs() <= limit) & (remainder <= limit * e.fp);
        if accept {
            found.root = root;
        }
        found.found |= accept;
    }
    found.found &= near;
    found
}

/// The root of `F(u) = x` for `x > 1/eps` (and for an `x` that overflows, e.g. a subnormal
/// `ri - a`): there `e^{-q u}` is below `eps` and `F(u) = A e^u + B e^{-q u} - (A + B)`
/// (docs/model.md §4) gives `u = ln(x / A) + ln(1 + (A + B)/x)` to rounding, with
/// `ln x = ln(R - ri) - ln(ri - a)` so that `x` itself is never formed. No iteration.
fn large_u<T: Real>(shape: &Shape<T>, rise: T, den: T) -> T {
    let sum = shape.a_coef + shape.b_coef;
    (rise.ln() - den.ln()) - shape.a_coef.ln() + sum * (den / rise)
}

/// What a Coriolis scene's root starts from (`a < ri < R`, checked by the caller).
#[derive(Clone, Copy)]
struct Setup<T> {
    shape: Shape<T>,
    /// `R - ri`.
    rise: T,
    /// `ri - a`.
    den: T,
    /// `x = (R - ri) / (ri - a)`, the right-hand side of `F(u) = x`.
    x: T,
}

impl<T: Real> Setup<T> {
    fn new(scene: &Scene<T>, a: T) -> Result<Self, SceneError> {
        let shape = Shape::new(scene, Model::Coriolis)?;
        let den = scene.ri_m - a;
        let rise = scene.rim_radius_m - scene.ri_m;
        Ok(Self {
            shape,
            rise,
            den,
            x: rise / den,
        })
    }

    /// The root and `expm1(-q u)` where no search is needed ([`large_u`]), else `None`.
    fn direct_root(&self) -> Option<(T, T)> {
        if self.x.is_finite() && self.x * T::EPSILON <= T::ONE {
            None
        } else {
            Some((large_u(&self.shape, self.rise, self.den), -T::ONE))
        }
    }
}

/// Scenes whose root searches a batch advances in turn.
const LANES: usize = 4;

/// One batch scene whose root is being searched.
#[derive(Clone, Copy)]
struct Lane<T> {
    shape: Shape<T>,
    x: T,
    omega_rad_s: T,
    search: Search<T>,
}

/// The residence times of `scenes` into `out` (paired in order), each bit for bit what
/// [`super::residence_time_s`] gives for it. One root search is a chain of dependent
/// exponentials and divisions that keeps the host's out-of-order core waiting; advancing
/// [`LANES`] independent searches in turn lets it overlap them (the batch closed form's
/// throughput, `bowl predict --batch --throughput`).
pub(crate) fn times_s<T: Real>(scenes: &[Scene<T>], out: &mut [Result<T, SceneError>]) {
    for (group, answers) in scenes.chunks(LANES).zip(out.chunks_mut(LANES)) {
        // Phase by phase across the lanes, so that each phase's lanes sit together in the
        // core's window.
        let mut setups: [Option<Setup<T>>; LANES] = [None; LANES];
        for ((scene, answer), setup) in group.iter().zip(answers.iter_mut()).zip(&mut setups) {
            *answer = match super::before_model(scene) {
                Ok(Before::Answer(time)) => Ok(time),
                Ok(Before::Leaves { a }) => match Setup::new(scene, a) {
                    Ok(ready) => {
                        *setup = Some(ready);
                        continue;
                    }
                    Err(e) => Err(e),
                },
                Err(e) => Err(e),
            };
        }
        let mut lanes: [Option<Lane<T>>; LANES] = [None; LANES];
        for (((scene, answer), setup), lane) in group
            .iter()
            .zip(answers.iter_mut())
            .zip(&setups)
            .zip(&mut lanes)
        {
            let Some(setup) = setup else { continue };
            match setup.direct_root() {
                Some((u, _)) => {
                    *answer = finite_time(u / (setup.shape.c1 * scene.omega_rad_s));
                }
                None => {
                    *lane = Some(Lane {
                        search: Search::new(&setup.shape, setup.x),
                        shape: setup.shape,
                        x: setup.x,
                        omega_rad_s: scene.omega_rad_s,
                    });
                }
            }
        }
        let mut searching = lanes.iter().filter(|l| l.is_some()).count();
        while searching > 0 {
            for (slot, answer) in lanes.iter_mut().zip(answers.iter_mut()) {
                let Some(lane) = slot else { continue };
                if let Some(done) = lane.search.step(&lane.shape, lane.x) {
                    let l1 = lane.shape.c1 * lane.omega_rad_s;
                    *answer = done.and_then(|(u, _)| finite_time(u / l1));
                    *slot = None;
                    searching -= 1;
                }
            }
        }
    }
}

/// Coriolis model, `a < ri < R` (checked by the caller). `T = u / l1`, `l1 = k omega/(s + k mu)`.
///
/// Exit velocity `r'(T) = (ri - a) l1 F'(u)` (paper Eq. 11: `(ri - a)(k omega/(2 s))
/// (e^{l1 T} - e^{l2 T})`) through the identity `F'(u) = x - (A + B) expm1(-q u)` (from
/// `F = A e^u + B e^{-q u} - (A + B) = x` and `B q = A`): `F'` from `e^u` would carry `u`'s
/// rounding times `u`; the identity depends on `u` only through a bounded term. Then
/// `r'(T) = l1 ((R - ri) - (ri - a)(A + B) expm1(-q u))`, which never forms `x`.
pub(crate) fn residence<T: Real>(scene: &Scene<T>, a: T) -> Result<Exit<T>, SceneError> {
    let setup = Setup::new(scene, a)?;
    let (shape, rise, den) = (setup.shape, setup.rise, setup.den);
    let (u, eb) = match setup.direct_root() {
        Some(root) => root,
        None => solve_u(&shape, setup.x)?,
    };
    let ri = scene.ri_m;
    let l1 = shape.c1 * scene.omega_rad_s;
    // (ri - a) F'(u), finite even where x is not.
    let den_fp = rise - den * (shape.a_coef + shape.b_coef) * eb;
    // kx = x / (u F'(u)); as x -> 0, F ~ A (1 + q) u^2 / 2, so the ratio tends to 1/2.
    let kx = if u * den_fp > T::ZERO {
        rise / (u * den_fp)
    } else {
        T::HALF
    };
    // The caller checks that these are finite.
    Ok(Exit {
        time: u / l1,
        radial: l1 * den_fp,
        condition: condition(kx, a, ri),
    })
}
