//! The simulated rig: two gearmotors, the spin motor's reaction on the precession axis, a
//! proximity sensor per shaft with tooth-spacing error and timing jitter, load ripple and
//! injectable faults. Produces exactly what the firmware gives the controller: capture
//! timestamps per axis and the timer's value at each tick.

use super::motor::{MotorParams, MotorState};
use super::prng::{Prng, hashed_symmetric};

/// Largest number of edges buffered per axis per control tick (more are counted as lost).
pub const EDGE_BUFFER: usize = 32;

/// The proximity sensor and target wheel of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorParams {
    /// Teeth (pulses) per output revolution.
    pub pulses_per_rev: u16,
    /// Tooth-spacing error: each tooth sits up to this fraction of a pitch from its nominal
    /// place (uniform, fixed per tooth).
    pub tooth_error: f32,
    /// Timing jitter of each edge, s (uniform in +/- this).
    pub jitter_s: f32,
}

/// [`AxisFaults::missing_tooth`] of a whole wheel.
pub const NO_TOOTH_MISSING: u16 = u16::MAX;

/// Faults injected on one axis. Times are simulation seconds; `f32::INFINITY` = never.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisFaults {
    /// Probability that an edge is lost.
    pub missing_probability: f32,
    /// A wheel with this tooth (0..pulses_per_rev, counted from the angle's zero) gone: its
    /// edge never comes, every revolution; [`NO_TOOTH_MISSING`] = a whole wheel.
    pub missing_tooth: u16,
    /// Probability that an edge bounces (a second edge follows after `bounce_delay_s`).
    pub bounce_probability: f32,
    /// Delay of a bounce edge, s.
    pub bounce_delay_s: f32,
    /// From this time on, no edges at all.
    pub dead_sensor_from_s: f32,
    /// From this time on, the shaft is blocked.
    pub blocked_from_s: f32,
    /// From this time on, an extra friction-like load (material in the bowl), N m.
    pub load_step_from_s: f32,
    /// The load step's size, N m (added to the Coulomb and stiction torques).
    pub load_step_nm: f32,
    /// From this time on, the bridge is stuck on: any nonzero commanded duty drives the motor
    /// at full duty in the commanded direction (a shorted driver input); a zero duty still
    /// coasts (the driver's enable follows the controller's stop).
    pub bridge_stuck_from_s: f32,
    /// From this time on, the bridge is shorted: it drives the motor at full duty whatever the
    /// controller commands, zero included (a shorted FET pair), in the direction of the last
    /// nonzero duty; only the supply cut ([`Plant::cut_supply`]) stops it.
    pub bridge_shorted_from_s: f32,
}

impl AxisFaults {
    /// No faults.
    pub const NONE: Self = Self {
        missing_probability: 0.0,
        missing_tooth: NO_TOOTH_MISSING,
        bounce_probability: 0.0,
        bounce_delay_s: 50e-6,
        dead_sensor_from_s: f32::INFINITY,
        blocked_from_s: f32::INFINITY,
        load_step_from_s: f32::INFINITY,
        load_step_nm: 0.0,
        bridge_stuck_from_s: f32::INFINITY,
        bridge_shorted_from_s: f32::INFINITY,
    };
}

/// The H-bridge's current-sense output of one axis as the MCU's ADC reads it, sampled once per
/// control tick in step with the PWM (VNH5019 CS, BTS7960 IS, or a shunt and amplifier), with
/// the errors a real one has. The armature current flows through the sense only while the
/// bridge drives: a coasting bridge's (or a cut supply's) reading is the offset and the noise.
/// Signed in the motor's positive direction (firmware multiplies an unsigned CS reading by
/// the direction the bridge drives).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurrentSense {
    /// The axis has one (rig file `current_sense = true`); most rigs have none yet.
    pub enabled: bool,
    /// Zero offset, A (added to every reading).
    pub offset_a: f32,
    /// Gain error, fraction (a reading is `(1 + gain_error) * i + offset + noise`).
    pub gain_error: f32,
    /// Noise, A (uniform in +/- this, independent per sample).
    pub noise_a: f32,
}

impl CurrentSense {
    /// No current sense.
    pub const NONE: Self = Self {
        enabled: false,
        offset_a: 0.0,
        gain_error: 0.0,
        noise_a: 0.0,
    };
    /// A typical sense chain when `current_sense = true` and no error keys are given: 20 mA
    /// offset, 3 % gain error, 10 mA noise (a VNH5019's CS through a 12-bit ADC).
    pub const TYPICAL: Self = Self {
        enabled: true,
        offset_a: 0.02,
        gain_error: 0.03,
        noise_a: 0.01,
    };
}

