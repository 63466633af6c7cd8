//! Each key checked against its range, with the file and the line in the error.

use super::*;

/// `x` as written by a person: the plant holds f32, so a nominal 0.02 reads 0.02, not the
/// f64 digits of the nearest f32.
pub(crate) fn shortest(x: f64) -> String {
    let narrow = x as f32;
    if f64::from(narrow) == x {
        format!("{narrow}")
    } else {
        format!("{x}")
    }
}

pub(crate) struct Checker<'a> {
    pub(crate) file: &'a str,
    pub(crate) at: &'a dyn Fn(usize) -> usize,
}

impl Checker<'_> {
    /// The value of `key` (or `default`), checked against `[lo, hi]`.
    pub(crate) fn get(&self, v: &Num, key: &str, lo: f64, hi: f64, default: f64) -> Result<f64> {
        let Some(v) = v else { return Ok(default) };
        let x = *v.get_ref();
        if x.is_finite() && x >= lo && x <= hi {
            Ok(x)
        } else {
            Err(anyhow!(
                "rig file {}, line {}: {key} = {x} is outside its range {} to {}; \
                 change it or leave the key out for the nominal value {}",
                self.file,
                (self.at)(v.span().start),
                shortest(lo),
                shortest(hi),
                shortest(default)
            ))
        }
    }

    pub(crate) fn integer(
        &self,
        v: &Num,
        key: &str,
        lo: f64,
        hi: f64,
        default: f64,
    ) -> Result<f64> {
        let x = self.get(v, key, lo, hi, default)?;
        if x.fract() != 0.0 {
            let line = v.as_ref().map_or(0, |v| (self.at)(v.span().start));
            return Err(anyhow!(
                "rig file {}, line {line}: {key} = {x} must be a whole number",
                self.file
            ));
        }
        Ok(x)
    }

    pub(crate) fn rig(&self, t: &RigToml) -> Result<PlantParams> {
        let mut p = PlantParams::nominal();
        p.supply_v = self.get(&t.supply_v, "supply_v", 1.0, 60.0, 12.0)? as f32;
        p.coupling = self.get(&t.coupling, "coupling", -1.0, 1.0, 0.5)? as f32;
        p.timer_hz = self.integer(&t.timer_hz, "timer_hz", 10_000.0, 1e9, 1e6)? as u32;
        let bits = self.integer(&t.timer_bits, "timer_bits", 16.0, 32.0, 32.0)?;
        if bits != 16.0 && bits != 32.0 {
            let line = t
                .timer_bits
                .as_ref()
                .map_or(0, |v| (self.at)(v.span().start));
            return Err(anyhow!(
                "rig file {}, line {line}: timer_bits = {bits} must be 16 or 32",
                self.file
            ));
        }
        p.timer_bits = bits as u8;
        let empty = AxisToml::default();
        for (i, (section, axis)) in [("precession", &t.precession), ("spin", &t.spin)]
            .into_iter()
            .enumerate()
        {
            self.axis(section, axis.as_ref().unwrap_or(&empty), &mut p.axes[i])?;
        }
        self.current_sense(t, &mut p)?;
        Ok(p)
    }

    /// The bridges' current sense (both axes: one driver board) and its errors.
    pub(crate) fn current_sense(&self, t: &RigToml, p: &mut PlantParams) -> Result<()> {
        let typical = CurrentSense::TYPICAL;
        let f = |v: &Num, key: &str, lo: f64, hi: f64, d: f32| -> Result<f32> {
            Ok(self.get(v, key, lo, hi, d.into())? as f32)
        };
        let c = CurrentSense {
            enabled: t.current_sense.unwrap_or(false),
            offset_a: f(
                &t.current_offset_a,
                "current_offset_a",
                -1.0,
                1.0,
                typical.offset_a,
            )?,
            gain_error: f(
                &t.current_gain_error,
                "current_gain_error",
                -0.5,
                0.5,
                typical.gain_error,
            )?,
            noise_a: f(
                &t.current_noise_a,
                "current_noise_a",
                0.0,
                1.0,
                typical.noise_a,
            )?,
        };
        let error_key = [
            &t.current_offset_a,
            &t.current_gain_error,
            &t.current_noise_a,
        ]
        .into_iter()
        .flatten()
        .next();
        if let (false, Some(v)) = (c.enabled, error_key) {
            return Err(anyhow!(
                "rig file {}, line {}: a current-sense error key without `current_sense = true`; \
                 add that line, or leave the error keys out",
                self.file,
                (self.at)(v.span().start)
            ));
        }
        for a in &mut p.axes {
            a.current_sense = if c.enabled { c } else { CurrentSense::NONE };
        }
        Ok(())
    }

    /// The `[particle]` table, each key checked against [`ParticleParams::ranges`]; with
    /// `model = "bowl"` the granule in the rig's `[bowl]` ([`Checker::granule_in_bowl`]).
    pub(crate) fn particle(
        &self,
        t: &ParticleToml,
        bowl: Option<&bowl::BowlToml>,
    ) -> Result<ParticleParams> {
        let mut p = ParticleParams::default();
        let mut in_bowl = None;
        if let Some(m) = &t.model {
            let line = (self.at)(m.span().start);
            match m.get_ref().as_str() {
                "flat" => p.model = Model::Flat,
                "coriolis" => p.model = Model::Coriolis,
                "bowl" => in_bowl = Some(line),
                other => {
                    return Err(anyhow!(
                        "rig file {}, line {line}: [particle] model = {other:?} must be \"flat\", \
                         \"coriolis\" or \"bowl\"",
                        self.file,
                    ));
                }
            };
        }
        // In the order of `ParticleParams::ranges`: mu, mu_spread, k2, release_radius_m,
        // rim_radius_m, release_spread_m, gate_jitter_s.
        let given: [&Num; 7] = [
            &t.mu,
            &t.mu_spread,
            &t.k2,
            &t.release_radius_m,
            &t.rim_radius_m,
            &t.release_spread_m,
            &t.gate_jitter_s,
        ];
        let mut values = [0.0; 7];
        for ((slot, (key, default, lo, hi)), v) in values
            .iter_mut()
            .zip(ParticleParams::default().ranges())
            .zip(given)
        {
            *slot = self.get(v, &format!("[particle] {key}"), lo, hi, default)?;
        }
        [
            p.mu,
            p.mu_spread,
            p.k2,
            p.release_radius_m,
            p.rim_radius_m,
            p.release_spread_m,
            p.gate_jitter_s,
        ] = values;
        self.granule_in_bowl(t, bowl, in_bowl, &mut p)?;
        if p.release_radius_m >= p.rim_radius_m {
            let line = t
                .release_radius_m
                .as_ref()
                .or(t.rim_radius_m.as_ref())
                .map_or(0, |v| (self.at)(v.span().start));
            return Err(anyhow!(
                "rig file {}, line {line}: [particle] release_radius_m = {} must lie inside the \
                 rim (rim_radius_m = {})",
                self.file,
                p.release_radius_m,
                p.rim_radius_m
            ));
        }
        Ok(p)
    }

    pub(crate) fn axis(&self, section: &str, a: &AxisToml, p: &mut AxisParams) -> Result<()> {
        let key = |k: &str| format!("[{section}] {k}");
        let m = &mut p.motor;
        let f = |v: &Num, k: &str, lo: f64, hi: f64, d: f32| -> Result<f32> {
            Ok(self.get(v, &key(k), lo, hi, d as f64)? as f32)
        };
        m.resistance_ohm = f(
            &a.resistance_ohm,
            "resistance_ohm",
            0.01,
            1000.0,
            m.resistance_ohm,
        )?;
        m.inductance_h = f(&a.inductance_h, "inductance_h", 1e-6, 1.0, m.inductance_h)?;
        m.torque_constant = f(
            &a.torque_constant,
            "torque_constant",
            1e-3,
            100.0,
            m.torque_constant,
        )?;
        m.inertia_kg_m2 = f(
            &a.inertia_kg_m2,
            "inertia_kg_m2",
            1e-6,
            100.0,
            m.inertia_kg_m2,
        )?;
        m.viscous_nm_s = f(&a.viscous_nm_s, "viscous_nm_s", 0.0, 100.0, m.viscous_nm_s)?;
        m.coulomb_nm = f(&a.coulomb_nm, "coulomb_nm", 0.0, 100.0, m.coulomb_nm)?;
        // Stiction is at least the sliding friction; without the key it keeps the nominal
        // ratio to it.
        let nominal_ratio = m.stiction_nm / m.coulomb_nm.max(f32::MIN_POSITIVE);
        let default_stiction = if a.coulomb_nm.is_some() {
            m.coulomb_nm * nominal_ratio
        } else {
            m.stiction_nm
        };
        m.stiction_nm = f(
            &a.stiction_nm,
            "stiction_nm",
            m.coulomb_nm as f64,
            100.0,
            default_stiction,
        )?;
        p.ripple_nm = f(&a.ripple_nm, "ripple_nm", 0.0, 100.0, p.ripple_nm)?;
        p.load_step_nm = f(&a.load_step_nm, "load_step_nm", 0.0, 100.0, p.load_step_nm)?;
        p.sensor.pulses_per_rev = self.integer(
            &a.pulses_per_rev,
            &key("pulses_per_rev"),
            1.0,
            1000.0,
            p.sensor.pulses_per_rev as f64,
        )? as u16;
        p.sensor.tooth_error = f(
            &a.tooth_error,
            "tooth_error",
            0.0,
            0.45,
            p.sensor.tooth_error,
        )?;
        p.sensor.jitter_s = f(&a.jitter_s, "jitter_s", 0.0, 0.01, p.sensor.jitter_s)?;
        Ok(())
    }
}
