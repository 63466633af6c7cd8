//! Sine and cosine of the axes angle at construction time: `const fn`, f32 only, so no libm
//! sine or cosine and no f64 arithmetic reach the firmware image.

/// sin(z) for |z| <= pi/2 in f32, usable in `const fn`: the Taylor series to z^23 in Horner
/// form (truncation below 1e-15 there; f32 rounding dominates, a few 1e-8). No libm sine or
/// cosine and no f64 arithmetic reach the firmware image this way.
const fn sin_series(z: f32) -> f32 {
    let z2 = z * z;
    // sin z = z (1 - z^2/(2*3) (1 - z^2/(4*5) (1 - ...))), innermost term first.
    let mut acc = 1.0f32;
    let mut k = 11;
    while k > 0 {
        acc = 1.0 - z2 / ((2 * k) as f32 * (2 * k + 1) as f32) * acc;
        k -= 1;
    }
    z * acc
}

/// cos(x) for x in [0, pi) (the configuration's axes angle), usable in `const fn`:
/// cos x = sin(pi/2 - x), |pi/2 - x| <= pi/2. (libm's `cosf` is not a `const fn`.)
pub(crate) const fn cos_const(x: f32) -> f32 {
    sin_series(core::f32::consts::FRAC_PI_2 - x)
}

/// sin(x) for x in [0, pi): sin x = cos(pi/2 - x) = sqrt(1 - sin^2(pi/2 - x)) would need a
/// square root; instead sin x = sin(pi - x) folds x into [0, pi/2], where the series holds.
pub(crate) const fn sin_const(x: f32) -> f32 {
    let folded = if x > core::f32::consts::FRAC_PI_2 {
        core::f32::consts::PI - x
    } else {
        x
    };
    sin_series(folded)
}

#[cfg(test)]
mod tests {
    #[test]
    fn cos_const_matches_libm() {
        let mut x = 0.0f32;
        while x < core::f32::consts::PI {
            let d = (super::cos_const(x) - libm::cosf(x)).abs();
            assert!(d < 2e-7, "x {x}: {d}");
            let d = (super::sin_const(x) - libm::sinf(x)).abs();
            assert!(d < 2e-7, "sin x {x}: {d}");
            x += 0.01;
        }
    }
}
