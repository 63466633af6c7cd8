//! Commissioning on a simulated plant (the simulator's, so the binding the firmware links never
//! needs the plant), as a real rig is commissioned once after assembly: the
//! host's virtual rig and the emulated board both start with the motor models they identified
//! on their own plant, not with the datasheet's.

use super::Plant;
use crate::binding::{ControllerBackend, Injector};
use crate::control::{IdentifyError, State};
use crate::wire::Reason;
use crate::wire::device::Backend;

/// Simulated seconds commissioning may take on a plant (it ends much sooner: about 15 s on the
/// nominal rig, 25 s on a bowl three times as heavy).
pub const ASSEMBLY_COMMISSION_MAX_S: f32 = 300.0;

/// Why commissioning on the plant did not end idle with both motors identified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AssemblyError {
    /// COMMISSION was refused (the parameters in force do not allow it).
    Refused(Reason),
    /// The routine ended in this state (a fault, or still running at the time limit), with the
    /// identification's reason if it gave one.
    Ended(State, Option<IdentifyError>),
}

/// Runs COMMISSION on `rig` against `plant`, one control period at a time, through the same
/// path the wire uses, the link held alive (no host is connected yet), until the rig is idle
/// again or [`ASSEMBLY_COMMISSION_MAX_S`] have passed. The plant keeps its clock and state for
/// what follows; the rig keeps what it identified.
pub fn commission_on_plant<I: Injector>(
    rig: &mut ControllerBackend<I>,
    plant: &mut Plant,
) -> Result<(), AssemblyError> {
    rig.commission().map_err(AssemblyError::Refused)?;
    let dt_s = 1.0 / rig.controller().config().tick_hz as f32;
    for _ in 0..(ASSEMBLY_COMMISSION_MAX_S / dt_s) as u32 {
        if rig.controller().state() != State::Commissioning {
            break;
        }
        rig.heartbeat();
        let duties = rig
            .controller_mut()
            .tick(plant.now_ticks(), [plant.edges(0), plant.edges(1)]);
        plant.advance(duties, dt_s);
    }
    let ctrl = rig.controller();
    match ctrl.state() {
        State::Idle if ctrl.identified().iter().all(Option::is_some) => Ok(()),
        state => Err(AssemblyError::Ended(state, ctrl.identify_error())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::binding::{NoInjection, default_persisted};
    use crate::control::ControllerConfig;
    use crate::sim::PlantParams;
    use crate::wire::{Hello, ResetCause};

    fn rig() -> ControllerBackend<NoInjection> {
        let hello = Hello {
            reset_cause: ResetCause::Unknown,
            reset_count: 0,
        };
        ControllerBackend::new(
            ControllerConfig::nominal(),
            default_persisted(),
            hello,
            NoInjection,
        )
        .0
    }

    #[test]
    fn the_nominal_rig_is_identified_on_its_plant() {
        let mut rig = rig();
        let mut plant = Plant::new(PlantParams::nominal(), 1);
        let before = rig.motor_models();
        assert_eq!(commission_on_plant(&mut rig, &mut plant), Ok(()));
        assert_eq!(rig.identified(), [true, true]);
        assert_ne!(rig.motor_models(), before);
        // Commissioning ran on the plant's clock: it is no longer at rest at time zero.
        assert!(plant.time_s() > 1.0, "{}", plant.time_s());
    }

    #[test]
    fn a_plant_without_sensor_edges_is_not_identified() {
        let mut rig = rig();
        let mut params = PlantParams::nominal();
        params.axes[1].faults.dead_sensor_from_s = 0.0;
        let mut plant = Plant::new(params, 1);
        let err = commission_on_plant(&mut rig, &mut plant).unwrap_err();
        assert!(
            matches!(
                err,
                AssemblyError::Ended(State::Idle | State::Fault, Some(_))
            ),
            "{err:?}"
        );
        assert!(!rig.identified()[1]);
    }
}
