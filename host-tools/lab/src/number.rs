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

/// A value the user gave, echoed with all its digits (shortest round-trip, so 3.6 reads 3.6) but
/// in scientific notation beyond 1e-4 to 1e9: Rust's `{}` never is, and echoed `1e30` as 31
/// digits and `1e-20` as twenty zeros.
pub fn echo(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-4..1e9).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `x`, an `f32` (what the MCU and the controller compute in), as the `f64` of its shortest
/// decimal: widened with `f64::from` it was written with its binary's noise (a split speed of
/// 1.7153077 rad/s as 1.7153077125549316 in a results file).
pub fn from_f32(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

/// serde's `serialize_with` for an `f64` computed from `f32` data (the simulated rig's speeds
/// and ticks): written as that `f32`'s shortest decimal, not with the widening's digits (a
/// settling time of 1.543 s as 1.5430000732885674).
pub fn f32_digits<S: serde::Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    // As the f64 of the f32's decimal, not `serialize_f32`: a report built as a
    // `serde_json::Value` first widens an f32 again.
    s.serialize_f64(from_f32(*x as f32))
}

/// [`f32_digits`] for an optional value.
pub fn f32_digits_opt<S: serde::Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match x {
        Some(v) => s.serialize_some(&from_f32(*v as f32)),
        None => s.serialize_none(),
    }
}

/// A time the simulated rig measured in whole control ticks of `dt_s` (the tick as its decimal,
/// [`from_f32`]), written as that count of ticks times the tick, to 1e-9 s: a product of the
/// tick read 8258 ticks as 8.258000000000001 s, a sum of `f32` ticks 785 of them as
/// 0.78499347 s and the rig's clock 1000 as 1.0000000474974513 s. Not finite: as it is.
pub fn tick_s(t_s: f64, dt_s: f64) -> f64 {
    if !t_s.is_finite() || dt_s <= 0.0 {
        return t_s;
    }
    // A sum of f32 ticks drifts by far less than half a tick over a run (1e-5 s in 1 s).
    let ticks = (t_s / dt_s).round();
    (ticks * dt_s * 1e9).round() / 1e9
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
    use super::{count, echo, f32_digits, f32_digits_opt, fixed, from_f32, shares, tick_s};

    /// A given value keeps its digits, in scientific notation at the ends of the range.
    #[test]
    fn echoes_keep_digits_and_stay_short() {
        assert_eq!(echo(3.6), "3.6");
        assert_eq!(echo(0.029), "0.029");
        assert_eq!(echo(-12345678.5), "-12345678.5");
        assert_eq!(echo(0.0), "0");
        assert_eq!(echo(1e30), "1e30");
        assert_eq!(echo(-1.5e-20), "-1.5e-20");
        assert_eq!(echo(2.5e9), "2.5e9");
    }

    /// A time in whole ticks is written as the ticks, without the binary noise of the tick.
    #[test]
    fn tick_times_are_whole_ticks() {
        assert_eq!((8258.0 * 0.001f64).to_string(), "8.258000000000001");
        assert_eq!(tick_s(8258.0 * 0.001, 0.001).to_string(), "8.258");
        assert_eq!(
            tick_s(f64::from(0.784_993_47f32), 0.001).to_string(),
            "0.785"
        );
        assert_eq!(tick_s(1.000_000_047_497_451_3, 0.001).to_string(), "1");
        assert_eq!(tick_s(0.0025, 0.0025).to_string(), "0.0025");
        assert!(tick_s(f64::INFINITY, 0.001).is_infinite());
    }

    /// An f32's value is written with its own digits, not the widening's.
    #[test]
    fn f32_values_keep_their_own_digits() {
        assert_eq!(from_f32(1.715_307_7).to_string(), "1.7153077");
        assert_eq!(f64::from(1.715_307_7f32).to_string(), "1.7153077125549316");
        #[derive(serde::Serialize)]
        struct Figures {
            #[serde(serialize_with = "f32_digits")]
            pct: f64,
            #[serde(serialize_with = "f32_digits_opt")]
            s: Option<f64>,
            #[serde(serialize_with = "f32_digits_opt")]
            never: Option<f64>,
        }
        let f = Figures {
            pct: f64::from(1.048_243f32),
            s: Some(1543.0 * from_f32(0.001)),
            never: None,
        };
        assert_eq!(
            serde_json::to_string(&f).unwrap(),
            r#"{"pct":1.048243,"s":1.543,"never":null}"#
        );
    }

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
