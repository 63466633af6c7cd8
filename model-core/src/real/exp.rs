//! `e^x` in f64 for the host, without libm's division: the batch Coriolis closed form spends a
//! fifth of its time in `exp`, and once its root searches are interleaved (particle::coriolis)
//! what counts is each call's throughput, which a division limits.
//!
//! Method (Cody and Waite's reduction, as fdlibm): `x = k ln 2 + r` with `k` the nearest
//! integer to `x / ln 2` and `|r| <= ln(2) / 2`, `ln 2` split in two so that `k ln2_hi` is exact;
//! then `e^r = 1 + (r + phi(r))` with `phi(r) = e^r - 1 - r = r^2 / 2 * sum_j 2 r^j / (j + 2)!`
//! ([`phi_terms_f64`], the series the Coriolis form needs for small arguments anyway; its
//! truncation is below 1e-17 relative for `|r| < 1`), and `e^x = 2^k e^r` by the exponent bits.
//! Worst error below 1 ulp (tested against a 40-term series in double-double below).

// fdlibm's split of ln 2 (the high part has 21 trailing zero bits).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
const LOG2_E: f64 = core::f64::consts::LOG2_E;
/// Adding and subtracting it rounds a value below 2^51 to the nearest integer.
const ROUND: f64 = 6_755_399_441_055_744.0;
/// Above this `e^x` overflows; below [`UNDERFLOW`] it rounds to 0.
const OVERFLOW: f64 = 709.782_712_893_384;
const UNDERFLOW: f64 = -745.133_219_101_941_1;

/// `2 / (j + 2)!` for `j = 0..=17`, computed at compile time.
const TERMS_F64: [f64; 18] = {
    let mut c = [1.0f64; 18];
    let mut j = 1;
    while j < 18 {
        c[j] = c[j - 1] / (j + 2) as f64;
        j += 1;
    }
    c
};

/// `2 phi(z) / z^2 = sum_j 2 z^j / (j + 2)!` to the 19th factorial (degree 17), accurate to
/// rounding for `|z| < 1`, by Estrin's scheme: on the host's out-of-order cores latency, not
/// the operation count, bounds the closed forms, and Estrin's tree is 6 operations deep where
/// Horner's chain is 34.
#[inline(always)]
pub fn phi_terms_f64(z: f64) -> f64 {
    let c = &TERMS_F64;
    let z2 = z * z;
    let z4 = z2 * z2;
    let z8 = z4 * z4;
    let z16 = z8 * z8;
    let pair = |j: usize| c[j] + c[j + 1] * z;
    let quad = |j: usize| pair(j) + pair(j + 2) * z2;
    let oct = |j: usize| quad(j) + quad(j + 4) * z4;
    (oct(0) + oct(8) * z8) + pair(16) * z16
}

/// `e^x`: +infinity above 709.78, 0 below -745.13, NaN for NaN.
#[inline]
pub fn exp_f64(x: f64) -> f64 {
    // NaN fails both comparisons and comes back as itself.
    if !(UNDERFLOW..=OVERFLOW).contains(&x) {
        return if x > OVERFLOW {
            f64::INFINITY
        } else if x < UNDERFLOW {
            0.0
        } else {
            x
        };
    }
    let (er, kf) = reduced(x);
    let k = kf as i32;
    if (-1022..=1023).contains(&k) {
        er * pow2(k)
    } else if k > 0 {
        // k = 1024: e^r < 1 there, so the product is finite.
        er * pow2(k - 1) * 2.0
    } else {
        // Subnormal results: two scalings (the second rounds once more, within 1 ulp).
        er * pow2(k + 1000) * pow2(-1000)
    }
}

/// `e^x` for `|x| <= 700` (no range check, no branch: the batch closed form's SIMD lanes),
/// bit for bit [`exp_f64`] there.
#[inline(always)]
pub fn exp_in_domain_f64(x: f64) -> f64 {
    let (er, kf) = reduced(x);
    er * pow2(kf as i32)
}

/// `(e^r, k)` with `x = k ln 2 + r` (Cody and Waite's reduction, see the module's comment).
#[inline(always)]
fn reduced(x: f64) -> (f64, f64) {
    let kf = (x * LOG2_E + ROUND) - ROUND;
    let r = (x - kf * LN2_HI) - kf * LN2_LO;
    (1.0 + (r + r * r * 0.5 * phi_terms_f64(r)), kf)
}

