//! The command table's "allowed in" column is what the rig does: in each controller state, each
//! command (the table's example) is refused with `STATE` exactly where the table does not allow
//! it. The rig is the firmware's binding on the simulated plant, driven into each state.

use model_core::binding::{ControllerBackend, NoInjection, default_persisted};
use model_core::control::ControllerConfig;
use model_core::sim::{Plant, PlantParams, commission_on_plant};
use model_core::wire::device::{Backend, Device};
use model_core::wire::*;

type Rig = ControllerBackend<NoInjection>;

/// Ticks the controller against the plant for `seconds`, the host heard each tick or not,
/// until `until` says stop.
fn run(rig: &mut Rig, plant: &mut Plant, seconds: f32, host: bool, until: impl Fn(&Rig) -> bool) {
    let dt_s = 1.0 / rig.controller().config().tick_hz as f32;
    for _ in 0..(seconds / dt_s) as u32 {
        if until(rig) {
            return;
        }
        if host {
            rig.heartbeat();
        }
        let duties = rig
            .controller_mut()
            .tick(plant.now_ticks(), [plant.edges(0), plant.edges(1)]);
        plant.advance(duties, dt_s);
    }
}

fn state(rig: &Rig) -> DeviceState {
    rig.telemetry().state
}

/// The nominal rig, commissioned on its plant, in each of the six states.
fn rigs() -> Vec<Rig> {
    let hello = Hello {
        reset_cause: ResetCause::Unknown,
        reset_count: 0,
    };
    let mut idle = ControllerBackend::new(
        ControllerConfig::nominal(),
        default_persisted(),
        hello,
        NoInjection,
    )
    .0;
    let mut plant = Plant::new(PlantParams::nominal(), 1);
    commission_on_plant(&mut idle, &mut plant).unwrap();
    let mut commissioning = idle.clone();
    commissioning.commission().unwrap();
    let mut changing_speed = idle.clone();
    changing_speed.set_speeds(1800, 2100).unwrap();
    changing_speed.start().unwrap();
    let mut running = changing_speed.clone();
    run(&mut running, &mut plant, 20.0, true, |r| {
        state(r) == DeviceState::Running
    });
    let mut stopping = running.clone();
    stopping.stop();
    let mut faulted = running.clone();
    // Host silence (LINK_TIMEOUT_MS, 3 s by default) faults a running rig.
    run(&mut faulted, &mut plant, 10.0, false, |r| {
        state(r) == DeviceState::Faulted
    });
    let rigs = vec![
        idle,
        commissioning,
        changing_speed,
        running,
        stopping,
        faulted,
    ];
    let states: Vec<DeviceState> = rigs.iter().map(state).collect();
    assert_eq!(
        states,
        (0..=5)
            .filter_map(DeviceState::from_code)
            .collect::<Vec<_>>()
    );
    rigs
}

#[test]
fn each_command_is_refused_for_the_state_exactly_where_the_table_says() {
    let mut checked = 0;
    for rig in rigs() {
        let now = state(&rig);
        for kind in CommandKind::ALL {
            let words: Vec<&str> = kind.example().split(' ').collect();
            let command = Command::from_words(&words).unwrap();
            let answer = Device::new().execute(&mut rig.clone(), 1, command);
            let refused = matches!(
                answer,
                Frame::Reject {
                    reason: Reason::State,
                    ..
                }
            );
            assert_eq!(
                refused,
                !kind.states().contains(now),
                "`{}` while {now:?}: {answer:?}",
                kind.example()
            );
            if !refused && !matches!(answer, Frame::Reject { .. }) {
                assert_eq!(
                    encode::kind_letter(&answer),
                    kind.answer().letter(),
                    "`{}` while {now:?}",
                    kind.example()
                );
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 6 * COMMAND_COUNT);
}
