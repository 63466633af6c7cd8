//! What speed can do: the residence time `T` sampled at [`SPEED_TABLE_LEN`] bowl speeds evenly
//! spaced over the rig's speed range, and its inverse by linear interpolation (docs/model.md
//! §11).
//!
//! The PC computes the table with whichever model the chooser picked for the rig's bowl, tilt
//! and granule (the real bowl's granule needs an integrator the MCU has no room or time for),
//! and the rig stores it as parameters (`RT_W_LO_MRAD_S`, `RT_W_HI_MRAD_S`, `RT_T1_US` ..
//! `RT_T8_US`); `RTIME TABLE` then turns a target `T` into a bowl speed here, on the MCU, with
//! no model of its own. A target outside `[Tmin, Tmax]` is refused, and so is every target when
//! the table is flat: a span under [`FLAT_SPAN_FRACTION`] of `T` is smaller than what the
//! model knows `T` to (issue 30: 1 % against the independent reference), so no speed can be
//! said to set it (at 60 degrees of tilt gravity dominates and `T` barely moves with speed).
//!
//! f32, no heap, no panic on any input: a table is only built through [`SpeedTable::new`],
//! which refuses what is not finite and ordered.

/// How many speeds the table samples (the bowl speeds `lo + k (hi - lo) / 7`, `k = 0..8`).
/// Eight keep the PARAMS answer under the frame limit; the interpolation error this leaves is
/// measured in docs/model.md §11.
pub const SPEED_TABLE_LEN: usize = 8;

/// A table whose whole span `Tmax - Tmin` is under this fraction of `Tmax` is flat: speed
/// cannot set `T` to better than the model knows it.
pub const FLAT_SPAN_FRACTION: f32 = 0.01;

/// `T` at evenly spaced bowl speeds (paper Eq. 2's combined speed, as RTIME splits it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedTable {
    omega_lo_rad_s: f32,
    omega_hi_rad_s: f32,
    residence_s: [f32; SPEED_TABLE_LEN],
}

/// Why a table cannot be built, or why it cannot give a target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpeedTableError {
    /// The speeds are not `0 <= lo < hi` (finite), or a time is not finite and positive.
    Invalid,
    /// The target is outside every time the table holds: `[min_s, max_s]`.
    Outside {
        /// The shortest time in the table, s.
        min_s: f32,
        /// The longest, s.
        max_s: f32,
    },
    /// The table is flat (see [`FLAT_SPAN_FRACTION`]): speed cannot set `T`.
    Flat,
}

impl SpeedTable {
    /// A table of `residence_s[k]` at bowl speed `lo + k (hi - lo) / (LEN - 1)`.
    pub fn new(
        omega_lo_rad_s: f32,
        omega_hi_rad_s: f32,
        residence_s: [f32; SPEED_TABLE_LEN],
    ) -> Result<Self, SpeedTableError> {
        let ordered = omega_lo_rad_s.is_finite()
            && omega_hi_rad_s.is_finite()
            && omega_lo_rad_s >= 0.0
            && omega_lo_rad_s < omega_hi_rad_s;
        if !ordered || !residence_s.iter().all(|t| t.is_finite() && *t > 0.0) {
            return Err(SpeedTableError::Invalid);
        }
        Ok(Self {
            omega_lo_rad_s,
            omega_hi_rad_s,
            residence_s,
        })
    }

    /// The bowl speed of entry `k` (clamped to the last), rad/s.
    pub fn omega_rad_s(&self, k: usize) -> f32 {
        let k = k.min(SPEED_TABLE_LEN - 1);
        let h = (self.omega_hi_rad_s - self.omega_lo_rad_s) / (SPEED_TABLE_LEN - 1) as f32;
        if k == SPEED_TABLE_LEN - 1 {
            self.omega_hi_rad_s
        } else {
            self.omega_lo_rad_s + k as f32 * h
        }
    }

    /// The speed range the table covers, rad/s.
    pub fn speed_range_rad_s(&self) -> (f32, f32) {
        (self.omega_lo_rad_s, self.omega_hi_rad_s)
    }

    /// The times, s, in speed order.
    pub fn residence_s(&self) -> &[f32; SPEED_TABLE_LEN] {
        &self.residence_s
    }

    /// The shortest and longest time in the table, s.
    pub fn residence_range_s(&self) -> (f32, f32) {
        self.residence_s
            .iter()
            .fold((f32::INFINITY, 0.0f32), |(lo, hi), &t| {
                (lo.min(t), hi.max(t))
            })
    }

    /// Whether speed cannot set `T` here (see [`FLAT_SPAN_FRACTION`]).
    pub fn is_flat(&self) -> bool {
        let (lo, hi) = self.residence_range_s();
        hi - lo < FLAT_SPAN_FRACTION * hi
    }

