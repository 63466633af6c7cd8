//! A brushed DC gearmotor with its load, all quantities at the output shaft.
//!
//! Electrical: `L di/dt = u - R i - k w`, with `u = duty * V` (PWM averaged over its period:
//! at 20 kHz the period is 50 us, far below both the electrical time constant `L/R` and the
//! tick). At zero duty the bridge coasts: the current decays through the freewheel diodes within
//! `L/R` (a fraction of a millisecond), modelled as zero current. Integrated implicitly in `R`
//! (stable for any step).
//!
//! Mechanical: `J dw/dt = k i - b w - Tc sign(w) - T_load`, with stiction (Karnopp): a shaft at
//! rest stays at rest while the net driving torque is below `Ts`. Gearbox losses are lumped into
//! the friction terms; the gear ratio is lumped into `k` and `J` (output-shaft values).

/// Parameters of one motor and its load, output-shaft values, SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorParams {
    /// Armature resistance, ohm.
    pub resistance_ohm: f32,
    /// Armature inductance, H.
    pub inductance_h: f32,
    /// Torque constant = back-EMF constant at the output shaft, N m/A = V s/rad.
    pub torque_constant: f32,
    /// Inertia of rotor (through the gearbox), gearbox, bowl and load, kg m^2.
    pub inertia_kg_m2: f32,
    /// Viscous friction, N m s/rad.
    pub viscous_nm_s: f32,
    /// Coulomb (sliding) friction, N m.
    pub coulomb_nm: f32,
    /// Stiction (breakaway) torque, N m (>= Coulomb).
    pub stiction_nm: f32,
}

impl MotorParams {
    /// Spin axis: a 12 V, ~65 rpm gearmotor turning a 300 mm bowl with its load.
    pub const fn nominal_spin() -> Self {
        Self {
            resistance_ohm: 8.0,
            inductance_h: 0.002,
            torque_constant: 1.6,
            inertia_kg_m2: 0.02,
            viscous_nm_s: 0.01,
            coulomb_nm: 0.1,
            stiction_nm: 0.14,
        }
    }
    /// Precession axis: the same motor type turning the rod, the spin motor and the bowl.
    pub const fn nominal_precession() -> Self {
        Self {
            resistance_ohm: 8.0,
            inductance_h: 0.002,
            torque_constant: 1.6,
            inertia_kg_m2: 0.04,
            viscous_nm_s: 0.015,
            coulomb_nm: 0.15,
            stiction_nm: 0.2,
        }
    }

    /// Duty whose torque equals stiction at supply `supply_v`: `R Ts / (k V)`.
    pub fn ideal_breakaway_duty(&self, supply_v: f32) -> f32 {
        self.resistance_ohm * self.stiction_nm / (self.torque_constant * supply_v)
    }

    /// Steady-state model the controller identifies: `(volts_per_rad_s, friction_duty,
    /// time_constant_s)` at supply `supply_v` (ignoring stiction and inductance).
    pub fn ideal_model(&self, supply_v: f32) -> (f32, f32, f32) {
        let k = self.torque_constant;
        let r = self.resistance_ohm;
        let a = k + r * self.viscous_nm_s / k;
        let friction_duty = r * self.coulomb_nm / (k * supply_v);
        let tau = self.inertia_kg_m2 * r / (k * k + r * self.viscous_nm_s);
        (a, friction_duty, tau)
    }
}

/// State of one motor.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MotorState {
    /// Armature current, A.
    pub current_a: f32,
    /// Output shaft speed, rad/s.
    pub speed_rad_s: f32,
}

impl MotorState {
    /// Advances by `dt_s` with terminal voltage `volts` (None = coasting bridge) and external
    /// load torque `load_nm` (positive opposes positive rotation); `blocked` holds the shaft.
    /// Returns the motor torque, N m.
    pub fn step(
        &mut self,
        p: &MotorParams,
        volts: Option<f32>,
        load_nm: f32,
        blocked: bool,
        dt_s: f32,
    ) -> f32 {
        let k = p.torque_constant;
        match volts {
            None => self.current_a = 0.0,
            Some(u) => {
                let a = dt_s / p.inductance_h;
                self.current_a = (self.current_a + a * (u - k * self.speed_rad_s))
                    / (1.0 + a * p.resistance_ohm);
            }
        }
        let torque = k * self.current_a;
        if blocked {
            self.speed_rad_s = 0.0;
            return torque;
        }
        let drive = torque - load_nm;
        let w = self.speed_rad_s;
        if w == 0.0 {
            if drive.abs() <= p.stiction_nm {
                return torque;
            }
            let net = drive - p.coulomb_nm * drive.signum();
            self.speed_rad_s = net * dt_s / p.inertia_kg_m2;
            return torque;
        }
        let friction = p.viscous_nm_s * w + p.coulomb_nm * w.signum();
        let next = w + (drive - friction) * dt_s / p.inertia_kg_m2;
        // Friction cannot reverse the motion: crossing zero means the shaft stops (and sticks
        // unless the drive exceeds stiction next step).
        self.speed_rad_s = if next * w < 0.0 { 0.0 } else { next };
        torque
    }
}