/// One axis of the rig.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisParams {
    /// Motor and load.
    pub motor: MotorParams,
    /// Sensor.
    pub sensor: SensorParams,
    /// Once-per-revolution load ripple amplitude, N m (an off-centre load).
    pub ripple_nm: f32,
    /// Material poured in after commissioning, N m of friction-like drag: the experiments add
    /// it through [`AxisFaults::load_step_nm`] once the controller has identified its model.
    pub load_step_nm: f32,
    /// Injected faults.
    pub faults: AxisFaults,
    /// The bridge's current-sense output, if the rig has one.
    pub current_sense: CurrentSense,
}

/// The whole rig.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantParams {
    /// `[precession, spin]`.
    pub axes: [AxisParams; 2],
    /// Supply voltage, V.
    pub supply_v: f32,
    /// Projection of the spin axis's reaction onto the precession axis (`cos` of the angle
    /// between the axes; 0 turns coupling off). The spin motor's stator and the spin bearing sit
    /// on the rod, so the rod feels the motor torque minus the bearing and gearbox friction:
    /// the rate of change of the bowl's angular momentum, `J2 dw2/dt`.
    pub coupling: f32,
    /// Capture timer rate, Hz.
    pub timer_hz: u32,
    /// Capture timer width, bits (16 or 32).
    pub timer_bits: u8,
    /// Physics steps per control tick.
    pub substeps: u32,
}

impl PlantParams {
    /// The nominal rig: nominal motors, 12 pulses per revolution, ideal sensors, a small load
    /// ripple (2 mN m: a 0.2 kg load 1 mm off-centre), rigid coupling at 60 degrees.
    pub const fn nominal() -> Self {
        let sensor = SensorParams {
            pulses_per_rev: 12,
            tooth_error: 0.0,
            jitter_s: 0.0,
        };
        Self {
            axes: [
                AxisParams {
                    motor: MotorParams::nominal_precession(),
                    sensor,
                    ripple_nm: 0.002,
                    load_step_nm: 0.0,
                    faults: AxisFaults::NONE,
                    current_sense: CurrentSense::NONE,
                },
                AxisParams {
                    motor: MotorParams::nominal_spin(),
                    sensor,
                    ripple_nm: 0.002,
                    load_step_nm: 0.0,
                    faults: AxisFaults::NONE,
                    current_sense: CurrentSense::NONE,
                },
            ],
            supply_v: 12.0,
            coupling: 0.5,
            timer_hz: 1_000_000,
            timer_bits: 32,
            substeps: 4,
        }
    }

    /// The precession duty that cancels a unit spin acceleration, duty s^2/rad: the reaction
    /// `coupling J2 dw2/dt` over the precession motor's torque per duty `k1 V / R1` (what
    /// commissioning measures as `MotorModel::reaction_duty_s2_per_rad`).
    pub fn ideal_reaction_duty_s2_per_rad(&self) -> f32 {
        let p = &self.axes[0].motor;
        self.coupling * self.axes[1].motor.inertia_kg_m2 * p.resistance_ohm
            / (p.torque_constant * self.supply_v)
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct AxisSim {
    motor: MotorState,
    angle_rad: f64,
    tooth: i64,
    buf: [u32; EDGE_BUFFER],
    len: usize,
    pending_bounce: Option<f64>,
    lost_overflow: u32,
    edges_emitted: u32,
    edges_dropped: u32,
    torque_nm: f32,
    /// Sign of the last nonzero duty commanded (a shorted bridge drives that way).
    last_direction: f32,
}

/// The simulated rig.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plant {
    p: PlantParams,
    axes: [AxisSim; 2],
    time_s: f64,
    rng: Prng,
    seed: u32,
    mask: u32,
    /// Control periods so far (indexes the current sense's noise).
    tick_count: u32,
    /// The supply cut is open: no bridge drives (see [`Plant::cut_supply`]).
    supply_cut: bool,
}

impl Plant {
    /// A rig at rest at time 0; `seed` fixes tooth errors, jitter and fault draws.
    pub fn new(p: PlantParams, seed: u32) -> Self {
        let a = AxisSim {
            motor: MotorState::default(),
            angle_rad: 0.0,
            tooth: 0,
            buf: [0; EDGE_BUFFER],
            len: 0,
            pending_bounce: None,
            lost_overflow: 0,
            edges_emitted: 0,
            edges_dropped: 0,
            torque_nm: 0.0,
            last_direction: 1.0,
        };
        let mut axes = [a; 2];
        // Start between teeth, not on one.
        for (i, ax) in axes.iter_mut().enumerate() {
            ax.angle_rad = 0.37 + i as f64 * 0.11;
            let pitch = core::f64::consts::TAU / p.axes[i].sensor.pulses_per_rev as f64;
            ax.tooth = libm::floor(ax.angle_rad / pitch) as i64;
        }
        Self {
            p,
            axes,
            time_s: 0.0,
            rng: Prng::new(seed),
            seed,
            tick_count: 0,
            supply_cut: false,
            mask: if p.timer_bits >= 32 {
                u32::MAX
            } else {
                (1u32 << p.timer_bits) - 1
            },
        }
    }

