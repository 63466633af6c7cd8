//! The closed forms' one shape `F(u)` (paper Eq. 6, 10; docs/model.md §3's corrected
//! coefficients), evaluated free of cancellation.

use super::phi::phi_expm1;
use super::{Model, Scene, SceneError};
use crate::Real;

/// The model's solution in one shape: with `u = l1 t` (`l1 = c1 omega`),
/// `r(t) = ri + (ri - a) F(u)`, `F(u) = A (e^u - 1) + B (e^{-q u} - 1)`, `A = B q`, `A + B = 1`.
///
/// Coriolis (Eq. 10, corrected): `m = k mu`, `s = sqrt(1 + m^2)`, `A = (1 + m/s)/2`,
/// `B = 1/(2 s (s + m))` (= `(1 - m/s)/2` without its cancellation), `q = (s + m)^2`,
/// `c1 = k/(s + m)`; so `l2 = -q l1 = -k omega (s + m)`. Flat (Eq. 6): `m = 0`, so
/// `A = B = 1/2`, `q = 1`, `c1 = k` and `F(u) = cosh u - 1`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Shape<T> {
    pub c1: T,
    pub a_coef: T,
    pub b_coef: T,
    pub q: T,
}

impl<T: Real> Shape<T> {
    pub(crate) fn new(scene: &Scene<T>, model: Model) -> Result<Self, SceneError> {
        let k = scene.k2.sqrt();
        match model {
            Model::Flat => Ok(Self {
                c1: k,
                a_coef: T::HALF,
                b_coef: T::HALF,
                q: T::ONE,
            }),
            Model::Coriolis => {
                let m = k * scene.mu;
                // s = sqrt(1 + m^2) without overflowing m^2.
                let s = if m <= T::ONE {
                    (T::ONE + m * m).sqrt()
                } else {
                    let inv = T::ONE / m;
                    m * (T::ONE + inv * inv).sqrt()
                };
                let shape = Self::coriolis(k, m, s);
                if shape.q.is_finite() && shape.c1 > T::ZERO && shape.b_coef > T::ZERO {
                    Ok(shape)
                } else {
                    Err(SceneError::OutOfRange)
                }
            }
        }
    }

    /// The Coriolis model's shape from `k`, `m = k mu` and `s = sqrt(1 + m^2)` (docs/model.md
    /// §3's corrected A and B): `c1 = k / (s + m)`, `A = (1 + m / s) / 2`,
    /// `B = 1 / (2 s (s + m))`, `q = (s + m)^2`.
    #[inline(always)]
    pub(crate) fn coriolis(k: T, m: T, s: T) -> Self {
        let sm = s + m;
        Self {
            c1: k / sm,
            a_coef: T::HALF * (T::ONE + m / s),
            b_coef: T::HALF / (s * sm),
            q: sm * sm,
        }
    }

    /// `(F(u), F'(u), F''(u))` for `u >= 0`, free of cancellation (see `phi`):
    /// `F = A phi(u) + B phi(-q u)`, `F' = A (expm1(u) - expm1(-q u))`,
    /// `F'' = A (e^u + q e^{-q u})`.
    #[inline]
    pub(crate) fn eval(&self, u: T) -> (T, T, T) {
        let e = self.eval_parts(u);
        (e.f, e.fp, e.fpp)
    }

    /// [`Self::eval`], `F''' = A (e^u - q^2 e^{-q u})` and `expm1(-q u)`, from the same two
    /// exponentials.
    #[inline]
    pub(crate) fn eval_parts(&self, u: T) -> ShapeAt<T> {
        self.eval_parts_by(u, phi_expm1)
    }

    /// [`Self::eval_parts`] with `phi` for `(phi(z), expm1(z))` (the batch's lanes compute it
    /// without a branch).
    #[inline(always)]
    pub(crate) fn eval_parts_by(&self, u: T, phi: impl Fn(T) -> (T, T)) -> ShapeAt<T> {
        let (pa, ea) = phi(u);
        let qu = self.q * u;
        let (pb, eb) = phi(-qu);
        // For q u >= 1, B phi(-q u) = B expm1(-q u) + A u (as B q = A): no B * (q u) overflow.
        let b_term = if qu < T::ONE {
            self.b_coef * pb
        } else {
            self.b_coef * eb + self.a_coef * u
        };
        let grow = T::ONE + ea;
        let decay = self.q * (T::ONE + eb);
        ShapeAt {
            f: self.a_coef * pa + b_term,
            fp: self.a_coef * (ea - eb),
            fpp: self.a_coef * (grow + decay),
            fppp: self.a_coef * (grow - self.q * decay),
            decay_m1: eb,
            grow,
            decay,
        }
    }
}

/// `F` and its derivatives at one point, and `expm1(-q u)` (see [`Shape::eval_parts`]).
pub(crate) struct ShapeAt<T> {
    pub f: T,
    pub fp: T,
    pub fpp: T,
    pub fppp: T,
    pub decay_m1: T,
    /// `e^u`.
    pub grow: T,
    /// `q e^{-q u}`.
    pub decay: T,
}
