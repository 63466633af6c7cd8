//! The virtual rig: the simulated plant and the controller ([`crate::backend`]) behind
//! the protocol device (`model_core::wire::device`, the same code the firmware runs), advanced one
//! millisecond at a time. `bowl serve` ([`crate::serve`]) puts it on a pseudo-terminal or into a
//! capture file; the demo serves it the same way.

use anyhow::Result;
use model_core::wire::MAX_FRAME_LEN;
use model_core::wire::device::Device;

use crate::backend::SimulatedBackend;

/// The rig plus the protocol, advanced one millisecond at a time.
pub struct VirtualRig {
    rig: SimulatedBackend,
    device: Device,
    pub now_ms: u32,
}

impl VirtualRig {
    pub fn new(seed: u32) -> Result<Self> {
        Self::with_plant(
            model_core::sim::PlantParams::nominal(),
            model_core::sim::granule::ParticleParams::default(),
            seed,
        )
    }

    /// A virtual rig on the given plant and granules (a rig file's), commissioned on it.
    pub fn with_plant(
        plant: model_core::sim::PlantParams,
        particle: model_core::sim::granule::ParticleParams,
        seed: u32,
    ) -> Result<Self> {
        Ok(Self {
            rig: SimulatedBackend::with_plant(plant, particle, seed)?,
            device: Device::new(),
            now_ms: 0,
        })
    }

    /// The boot announcement.
    pub fn boot(&mut self, out: &mut Vec<u8>) {
        let mut buf = [0u8; MAX_FRAME_LEN];
        if let Some(n) = self.device.hello(self.rig.bound(), &mut buf) {
            out.extend_from_slice(&buf[..n]);
        }
    }

    /// One millisecond: take the received bytes, run the plant and controller, send what is due.
    pub fn step_1ms(&mut self, received: &[u8], out: &mut Vec<u8>) {
        self.device
            .receive(self.rig.bound_mut(), received, |answer| {
                out.extend_from_slice(answer)
            });
        self.now_ms = self.now_ms.wrapping_add(1);
        self.rig.advance_to_ms(self.now_ms);
        let mut buf = [0u8; MAX_FRAME_LEN];
        while let Some(n) = self.device.poll_gate_event(self.rig.bound_mut(), &mut buf) {
            out.extend_from_slice(&buf[..n]);
        }
        if let Some(n) = self
            .device
            .poll_telemetry(self.rig.bound(), self.now_ms, &mut buf)
        {
            out.extend_from_slice(&buf[..n]);
        }
    }
}
