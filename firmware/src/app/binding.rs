//! The tasks' [`TaskCore`]: the protocol device and the controller backend together. The binding
//! of the controller and the particle model to the protocol is `model_core::binding` (the host's
//! virtual rig runs the same one); it is re-exported here.

pub use model_core::binding::{
    AXES as BOUND_AXES, ControllerBackend, Injector, NoInjection, OVERSPEED_PER_MAX,
    PERSISTED_COUNT, Persisted, default_params, default_persisted, persisted, split_persisted,
};
use model_core::control::State;
use model_core::wire::device::Device;
use model_core::wire::{Command, MAX_FRAME_LEN, ParamId};

use super::motors::AXES;
use super::tasks::{FRAME_BYTES, TaskCore};

const _: () = assert!(FRAME_BYTES == MAX_FRAME_LEN);
const _: () = assert!(AXES == BOUND_AXES);

/// The protocol device and the controller backend together: what the tasks run.
pub struct DeviceCore<I: Injector> {
    /// The protocol state (decoder, telemetry pacing).
    pub device: Device,
    /// The controller behind the protocol.
    pub backend: ControllerBackend<I>,
    dropped_edges: [u32; AXES],
}

impl<I: Injector> DeviceCore<I> {
    /// The device core; the telemetry rate comes from `backend`'s parameters.
    pub fn new(backend: ControllerBackend<I>) -> Self {
        let mut s = Self {
            device: Device::new(),
            backend,
            dropped_edges: [0; AXES],
        };
        let hz = s.backend.params()[ParamId::TelemetryHz.index()];
        // Inside the wire range by construction (checked params); a refusal keeps the default.
        let _ = s.device.execute(
            &mut s.backend,
            0,
            Command::SetParam {
                id: ParamId::TelemetryHz,
                value: hz,
            },
        );
        s
    }

    /// Every parameter including the telemetry rate, and the motor models, for persisting.
    pub fn params_to_persist(&self) -> Persisted {
        self.backend.to_persist(self.device.telemetry_hz())
    }

    /// Edges lost in capture so far, per axis.
    pub fn dropped_edges(&self) -> [u32; AXES] {
        self.dropped_edges
    }
}

impl<I: Injector> TaskCore for DeviceCore<I> {
    fn control_tick(
        &mut self,
        now_ticks: u32,
        edges: [&[u32]; AXES],
        currents_a: [Option<f32>; AXES],
    ) -> [f32; AXES] {
        // Only a board declared to measure them (CUR_SENSE 1): unconnected ADC pins read noise.
        let fitted = self.backend.params()[ParamId::CurrentSense.index()] == 1;
        let currents = if fitted { currents_a } else { [None; AXES] };
        self.backend
            .controller_mut()
            .tick_with_currents(now_ticks, edges, currents)
    }

    fn faulted(&self) -> bool {
        self.backend.controller().state() == State::Fault
    }

    fn hardware_stop(&mut self) {
        self.backend.controller_mut().hardware_stop();
    }

    fn cuts_supply(&self) -> bool {
        let c = self.backend.controller();
        c.supply_cut_requested() || c.fault().is_some_and(|f| f.cuts_supply())
    }

    fn hello(&mut self, out: &mut [u8; FRAME_BYTES]) -> Option<usize> {
        self.device.hello(&self.backend, out)
    }

    fn receive(&mut self, bytes: &[u8], send: &mut dyn FnMut(&[u8])) {
        self.device.receive(&mut self.backend, bytes, send);
    }

    fn poll_telemetry(&mut self, now_ms: u32, out: &mut [u8; FRAME_BYTES]) -> Option<usize> {
        self.backend.set_now_ms(now_ms);
        self.device.poll_telemetry(&self.backend, now_ms, out)
    }

    fn poll_gate_event(&mut self, out: &mut [u8; FRAME_BYTES]) -> Option<usize> {
        self.device.poll_gate_event(&mut self.backend, out)
    }

    fn set_dropped_edges(&mut self, dropped: [u32; AXES]) {
        self.dropped_edges = dropped;
    }
}