/// `2^k` for `-1022 <= k <= 1023`. Outside it (a batch lane out of [`exp_in_domain_f64`]'s
/// domain, whose result the batch discards) the bits mean nothing, but computing them never
/// traps: the exponent wraps, in debug builds as in release.
#[inline(always)]
fn pow2(k: i32) -> f64 {
    f64::from_bits((k.wrapping_add(1023) as u64) << 52)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `e^x` from an independent route: `e^x = (e^(x / 2^n))^(2^n)` with the inner value from
    /// its Taylor series, all in double-double (a pair of f64 summing to the value).
    fn exp_reference(x: f64) -> f64 {
        type Dd = (f64, f64);
        fn two_sum(a: f64, b: f64) -> Dd {
            let s = a + b;
            let bb = s - a;
            (s, (a - (s - bb)) + (b - bb))
        }
        fn split(a: f64) -> Dd {
            let t = 134_217_729.0 * a;
            let hi = t - (t - a);
            (hi, a - hi)
        }
        fn two_prod(a: f64, b: f64) -> Dd {
            let p = a * b;
            let (ah, al) = split(a);
            let (bh, bl) = split(b);
            (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
        }
        fn add(a: Dd, b: Dd) -> Dd {
            let (s, e) = two_sum(a.0, b.0);
            let e = e + a.1 + b.1;
            two_sum(s, e)
        }
        fn mul(a: Dd, b: Dd) -> Dd {
            let (p, e) = two_prod(a.0, b.0);
            two_sum(p, e + a.0 * b.1 + a.1 * b.0)
        }
        /// `a / i` for a small integer `i`, carrying the first quotient's remainder.
        fn div_int(a: Dd, i: f64) -> Dd {
            let q1 = a.0 / i;
            let (p, e) = two_prod(q1, i);
            let rem = ((a.0 - p) - e) + a.1;
            two_sum(q1, rem / i)
        }
        let y = x / 4096.0; // exact
        let mut term: Dd = (1.0, 0.0);
        let mut sum: Dd = (1.0, 0.0);
        for i in 1..30 {
            term = div_int(mul(term, (y, 0.0)), i as f64);
            sum = add(sum, term);
        }
        let mut v = sum;
        for _ in 0..12 {
            v = mul(v, v);
        }
        v.0 + v.1
    }

    #[test]
    fn exp_is_within_one_ulp_over_the_range() {
        let mut worst = 0.0f64;
        let mut x = -700.0;
        while x < 700.0 {
            let got = exp_f64(x);
            let want = exp_reference(x);
            let ulp = f64::EPSILON * want;
            worst = worst.max((got - want).abs() / ulp);
            x += 0.7317;
        }
        for &x in &[1e-300, -1e-300, 1e-8, -1e-8, 0.3466, -0.3466, 0.5, 1.0, 2.5] {
            let want = exp_reference(x);
            worst = worst.max((exp_f64(x) - want).abs() / (f64::EPSILON * want));
        }
        assert!(worst < 1.0, "worst error {worst} ulp");
    }

    #[test]
    fn the_branchless_exp_is_exp_bit_for_bit_in_its_domain() {
        // The batch's lanes rely on it: their answers must be the one-scene answers exactly.
        let n = 200_000;
        for i in 0..=n {
            let x = -700.0 + 1400.0 * i as f64 / n as f64;
            for x in [x, x + 1e-9, -x * 0.999_999_7] {
                assert_eq!(exp_in_domain_f64(x).to_bits(), exp_f64(x).to_bits(), "{x}");
            }
        }
    }

    #[test]
    fn the_branchless_exp_never_traps_outside_its_domain() {
        // A batch lane with an extreme scene computes this and discards it (found by the
        // batch property test: an overflowing exponent panicked in debug builds).
        for x in [1e300, -1e300, 710.0, -746.0, f64::MAX, f64::MIN, f64::NAN] {
            let _ = exp_in_domain_f64(x);
        }
    }

    #[test]
    fn exp_handles_the_edges() {
        assert_eq!(exp_f64(0.0), 1.0);
        assert_eq!(exp_f64(710.0), f64::INFINITY);
        assert_eq!(exp_f64(f64::INFINITY), f64::INFINITY);
        assert_eq!(exp_f64(-746.0), 0.0);
        assert_eq!(exp_f64(f64::NEG_INFINITY), 0.0);
        assert!(exp_f64(f64::NAN).is_nan());
        // Near overflow and in the subnormal range, against libm.
        for &x in &[709.7, 709.78, -708.5, -720.0, -740.0, -745.0] {
            let (got, want) = (exp_f64(x), libm::exp(x));
            assert!(
                (got - want).abs() <= 2.0 * f64::EPSILON * want.max(f64::MIN_POSITIVE),
                "exp({x}) = {got:e}, libm {want:e}"
            );
        }
    }
}
