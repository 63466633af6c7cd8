//! `f32` with micromath's approximate transcendental functions, to compare against libm on the
//! chart and on the Cortex-M4F (feature `micromath`).
//!
//! * [`MicroF32`]: everything micromath has (`sqrt`, `exp`, `ln`, `sin`, `cos`, `acos`),
//!   including its fast but rough `sqrt`.
//! * [`MicroF32HwSqrt`]: the same, but the correctly rounded square root of [`Real`] for `f32`
//!   (the FPU's VSQRT on the target): micromath's `sqrt` is far too rough for the model.
//!
//! micromath has no `expm1`, `log1p`, `cosh` or `sinh`; they are composed here the way a user
//! would, with the one classic guard that keeps `log1p` usable (Goldberg's
//! `ln(u) x / (u - 1)`, `u = 1 + x`). The model's own cancellation-free forms still apply on
//! top (see `particle::phi`).

use crate::Real;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};
use micromath::F32Ext;

macro_rules! micro_newtype {
    ($name:ident, $doc:literal, $sqrt:expr) => {
        #[doc = $doc]
        #[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
        pub struct $name(pub f32);

        impl Add for $name {
            type Output = Self;
            #[inline]
            fn add(self, o: Self) -> Self {
                Self(self.0 + o.0)
            }
        }
        impl Sub for $name {
            type Output = Self;
            #[inline]
            fn sub(self, o: Self) -> Self {
                Self(self.0 - o.0)
            }
        }
        impl Mul for $name {
            type Output = Self;
            #[inline]
            fn mul(self, o: Self) -> Self {
                Self(self.0 * o.0)
            }
        }
        impl Div for $name {
            type Output = Self;
            #[inline]
            fn div(self, o: Self) -> Self {
                Self(self.0 / o.0)
            }
        }
        impl Neg for $name {
            type Output = Self;
            #[inline]
            fn neg(self) -> Self {
                Self(-self.0)
            }
        }
        impl AddAssign for $name {
            #[inline]
            fn add_assign(&mut self, o: Self) {
                self.0 += o.0;
            }
        }
        impl SubAssign for $name {
            #[inline]
            fn sub_assign(&mut self, o: Self) {
                self.0 -= o.0;
            }
        }
        impl MulAssign for $name {
            #[inline]
            fn mul_assign(&mut self, o: Self) {
                self.0 *= o.0;
            }
        }

        impl Real for $name {
            const ZERO: Self = Self(0.0);
            const ONE: Self = Self(1.0);
            const TWO: Self = Self(2.0);
            const HALF: Self = Self(0.5);
            const EPSILON: Self = Self(f32::EPSILON);
            const INFINITY: Self = Self(f32::INFINITY);
            const MAX: Self = Self(f32::MAX);
            #[inline]
            fn from_f64(x: f64) -> Self {
                Self(x as f32)
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self.0 as f64
            }
            #[inline]
            fn is_finite(self) -> bool {
                Real::is_finite(self.0)
            }
            #[inline]
            fn is_nan(self) -> bool {
                self.0.is_nan()
            }
            #[inline]
            fn is_nonneg_finite(self) -> bool {
                self.0.is_nonneg_finite()
            }
            #[inline]
            fn is_in_unit_interval(self) -> bool {
                self.0.is_in_unit_interval()
            }
            #[inline]
            fn abs(self) -> Self {
                Self(f32::abs(self.0))
            }
            #[inline]
            fn sqrt(self) -> Self {
                let f: fn(f32) -> f32 = $sqrt;
                Self(f(self.0))
            }
            #[inline]
            fn exp(self) -> Self {
                Self(F32Ext::exp(self.0))
            }
            #[inline]
            fn exp_m1(self) -> Self {
                Self(F32Ext::exp(self.0) - 1.0)
            }
            #[inline]
            fn ln(self) -> Self {
                Self(F32Ext::ln(self.0))
            }
            #[inline]
            fn ln_1p(self) -> Self {
                let u = 1.0 + self.0;
                if u == 1.0 {
                    self
                } else {
                    Self(F32Ext::ln(u) * self.0 / (u - 1.0))
                }
            }
            #[inline]
            fn cosh(self) -> Self {
                let e = F32Ext::exp(self.0);
                Self(0.5 * (e + 1.0 / e))
            }
            #[inline]
            fn sinh(self) -> Self {
                let e = F32Ext::exp(self.0);
                Self(0.5 * (e - 1.0 / e))
            }
            #[inline]
            fn cos(self) -> Self {
                Self(F32Ext::cos(self.0))
            }
            #[inline]
            fn sin(self) -> Self {
                Self(F32Ext::sin(self.0))
            }
            #[inline]
            fn acos(self) -> Self {
                Self(F32Ext::acos(self.0))
            }
        }
    };
}

