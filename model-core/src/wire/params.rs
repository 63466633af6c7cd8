//! The settable parameters: ONE table. Each row gives the parameter's name in the code, its
//! token in `SET` commands, its unit, its wire range (inclusive) and the value a new board
//! starts with; [`ParamId`], [`ParamId::ALL`], [`PARAM_COUNT`] and the look-ups are made from
//! it. To change a range or a default, change its row here; to add a parameter, add a row
//! (wire order is row order) and say what it configures in `crate::binding::configure`
//! (an exhaustive `match`, so the compiler points there).
//!
//! Every range stays below 2^23 steps, so a value survives the controller's f32 configuration
//! exactly (relative f32 rounding 2^-24 is then under half a step): what PARAMS reports back is
//! what SET sent, never a silently rounded neighbour. The rig may reject a value inside the
//! wire range that conflicts with another parameter (for instance a start radius beyond the
//! rim) with [`Reason::Range`](super::Reason::Range).

use super::types::DUTY_MAX_BP;

macro_rules! parameter_table {
    ($(
        $(#[doc = $doc:literal])*
        $id:ident: $token:literal, $unit:literal, range ($min:expr, $max:expr), default $default:expr;
    )*) => {
        /// The settable parameters, in wire order (see the module docs for the table).
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub enum ParamId {
            $(
                $(#[doc = $doc])*
                #[doc = ""]
                #[doc = concat!(
                    "Token `", $token, "`, unit ", $unit, ", range ", stringify!($min), "..=",
                    stringify!($max), ", default ", stringify!($default), "."
                )]
                $id,
            )*
        }

        /// Number of parameters; a PARAMS answer carries this many values in [`ParamId::ALL`]
        /// order.
        pub const PARAM_COUNT: usize = [$(ParamId::$id),*].len();

        impl ParamId {
            /// Every parameter, in wire order.
            pub const ALL: [ParamId; PARAM_COUNT] = [$(ParamId::$id),*];

            /// The token used in `SET` commands.
            pub const fn token(self) -> &'static str {
                match self {
                    $(ParamId::$id => $token,)*
                }
            }

            /// The unit of the wire value.
            pub const fn unit(self) -> &'static str {
                match self {
                    $(ParamId::$id => $unit,)*
                }
            }

            /// The wire range (inclusive); values outside it are rejected with
            /// [`Reason::Range`](super::Reason::Range).
            pub const fn range(self) -> (i32, i32) {
                match self {
                    $(ParamId::$id => ($min, $max),)*
                }
            }

            /// The value a new board starts with (the controller's nominal configuration and
            /// the particle model's default scene, in wire units).
            pub const fn default_value(self) -> i32 {
                match self {
                    $(ParamId::$id => $default,)*
                }
            }
        }
    };
}

