//! The current sense inside the controller: each sample checked by the axis's
//! [`CurrentWatch`](crate::control::supervisor::CurrentWatch), a trip latched in the tick it is
//! seen, the supply cut asked for when a bridge cannot be trusted to stop, and the sensor-lost
//! watch's fault told apart (stall or dead sensor) by the back-EMF.

use super::Controller;
use crate::control::supervisor::{
    BACK_EMF_SPEED_SHARE, BACK_EMF_STEADY_SHARE, CURRENT_READING_LIMIT_A, CurrentTrip, Fault,
};

impl Controller {
    /// One current sample of axis `i` (see [`Controller::tick_with_currents`]). Out of line:
    /// only boards with current sense pay for it.
    #[inline(never)]
    pub(super) fn current_sample(&mut self, i: usize, reading_a: f32, applied: f32) {
        let a = &mut self.axes[i];
        // The loop's view of the reading (breakaway.rs): the current as the duty that drives it
        // into a held shaft, once the watch has learned the offset and the current per duty.
        let g = a.current.amps_per_duty();
        a.torque_duty = (g > 0.0 && reading_a.abs() <= CURRENT_READING_LIMIT_A)
            .then(|| (reading_a - a.current.offset_a()) * a.direction / g);
        if let Some(c) = a.torque_duty {
            // The back-EMF per rad/s where the edges measure the speed (commissioning's steady
            // runs, then every steady run), for the loop's back-EMF speed at the next start.
            let measured = if a.est.is_valid() { a.measured } else { 0.0 };
            a.emf.sample(applied * a.direction, c, measured, self.dt_s);
        }
        a.speed_loop
            .set_back_emf(a.emf.back_emf(a.k.duty_per_rad_s()));
        let model = a.speed_loop.model_rad_s().abs();
        let share = if a.steady {
            BACK_EMF_STEADY_SHARE
        } else {
            BACK_EMF_SPEED_SHARE
        };
        let speed_lo_rad_s = if a.est.is_valid() {
            share * a.measured.abs().min(model)
        } else {
            0.0
        };
        let trip = a.current.sample(
            reading_a,
            applied,
            a.direction,
            // At rest for the current per duty: no edge since it stopped, or none for so long
            // that the estimate is zero (the precession turned by the spin's reaction keeps its
            // last edge for seconds: its own start then taught nothing, seed 4 p10).
            a.est.at_rest() || a.est.is_stopped(),
            speed_lo_rad_s,
            a.k.duty_per_rad_s(),
            a.k.duty_limit(),
        );
        let Some(trip) = trip else {
            return;
        };
        // A bridge driving harder than it is told (at zero duty: still driving after it was
        // told to stop; otherwise more current than the duty drives into a held shaft) cannot
        // be trusted to stop: only the supply cut stops it. Over-current too (a short).
        if trip != CurrentTrip::Uncommanded {
            self.supply_cut = true;
        }
        self.latch(match trip {
            CurrentTrip::OverCurrent => Fault::OverCurrent(i as u8),
            CurrentTrip::Uncommanded | CurrentTrip::BridgeDriving => {
                Fault::CurrentAboveModel(i as u8)
            }
        });
    }

    /// The sensor-lost watch fired on axis `i`: the current, where there is one, tells a dead
    /// sensor (back-EMF of a turning shaft) from a stall (none).
    #[cold]
    pub(super) fn lost_edges_fault(&self, i: usize) -> Fault {
        let a = &self.axes[i];
        match a
            .current
            .shaft_turns(a.speed_loop.model_rad_s(), a.k.duty_per_rad_s())
        {
            Some(true) => Fault::SensorLost(i as u8),
            Some(false) => Fault::Stall(i as u8),
            None => Fault::SensorLostOrStall(i as u8),
        }
    }

    /// The supply cut is asked open (latched until [`Controller::clear_fault`]): a bridge drove
    /// harder than it was told (a current with the bridge told to stop, as a shorted bridge
    /// gives; or more current than the duty drives into a held shaft, as a bridge stuck on at low
    /// speed gives), or an over-current. Firmware drives its supply-cut output from this (open
    /// = no power to the bridges); the simulated rig opens its cut.
    pub fn supply_cut_requested(&self) -> bool {
        self.supply_cut
    }

    /// The current sense's learned offset and current per duty on `axis`, A and A per duty
    /// (`(0, 0)` until learned; the current per duty needs a start from rest).
    pub fn current_sense_learned(&self, axis: usize) -> (f32, f32) {
        self.axes.get(axis).map_or((0.0, 0.0), |a| {
            (a.current.offset_a(), a.current.amps_per_duty())
        })
    }
}