    /// Parameters.
    pub fn params(&self) -> &PlantParams {
        &self.p
    }
    /// Parameters, to inject a fault or a load change mid-run.
    pub fn params_mut(&mut self) -> &mut PlantParams {
        &mut self.p
    }
    /// Simulation time, s.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }
    /// True speed of an axis, rad/s.
    pub fn speed_rad_s(&self, axis: usize) -> f32 {
        self.axes[axis].motor.speed_rad_s
    }
    /// True shaft angle of an axis since the start, rad.
    pub fn angle_rad(&self, axis: usize) -> f64 {
        self.axes[axis].angle_rad
    }
    /// Armature current of an axis, A.
    pub fn current_a(&self, axis: usize) -> f32 {
        self.axes[axis].motor.current_a
    }
    /// The current-sense reading of an axis at the end of the last control period, A (sampled
    /// in step with the PWM): `(1 + gain_error) i + offset + noise`, where `i` is the armature
    /// current while the bridge drives and 0 while it coasts. None where the axis has no
    /// current sense.
    pub fn sensed_current_a(&self, axis: usize) -> Option<f32> {
        let c = self.p.axes[axis].current_sense;
        if !c.enabled {
            return None;
        }
        let i = self.axes[axis].motor.current_a;
        let n = self.tick_count.wrapping_mul(2).wrapping_add(axis as u32);
        let noise = c.noise_a * hashed_symmetric(self.seed ^ 0x00c0_ffee, n);
        Some((1.0 + c.gain_error) * i + c.offset_a + noise)
    }
    /// Opens the supply cut (a relay or high-side switch ahead of both bridges): from now on no
    /// bridge drives, whatever it is told or however it failed. Stays open.
    pub fn cut_supply(&mut self) {
        self.supply_cut = true;
    }
    /// Closes the supply cut again (a board that switches its supply back on after CLEAR).
    pub fn restore_supply(&mut self) {
        self.supply_cut = false;
    }
    /// The supply cut is open.
    pub fn supply_is_cut(&self) -> bool {
        self.supply_cut
    }
    /// Capture timer value now.
    pub fn now_ticks(&self) -> u32 {
        ticks_of(self.time_s, self.p.timer_hz) & self.mask
    }
    /// Edges captured on `axis` during the last [`Plant::advance`].
    pub fn edges(&self, axis: usize) -> &[u32] {
        &self.axes[axis].buf[..self.axes[axis].len]
    }
    /// Edges dropped because the per-tick buffer was full (never expected in normal runs).
    pub fn lost_edges(&self, axis: usize) -> u32 {
        self.axes[axis].lost_overflow
    }
    /// Edges emitted by the sensor so far (after injected faults).
    pub fn edges_emitted(&self, axis: usize) -> u32 {
        self.axes[axis].edges_emitted
    }
    /// Edges the sensor dropped so far ([`AxisFaults::missing_probability`] and
    /// [`AxisFaults::missing_tooth`]; a dead sensor's are not counted).
    pub fn edges_dropped(&self, axis: usize) -> u32 {
        self.axes[axis].edges_dropped
    }

    /// Advances by one control period `dt_s` with the duties held (zero duty = coast).
    pub fn advance(&mut self, duties: [f32; 2], dt_s: f32) {
        for a in &mut self.axes {
            a.len = 0;
        }
        self.tick_count = self.tick_count.wrapping_add(1);
        let n = self.p.substeps.max(1);
        let h = dt_s / n as f32;
        for _ in 0..n {
            self.substep(duties, h);
        }
    }