    /// `T` at bowl speed `omega_rad_s` by linear interpolation; `None` outside the range.
    pub fn residence_at_s(&self, omega_rad_s: f32) -> Option<f32> {
        let (lo, hi) = self.speed_range_rad_s();
        if !(omega_rad_s >= lo && omega_rad_s <= hi) {
            return None;
        }
        let x = (omega_rad_s - lo) / (hi - lo) * (SPEED_TABLE_LEN - 1) as f32;
        // In 0..=LEN-1 (checked above), so the cast neither saturates nor wraps.
        let k = (x as usize).min(SPEED_TABLE_LEN - 2);
        let f = x - k as f32;
        let (a, b) = (self.residence_s[k], self.residence_s[k + 1]);
        Some(a + f * (b - a))
    }

    /// The slowest bowl speed whose interpolated `T` is `target_s`, rad/s (the first segment,
    /// from the slow end, that brackets it: a table need not be monotone); refused when the
    /// table is flat or the target is outside its times.
    pub fn omega_for_s(&self, target_s: f32) -> Result<f32, SpeedTableError> {
        if self.is_flat() {
            return Err(SpeedTableError::Flat);
        }
        let (min_s, max_s) = self.residence_range_s();
        if !(target_s >= min_s && target_s <= max_s) {
            return Err(SpeedTableError::Outside { min_s, max_s });
        }
        for k in 0..SPEED_TABLE_LEN - 1 {
            let (a, b) = (self.residence_s[k], self.residence_s[k + 1]);
            if (target_s - a) * (target_s - b) <= 0.0 {
                let (w0, w1) = (self.omega_rad_s(k), self.omega_rad_s(k + 1));
                // a == b only when target == a: the segment's slow end.
                let f = if a == b {
                    0.0
                } else {
                    (target_s - a) / (b - a)
                };
                return Ok(w0 + f * (w1 - w0));
            }
        }
        // Unreachable: a target in [min, max] lies between two neighbours of a continuous
        // piecewise-linear curve; said as the refusal it would be, never a panic.
        Err(SpeedTableError::Outside { min_s, max_s })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(f: impl Fn(f32) -> f32) -> SpeedTable {
        let (lo, hi) = (0.5f32, 3.6f32);
        let mut t = [0.0; SPEED_TABLE_LEN];
        for (k, slot) in t.iter_mut().enumerate() {
            *slot = f(lo + k as f32 * (hi - lo) / 7.0);
        }
        SpeedTable::new(lo, hi, t).unwrap()
    }

    #[test]
    fn a_linear_table_is_inverted_exactly() {
        // T = 2 - 0.4 w: linear, so interpolation is exact.
        let t = table(|w| 2.0 - 0.4 * w);
        for w in [0.5f32, 1.0, 2.345, 3.6] {
            let back = t.omega_for_s(2.0 - 0.4 * w).unwrap();
            assert!((back - w).abs() < 1e-5, "{w} -> {back}");
            assert!((t.residence_at_s(w).unwrap() - (2.0 - 0.4 * w)).abs() < 1e-6);
        }
    }

    #[test]
    fn outside_and_flat_tables_are_refused() {
        let t = table(|w| 2.0 - 0.4 * w);
        let (lo, hi) = t.residence_range_s();
        assert!((lo - 0.56).abs() < 1e-6 && (hi - 1.8).abs() < 1e-6);
        assert_eq!(
            t.omega_for_s(1.9),
            Err(SpeedTableError::Outside {
                min_s: lo,
                max_s: hi
            })
        );
        assert!(t.omega_for_s(0.5).is_err() && t.omega_for_s(f32::NAN).is_err());
        // 0.143 to 0.144 s: under 1 % of T, flat.
        let flat = table(|w| 0.143 + 0.001 * (w - 0.5) / 3.1);
        assert!(flat.is_flat());
        assert_eq!(flat.omega_for_s(0.1435), Err(SpeedTableError::Flat));
    }

    #[test]
    fn bad_tables_are_not_built() {
        let ok = [1.0f32; SPEED_TABLE_LEN];
        assert!(SpeedTable::new(1.0, 1.0, ok).is_err());
        assert!(SpeedTable::new(-1.0, 1.0, ok).is_err());
        assert!(SpeedTable::new(0.0, f32::INFINITY, ok).is_err());
        let mut bad = ok;
        bad[3] = 0.0;
        assert!(SpeedTable::new(0.0, 1.0, bad).is_err());
        bad[3] = f32::NAN;
        assert!(SpeedTable::new(0.0, 1.0, bad).is_err());
    }

    #[test]
    fn a_table_with_a_hump_gives_the_slowest_speed() {
        // Up then down: 1.0 is met twice; the slow side is taken.
        let t = table(|w| 1.0 + 0.5 * (1.0 - (w - 2.05) * (w - 2.05)));
        let w = t.omega_for_s(1.2).unwrap();
        assert!(w < 2.05, "{w}");
        assert!((t.residence_at_s(w).unwrap() - 1.2).abs() < 1e-5);
    }
}
