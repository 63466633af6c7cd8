//! The straight line each step's edges are fitted with (commissioning's only arithmetic on
//! stored points: none are stored).

/// A straight line `y = b + m x` through points accumulated without storage: the slope from
/// the first point to the last, the intercept the least-squares one for it
/// ([`LineFit::solve_span`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LineFit {
    n: f32,
    sx: f32,
    sy: f32,
    first: (f32, f32),
    last: (f32, f32),
}

impl LineFit {
    /// Adds a point (one copy for the three fits: the firmware's flash).
    #[inline(never)]
    pub fn add(&mut self, x: f32, y: f32) {
        if self.n == 0.0 {
            self.first = (x, y);
        }
        self.last = (x, y);
        self.n += 1.0;
        self.sx += x;
        self.sy += y;
    }

    /// `(intercept, slope)` with the slope from the first point to the last, the intercept
    /// the least-squares one for that slope; `None` with fewer than 2 distinct abscissae.
    ///
    /// For edges of a shaft at a steady speed whose first and last are of the same tooth
    /// (whole revolutions apart) this slope is the mean speed exactly, whatever the teeth's
    /// offsets and a once-per-revolution load: the least-squares slope over one or two
    /// revolutions is not (it weighs the ends, so a tooth pattern tilts it: 0.2-0.6 % of the
    /// speed on family-60, more than 1 % on the slope between two steps), and its f32 sums of
    /// squares over 20 s lose a few parts in 10^4 as well. (One copy for its callers: the
    /// firmware's flash.)
    #[inline(never)]
    pub fn solve_span(&self) -> Option<(f32, f32)> {
        let dx = self.last.0 - self.first.0;
        if self.n < 2.0 || dx.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            return None;
        }
        let m = (self.last.1 - self.first.1) / dx;
        let b = (self.sy - m * self.sx) / self.n;
        if m.is_finite() && b.is_finite() {
            Some((b, m))
        } else {
            None
        }
    }

    /// Number of points.
    pub fn count(&self) -> u32 {
        self.n as u32
    }
}