    fn substep(&mut self, duties: [f32; 2], h: f32) {
        let t0 = self.time_s;
        let t1 = t0 + h as f64;
        // Spin first: its reaction acts on the precession axis in the same step.
        let mut spin_reaction = 0.0;
        for i in [1usize, 0] {
            let ap = self.p.axes[i];
            let f = ap.faults;
            let ax = &mut self.axes[i];
            // A NaN duty drives nothing (coast), never full reverse.
            let mut d = if duties[i].is_nan() {
                0.0
            } else {
                duties[i].clamp(-1.0, 1.0)
            };
            if d != 0.0 && t0 as f32 >= f.bridge_stuck_from_s {
                d = d.signum();
            }
            if d != 0.0 {
                ax.last_direction = d.signum();
            }
            if t0 as f32 >= f.bridge_shorted_from_s {
                d = ax.last_direction;
            }
            if self.supply_cut {
                d = 0.0;
            }
            let volts = if d == 0.0 {
                None
            } else {
                Some(d * self.p.supply_v)
            };
            let mut load = ap.ripple_nm * libm::sin(ax.angle_rad) as f32;
            let mut motor = ap.motor;
            if t0 as f32 >= f.load_step_from_s {
                // Material drag: friction-like, it opposes motion and never drives the shaft.
                motor.coulomb_nm += f.load_step_nm;
                motor.stiction_nm += f.load_step_nm;
            }
            if i == 0 {
                load += self.p.coupling * spin_reaction;
            }
            let blocked = t0 as f32 >= f.blocked_from_s;
            let w0 = ax.motor.speed_rad_s;
            ax.torque_nm = ax.motor.step(&motor, volts, load, blocked, h);
            let w1 = ax.motor.speed_rad_s;
            if i == 1 {
                spin_reaction = ap.motor.inertia_kg_m2 * (w1 - w0) / h;
            }
            let a0 = ax.angle_rad;
            ax.angle_rad += 0.5 * (w0 + w1) as f64 * h as f64;
            self.emit_edges(i, a0, t0, t1);
        }
        self.time_s = t1;
    }

    fn emit_edges(&mut self, i: usize, a0: f64, t0: f64, t1: f64) {
        let sensor = self.p.axes[i].sensor;
        let f = self.p.axes[i].faults;
        let pitch = core::f64::consts::TAU / sensor.pulses_per_rev as f64;
        let n = sensor.pulses_per_rev as i64;
        let a1 = self.axes[i].angle_rad;
        // A pending bounce from the previous step.
        if let Some(tb) = self.axes[i].pending_bounce
            && tb < t1
        {
            self.axes[i].pending_bounce = None;
            self.push_edge(i, tb, f);
        }
        loop {
            let ax = &self.axes[i];
            let forward = a1 >= a0;
            let k = if forward { ax.tooth + 1 } else { ax.tooth };
            let tooth_in_rev = k.rem_euclid(n) as u32;
            let err =
                sensor.tooth_error * hashed_symmetric(self.seed ^ (i as u32) << 16, tooth_in_rev);
            let at = (k as f64 + err as f64) * pitch;
            let crossed = if forward {
                at <= a1 && at > a0
            } else {
                at >= a1 && at < a0
            };
            if !crossed {
                break;
            }
            let frac = if a1 != a0 { (at - a0) / (a1 - a0) } else { 0.0 };
            // A NaN fraction maps to 0, never into the timestamp.
            let frac = if frac.is_nan() {
                0.0
            } else {
                frac.clamp(0.0, 1.0)
            };
            let t = t0 + frac * (t1 - t0);
            self.axes[i].tooth = if forward { k } else { k - 1 };
            let jitter = sensor.jitter_s * self.rng.symmetric();
            let te = t + jitter as f64;
            if (t as f32) >= f.dead_sensor_from_s {
                continue;
            }
            if (f.missing_probability > 0.0 && self.rng.unit() < f.missing_probability)
                || tooth_in_rev == f.missing_tooth as u32
            {
                let ax = &mut self.axes[i];
                ax.edges_dropped = ax.edges_dropped.wrapping_add(1);
                continue;
            }
            self.push_edge(i, te.max(t0).min(t1), f);
            if f.bounce_probability > 0.0 && self.rng.unit() < f.bounce_probability {
                let tb = te + f.bounce_delay_s as f64;
                if tb < t1 {
                    self.push_edge(i, tb, f);
                } else {
                    self.axes[i].pending_bounce = Some(tb);
                }
            }
        }
    }

    fn push_edge(&mut self, i: usize, t: f64, _f: AxisFaults) {
        let ticks = ticks_of(t, self.p.timer_hz) & self.mask;
        let ax = &mut self.axes[i];
        ax.edges_emitted = ax.edges_emitted.wrapping_add(1);
        if ax.len < EDGE_BUFFER {
            ax.buf[ax.len] = ticks;
            ax.len += 1;
        } else {
            ax.lost_overflow = ax.lost_overflow.wrapping_add(1);
        }
    }
}

fn ticks_of(t_s: f64, hz: u32) -> u32 {
    let x = libm::floor(t_s * hz as f64);
    // Wrap like a free-running counter.
    (x - libm::floor(x / 4_294_967_296.0) * 4_294_967_296.0) as u32
}
