//! The floating-point operations the model needs, for `f32` (target) and `f64` (host).
//!
//! Why our own trait rather than `num-traits::Float`: on the Cortex-M4F the square root must be
//! the FPU's `VSQRT.F32` (a handful of cycles) instead of libm's software `sqrtf` (about 52
//! instructions), and we want every transcendental call to go through one place we can measure.

use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

pub mod exp;
pub mod log1p;
#[cfg(feature = "micromath")]
pub mod micro;

/// A real number type the model is generic over (`f32` or `f64`).
pub trait Real:
    Copy
    + PartialOrd
    + core::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// 2.
    const TWO: Self;
    /// 1/2.
    const HALF: Self;
    /// Machine epsilon.
    const EPSILON: Self;
    /// Positive infinity.
    const INFINITY: Self;
    /// Largest finite value.
    const MAX: Self;

    /// Converts from `f64` (rounding to nearest for `f32`).
    fn from_f64(x: f64) -> Self;
    /// Widens to `f64` (exact).
    fn to_f64(self) -> f64;
    /// True unless NaN or infinite.
    fn is_finite(self) -> bool;
    /// True if NaN.
    fn is_nan(self) -> bool;
    /// True for `+0`, `-0` and every finite positive value; false for NaN, infinities and
    /// negatives. One integer compare on the bits (input validation runs on every call).
    fn is_nonneg_finite(self) -> bool;
    /// True for `0 < x <= 1`; false for NaN and everything else. One integer compare on the
    /// bits (positive floats order as their bit patterns).
    fn is_in_unit_interval(self) -> bool;
    /// Absolute value.
    fn abs(self) -> Self;
    /// Square root (hardware `VSQRT` on the Cortex-M4F for `f32`).
    fn sqrt(self) -> Self;
    /// e^x.
    fn exp(self) -> Self;
    /// e^x for `|x| <= 700`, with no branch where a type has such a path (f64: the batch
    /// closed form's SIMD lanes); outside that range the value is meaningless.
    #[inline]
    fn exp_in_domain(self) -> Self {
        self.exp()
    }
    /// e^x - 1, accurate near 0.
    fn exp_m1(self) -> Self;
    /// Natural logarithm.
    fn ln(self) -> Self;
    /// ln(1 + x), accurate near 0.
    fn ln_1p(self) -> Self;
    /// ln(1 + x) for a finite `x > -1` that the caller has established: the closed forms'
    /// arguments are sums of non-negative finite values. Skips the domain checks where a type
    /// has a cheaper path (f32 on the MCU); outside the domain the value is meaningless.
    #[inline]
    fn ln_1p_in_domain(self) -> Self {
        self.ln_1p()
    }
    /// Single precision (f32 and its variants: the MCU's types), not f64 (the host's): where the
    /// two want different methods (instruction count against latency).
    #[inline]
    fn is_single_precision() -> bool {
        Self::EPSILON.to_f64() > 1e-10
    }
    /// Hyperbolic cosine.
    fn cosh(self) -> Self;
    /// Hyperbolic sine.
    fn sinh(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
    /// Sine.
    fn sin(self) -> Self;
    /// Arc cosine.
    fn acos(self) -> Self;

    /// The larger of two values (NaN-ignoring, like `f64::max`).
    #[inline]
    fn max(self, other: Self) -> Self {
        if self >= other || other.is_nan() {
            self
        } else {
            other
        }
    }
    /// The smaller of two values (NaN-ignoring, like `f64::min`).
    #[inline]
    fn min(self, other: Self) -> Self {
        if self <= other || other.is_nan() {
            self
        } else {
            other
        }
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const TWO: Self = 2.0;
    const HALF: Self = 0.5;
    const EPSILON: Self = f64::EPSILON;
    const INFINITY: Self = f64::INFINITY;
    const MAX: Self = f64::MAX;
    #[inline]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline]
    fn is_finite(self) -> bool {
        // One compare (NaN fails it); core's bit test costs ~20 instructions on the M4F.
        f64::abs(self) <= f64::MAX
    }
    #[inline]
    fn is_nan(self) -> bool {
        f64::is_nan(self)
    }
    #[inline]
    fn is_nonneg_finite(self) -> bool {
        let bits = self.to_bits();
        bits < 0x7FF0_0000_0000_0000 || bits == 0x8000_0000_0000_0000
    }
    #[inline]
    fn is_in_unit_interval(self) -> bool {
        // 1 <= bits <= bits(1.0): the positive values up to 1 (zero, signs and NaN wrap out).
        self.to_bits().wrapping_sub(1) < 0x3FF0_0000_0000_0000
    }
    #[inline]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline]
    fn sqrt(self) -> Self {
        sqrt_f64(self)
    }
    #[inline]
    fn exp(self) -> Self {
        exp::exp_f64(self)
    }
    #[inline]
    fn exp_in_domain(self) -> Self {
        exp::exp_in_domain_f64(self)
    }
    #[inline]
    fn exp_m1(self) -> Self {
        libm::expm1(self)
    }
    #[inline]
    fn ln(self) -> Self {
        libm::log(self)
    }
    #[inline]
    fn ln_1p(self) -> Self {
        log1p::ln_1p_f64(self)
    }
    #[inline]
    fn ln_1p_in_domain(self) -> Self {
        log1p::ln_1p_in_domain_f64(self)
    }
    #[inline]
    fn cosh(self) -> Self {
        libm::cosh(self)
    }
    #[inline]
    fn sinh(self) -> Self {
        libm::sinh(self)
    }
    #[inline]
    fn cos(self) -> Self {
        libm::cos(self)
    }
    #[inline]
    fn sin(self) -> Self {
        libm::sin(self)
    }
    #[inline]
    fn acos(self) -> Self {
        libm::acos(self)
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const TWO: Self = 2.0;
    const HALF: Self = 0.5;
    const EPSILON: Self = f32::EPSILON;
    const INFINITY: Self = f32::INFINITY;
    const MAX: Self = f32::MAX;
    #[inline]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline]
    fn is_finite(self) -> bool {
        // VABS + VCMP: core's bit-twiddling version costs ~20 instructions on the M4F.
        f32::abs(self) <= f32::MAX
    }
    #[inline]
    fn is_nan(self) -> bool {
        f32::is_nan(self)
    }
    #[inline]
    fn is_nonneg_finite(self) -> bool {
        let bits = self.to_bits();
        bits < 0x7F80_0000 || bits == 0x8000_0000
    }
    #[inline]
    fn is_in_unit_interval(self) -> bool {
        self.to_bits().wrapping_sub(1) < 0x3F80_0000
    }
    #[inline]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline]
    fn sqrt(self) -> Self {
        sqrt_f32(self)
    }
    #[inline]
    fn exp(self) -> Self {
        libm::expf(self)
    }
    #[inline]
    fn exp_m1(self) -> Self {
        libm::expm1f(self)
    }
    #[inline]
    fn ln(self) -> Self {
        libm::logf(self)
    }
    #[inline]
    fn ln_1p(self) -> Self {
        log1p::ln_1p_f32(self)
    }
    #[inline]
    fn ln_1p_in_domain(self) -> Self {
        log1p::ln_1p_in_domain(self)
    }
    #[inline]
    fn cosh(self) -> Self {
        libm::coshf(self)
    }
    #[inline]
    fn sinh(self) -> Self {
        libm::sinhf(self)
    }
    #[inline]
    fn cos(self) -> Self {
        libm::cosf(self)
    }
    #[inline]
    fn sin(self) -> Self {
        libm::sinf(self)
    }
    #[inline]
    fn acos(self) -> Self {
        libm::acosf(self)
    }
}

/// `f32` square root: the FPU instruction on the Cortex-M4F, libm elsewhere.
/// Both are correctly rounded (IEEE 754 requires it of VSQRT), so results agree bit for bit.
///
/// Selected by the hard-float ABI. Stable Rust neither exposes the ARM FPU features to `cfg`
/// (a `target_feature = "vfp2"` test is always false, which silently picked libm's software
/// `sqrtf`, about 52 instructions) nor accepts the `sreg` operand class on this target (it wants
/// the double-precision `vfp2`, which the single-precision FPv4-SP lacks). So the value travels
/// in a core register and the asm borrows `s15`, saving and restoring it itself.
#[inline]
fn sqrt_f32(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        let mut bits = x.to_bits();
        // SAFETY: only register moves and VSQRT.F32; s15 is restored before the asm ends, so
        // the compiler's view of every FPU register is unchanged. No memory, no stack.
        unsafe {
            core::arch::asm!(
                "vmov {saved}, s15",
                "vmov s15, {bits}",
                "vsqrt.f32 s15, s15",
                "vmov {bits}, s15",
                "vmov s15, {saved}",
                bits = inout(reg) bits,
                saved = out(reg) _,
                options(pure, nomem, nostack),
            );
        }
        f32::from_bits(bits)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

/// `sqrt` in f64, correctly rounded. On x86-64 through SSE2's packed square root, one lane
/// used: the compiler sees a square root it may widen into SIMD lanes (the flat batch form),
/// where libm's x86 `sqrt` is an opaque `sqrtsd` in inline assembly that it cannot.
#[inline]
fn sqrt_f64(x: f64) -> f64 {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        use core::arch::x86_64::{_mm_cvtsd_f64, _mm_set_sd, _mm_sqrt_pd};
        // SAFETY: SSE2, all these need, is enabled in this build (the cfg above); they touch
        // no memory.
        unsafe { _mm_cvtsd_f64(_mm_sqrt_pd(_mm_set_sd(x))) }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        libm::sqrt(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sqrt_f32_is_correctly_rounded_against_f64() {
        for &x in &[0.0f32, 1.0, 2.0, 0.5, 1e-30, 3.4e38, 12345.678] {
            let want = (x as f64).sqrt() as f32;
            assert_eq!(Real::sqrt(x), want, "sqrt({x})");
        }
    }

    #[test]
    fn unit_interval_classifies() {
        for (x, want) in [
            (0.5f64, true),
            (1.0, true),
            (1e-310, true),
            (0.0, false),
            (-0.0, false),
            (1.0000000000000002, false),
            (-0.5, false),
            (f64::NAN, false),
            (f64::INFINITY, false),
        ] {
            assert_eq!(x.is_in_unit_interval(), want, "{x}");
            // f32: 1e-310 rounds to 0 (outside), 1.0000000000000002 to 1 (inside).
            let y = x as f32;
            assert_eq!(y.is_in_unit_interval(), y > 0.0 && y <= 1.0, "{x} as f32");
        }
        assert!(!1.000_000_1f32.is_in_unit_interval());
    }

    #[test]
    fn nonneg_finite_classifies() {
        for (x, want) in [
            (0.0f64, true),
            (-0.0, true),
            (1e-310, true),
            (f64::MAX, true),
            (f64::INFINITY, false),
            (f64::NAN, false),
            (-1e-310, false),
            (-1.0, false),
        ] {
            assert_eq!(x.is_nonneg_finite(), want, "{x}");
        }
        for (x, want) in [
            (0.0f32, true),
            (-0.0, true),
            (1e-40, true),
            (f32::MAX, true),
            (f32::INFINITY, false),
            (f32::NAN, false),
            (-1e-40, false),
            (-f32::MAX, false),
        ] {
            assert_eq!(x.is_nonneg_finite(), want, "{x}");
        }
    }

    #[test]
    fn max_min_ignore_nan() {
        assert_eq!(Real::max(1.0f64, f64::NAN), 1.0);
        assert_eq!(Real::min(f64::NAN, 2.0f64), 2.0);
        assert_eq!(Real::max(1.0f32, 3.0), 3.0);
    }
}
