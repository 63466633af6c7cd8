//! Numbers as people read them. A fixed count of decimals hid values at the ends of the range
//! (a residence time of 2.7e-9 s printed as "0.000000 s", a radius of 2.8e17 m with eighteen
//! digits of rounding noise), so every text writer formats through [`fixed`].

/// `x` with `decimals` decimals where that shows at least three significant figures and stays
/// short, else in scientific notation with four (`2.700e-9`). Exactly 0 keeps its decimals.
/// Not finite: the words "no value"; a writer says what that means (never leaves, no
/// equilibrium) before it gets here, this is the last guard against "inf" or "NaN" on screen.
pub fn fixed(x: f64, decimals: usize) -> String {
    if !x.is_finite() {
        return "no value".into();
    }
    let a = x.abs();
    let smallest = 10f64.powi(2 - decimals as i32);
    if x == 0.0 || (a >= smallest && a < 1e7) {
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    }
}

/// `n` and the noun, singular for one ("1 release", "12 releases").
pub fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// Shares of a whole (a JSON object of name to fraction, e.g. a release's regime) in words:
/// `roll 10 %, slide 90 %`, not the raw 16-digit JSON.
pub fn shares(v: &serde_json::Value) -> String {
    let Some(m) = v.as_object() else {
        return String::new();
    };
    m.iter()
        .filter_map(|(name, x)| {
            // A share that rounds to 0 % is still there: "<1 %", not "0 %".
            x.as_f64().map(|x| match 100.0 * x {
                p if p > 0.0 && p < 0.5 => format!("{name} <1 %"),
                p => format!("{name} {p:.0} %"),
            })
        })
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::{count, fixed, shares};

    /// One release is singular; a regime reads as percentages.
    #[test]
    fn counts_and_shares_read_as_words() {
        assert_eq!(count(1, "release", "releases"), "1 release");
        assert_eq!(count(12, "release", "releases"), "12 releases");
        let v = serde_json::json!({"roll": 0.1000000000000001, "slide": 0.8999999999999999});
        assert_eq!(shares(&v), "roll 10 %, slide 90 %");
        let v = serde_json::json!({"fly": 0.002, "roll": 0.998});
        assert_eq!(shares(&v), "fly <1 %, roll 100 %");
    }

    /// The ends of the range keep their significant figures; the middle is as before.
    #[test]
    fn keeps_significant_figures() {
        assert_eq!(fixed(0.168_234, 6), "0.168234");
        assert_eq!(fixed(2.7e-9, 6), "2.700e-9");
        assert_eq!(fixed(2.8449e17, 6), "2.845e17");
        assert_eq!(fixed(0.0, 6), "0.000000");
        assert_eq!(fixed(f64::INFINITY, 6), "no value");
        assert_eq!(fixed(f64::NAN, 3), "no value");
        assert_eq!(fixed(-0.5, 3), "-0.500");
    }
}