micro_newtype!(
    MicroF32,
    "`f32` with every function from micromath, its rough `sqrt` included.",
    |x| F32Ext::sqrt(x)
);
micro_newtype!(
    MicroF32HwSqrt,
    "`f32` with micromath's `exp`/`ln`/trigonometry and a correctly rounded `sqrt` (VSQRT).",
    |x| Real::sqrt(x)
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn micromath_sqrt_is_rough_ours_is_exact() {
        // Measured, not assumed: micromath's fast sqrt against the correctly rounded one.
        let mut worst: f64 = 0.0;
        for i in 1..1000 {
            let x = i as f32 * 0.01;
            let rough = MicroF32(x).sqrt().0 as f64;
            let exact = (x as f64).sqrt();
            worst = worst.max(((rough - exact) / exact).abs());
            assert_eq!(MicroF32HwSqrt(x).sqrt().0, (x as f64).sqrt() as f32);
        }
        assert!(worst > 1e-3, "micromath sqrt better than expected: {worst}");
    }

    /// Worst relative error of `f` against `want` over `xs`.
    fn worst(
        xs: impl Iterator<Item = f32>,
        f: impl Fn(f32) -> f32,
        want: impl Fn(f64) -> f64,
    ) -> f64 {
        xs.map(|x| ((f(x) as f64 - want(x as f64)) / want(x as f64)).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn micromath_accuracy_as_measured() {
        extern crate std;
        let exp = worst(
            (-80..80).map(|i| i as f32 * 0.1),
            |x| MicroF32(x).exp().0,
            f64::exp,
        );
        // ln: absolute error (its value crosses 0 at 1).
        let ln = (1..400)
            .map(|i| i as f32 * 0.037 + 0.01)
            .map(|x| (MicroF32(x).ln().0 as f64 - (x as f64).ln()).abs())
            .fold(0.0, f64::max);
        let sqrt = worst(
            (1..400).map(|i| i as f32 * 0.037),
            |x| MicroF32(x).sqrt().0,
            f64::sqrt,
        );
        let log1p = worst(
            (1..400).map(|i| i as f32 * 1e-3),
            |x| MicroF32(x).ln_1p().0,
            |x| x.ln_1p(),
        );
        std::println!(
            "micromath worst error: exp {exp:e} rel, ln {ln:e} abs, sqrt {sqrt:e} rel, \
             log1p (Goldberg) {log1p:e} rel"
        );
        // Far worse than libm's ~1 ulp (6e-8): the model's f32 target (2e-6) is out of reach.
        // Measured (micromath 2.1, these grids): exp 2.0e-3 rel, ln 0.12 abs (x in [0.05, 15]),
        // sqrt 6.0e-2 rel, log1p 5.7e-2 rel.
        assert!(exp > 1e-4 && exp < 1e-2, "exp {exp}");
        assert!(sqrt > 1e-2 && sqrt < 0.2, "sqrt {sqrt}");
        assert!(ln < 0.2 && log1p < 0.1, "ln {ln} log1p {log1p}");
    }
}