parameter_table! {
    /// Bowl rim radius R.
    RimUm: "RIM_UM", "um", range (10_000, 1_000_000), default 100_000;
    /// Particle start radius ri.
    StartUm: "START_UM", "um", range (0, 1_000_000), default 50_000;
    /// Effective rolling-resistance coefficient mu.
    MuPpm: "MU_PPM", "ppm", range (0, 1_000_000), default 29_000;
    /// Inertia factor k2 = m rp^2 / (I + m rp^2) (solid sphere 714 286).
    K2Ppm: "K2_PPM", "ppm", range (1, 1_000_000), default 714_286;
    /// Angle between the spin and precession axes (paper Eq. 2).
    AxesMdeg: "AXES_MDEG", "mdeg", range (0, 179_999), default 60_000;
    /// Precession speed-loop bandwidth (the PI gains follow from it and the motor model).
    Bandwidth1MradS: "BW1_MRAD_S", "mrad/s", range (10, 1_000_000), default 8_000;
    /// Spin speed-loop bandwidth.
    Bandwidth2MradS: "BW2_MRAD_S", "mrad/s", range (10, 1_000_000), default 8_000;
    /// Precession loop bandwidth per pulse rate (caps the bandwidth at low speed).
    PerPulse1Milli: "PER_PULSE1_MILLI", "1/1000", range (10, 10_000), default 500;
    /// Spin loop bandwidth per pulse rate.
    PerPulse2Milli: "PER_PULSE2_MILLI", "1/1000", range (10, 10_000), default 500;
    /// Precession speed limit (setpoints above it are rejected). It must lie above the
    /// lowest speed the controller drives (0.2 rad/s, the nominal `min_speed_rad_s`): the
    /// range says so, rather than a refusal that only the controller could explain.
    SpeedMax1MradS: "SPEED_MAX1_MRAD_S", "mrad/s", range (201, i16::MAX as i32), default 4_000;
    /// Spin speed limit (above 0.2 rad/s, as the precession's).
    SpeedMax2MradS: "SPEED_MAX2_MRAD_S", "mrad/s", range (201, i16::MAX as i32), default 4_000;
    /// Precession setpoint ramp rate (the controller's own limits: 0.01..=1000 rad/s^2).
    Accel1MradS2: "ACCEL1_MRAD_S2", "mrad/s^2", range (10, 1_000_000), default 6_000;
    /// Spin setpoint ramp rate.
    Accel2MradS2: "ACCEL2_MRAD_S2", "mrad/s^2", range (10, 1_000_000), default 6_000;
    /// Precession PWM duty limit (the controller's own limits: 0.05..=1).
    DutyMax1Bp: "DUTY_MAX1_BP", "bp", range (500, DUTY_MAX_BP as i32), default 9_500;
    /// Spin PWM duty limit.
    DutyMax2Bp: "DUTY_MAX2_BP", "bp", range (500, DUTY_MAX_BP as i32), default 9_500;
    /// Target-wheel teeth (pulses per revolution) on the precession sensor.
    Teeth1: "TEETH1", "pulses/rev", range (1, 255), default 12;
    /// Target-wheel teeth on the spin sensor.
    Teeth2: "TEETH2", "pulses/rev", range (1, 255), default 12;
    /// Spin speed per precession speed used to split a combined bowl speed (Eq. 2).
    RatioPpm: "RATIO_PPM", "ppm", range (1_000, 8_000_000), default 1_000_000;
    /// Telemetry rate, 0 = off (50 fills under half of 115 200 baud).
    TelemetryHz: "TELEM_HZ", "frames/s", range (0, 50), default 50;
    /// Host link silence (no command, PING included) after which a driving rig faults and
    /// stops both motors; 0 disables the check. Host tools PING every second.
    LinkTimeoutMs: "LINK_TIMEOUT_MS", "ms", range (0, 3_600_000), default 3_000;
    /// What speed can do (`RTIME TABLE`, docs/model.md §11): the slowest bowl speed of the
    /// residence-time table the PC computed and stored; the table is off while
    /// `RT_W_HI_MRAD_S` is not above it.
    RtSpeedLoMradS: "RT_W_LO_MRAD_S", "mrad/s", range (0, 99_999), default 0;
    /// The table's fastest bowl speed (0 = no table).
    RtSpeedHiMradS: "RT_W_HI_MRAD_S", "mrad/s", range (0, 99_999), default 0;
    /// The table's residence time at its slowest speed (entry 1 of 8).
    RtTime1Us: "RT_T1_US", "us", range (0, 8_000_000), default 0;
    /// The table's residence time at speed number 2 of 8 (evenly spaced).
    RtTime2Us: "RT_T2_US", "us", range (0, 8_000_000), default 0;
    /// The table's residence time at speed number 3 of 8 (evenly spaced).
    RtTime3Us: "RT_T3_US", "us", range (0, 8_000_000), default 0;
    /// The table's residence time at speed number 4 of 8 (evenly spaced).
    RtTime4Us: "RT_T4_US", "us", range (0, 8_000_000), default 0;
    /// The table's residence time at speed number 5 of 8 (evenly spaced).
    RtTime5Us: "RT_T5_US", "us", range (0, 8_000_000), default 0;
    /// The table's residence time at speed number 6 of 8 (evenly spaced).
    RtTime6Us: "RT_T6_US", "us", range (0, 8_000_000), default 0;
    /// The table's residence time at speed number 7 of 8 (evenly spaced).
    RtTime7Us: "RT_T7_US", "us", range (0, 8_000_000), default 0;
    /// The table's residence time at its fastest speed (entry 8 of 8).
    RtTime8Us: "RT_T8_US", "us", range (0, 8_000_000), default 0;
    /// The board measures the motor currents (docs/wiring.md: a current-sense amplifier on each
    /// motor lead into the ADC): 1 turns on the current trips (over-current, a bridge driving
    /// harder than told, the supply cut) and tells a stall from a dead sensor; 0 = pulses only.
    CurrentSense: "CUR_SENSE", "0/1", range (0, 1), default 0;
}

/// The values of all parameters, indexed by [`ParamId::index`].
pub type ParamValues = [i32; PARAM_COUNT];

impl ParamId {
    /// Position in [`ParamId::ALL`] and in a PARAMS answer.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// The parameter with this token.
    pub fn from_token(token: &[u8]) -> Option<ParamId> {
        ParamId::ALL
            .iter()
            .copied()
            .find(|p| p.token().as_bytes() == token)
    }

    /// Every parameter's [`ParamId::default_value`], in wire order.
    pub const fn defaults() -> ParamValues {
        let mut v = [0i32; PARAM_COUNT];
        let mut i = 0;
        while i < PARAM_COUNT {
            v[i] = ParamId::ALL[i].default_value();
            i += 1;
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_consistent() {
        for (i, id) in ParamId::ALL.into_iter().enumerate() {
            assert_eq!(id.index(), i, "{id:?}: wire order is row order");
            let (lo, hi) = id.range();
            assert!(lo <= hi, "{}: empty range", id.token());
            // Below 2^23 steps: exact through the controller's f32 configuration.
            assert!(i64::from(hi) - i64::from(lo) < 1 << 23, "{}", id.token());
            let d = id.default_value();
            assert!(
                (lo..=hi).contains(&d),
                "{}: default {d} outside",
                id.token()
            );
            assert_eq!(ParamId::from_token(id.token().as_bytes()), Some(id));
            assert!(!id.unit().is_empty());
        }
        assert_eq!(ParamId::ALL.len(), PARAM_COUNT);
    }
}
