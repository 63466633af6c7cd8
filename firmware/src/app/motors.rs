//! The two motor outputs and the one path that turns them off.

use super::hal::MotorOutput;

/// Axis order everywhere: precession (omega1, the rod) then spin (omega2, the bowl).
pub const AXES: usize = 2;

/// Turns a controller duty into what the PWM may be given: finite and within -1..=1, else 0.
/// A NaN or out-of-range duty is a bug upstream; off is the only safe reading of it.
pub fn sanitize_duty(duty: f32) -> f32 {
    if duty.is_finite() && (-1.0..=1.0).contains(&duty) {
        duty
    } else {
        0.0
    }
}

/// Both motors.
pub struct Motors<M: MotorOutput> {
    outputs: [M; AXES],
    duties: [f32; AXES],
}

impl<M: MotorOutput> Motors<M> {
    /// Takes the outputs and turns both off.
    pub fn new(outputs: [M; AXES]) -> Self {
        let mut m = Self {
            outputs,
            duties: [0.0; AXES],
        };
        m.all_off();
        m
    }

    /// Applies the controller's duties (each sanitised).
    pub fn apply(&mut self, duties: [f32; AXES]) {
        for ((out, applied), d) in self.outputs.iter_mut().zip(&mut self.duties).zip(duties) {
            let d = sanitize_duty(d);
            out.set_duty(d);
            *applied = d;
        }
    }

    /// Both outputs off at once.
    pub fn all_off(&mut self) {
        for out in &mut self.outputs {
            out.off();
        }
        self.duties = [0.0; AXES];
    }

    /// A fault: both output stages disabled (see [`MotorOutput::disable`]).
    pub fn fault_stop(&mut self) {
        for out in &mut self.outputs {
            out.disable();
        }
        self.duties = [0.0; AXES];
    }

    /// The duties last applied.
    pub fn duties(&self) -> [f32; AXES] {
        self.duties
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Default)]
    struct Probe {
        duty: Option<f32>,
    }
    impl MotorOutput for Probe {
        fn set_duty(&mut self, duty: f32) {
            self.duty = Some(duty);
        }
        fn off(&mut self) {
            self.duty = Some(0.0);
        }
    }

    #[test]
    fn off_at_construction_and_bad_duties_become_off() {
        let mut m = Motors::new([Probe::default(), Probe::default()]);
        assert_eq!(m.outputs[0].duty, Some(0.0));
        m.apply([0.5, -0.25]);
        assert_eq!(m.duties(), [0.5, -0.25]);
        m.apply([f32::NAN, 1.5]);
        assert_eq!(m.duties(), [0.0, 0.0]);
        assert_eq!(m.outputs[1].duty, Some(0.0));
        m.apply([-1.0, 1.0]);
        m.all_off();
        assert_eq!(m.duties(), [0.0, 0.0]);
    }
}
