//! Flash sectors 6 and 7 of the STM32F411CE (0x0804_0000..0x0808_0000, 128 KiB each) as the
//! parameter region. `memory.x` ends the image's flash before sector 6, so code never lands
//! there; docs/wiring.md notes the reservation.

use embassy_stm32::flash::{Blocking, Flash};

use crate::app::hal::{FlashError, FlashRegion};

/// Offset of sector 6 from the start of flash.
const REGION_OFFSET: u32 = 0x4_0000;

/// The parameter sectors.
pub struct ParamSector {
    flash: Flash<'static, Blocking>,
}

impl ParamSector {
    /// Wraps the flash driver.
    pub fn new(flash: Flash<'static, Blocking>) -> Self {
        Self { flash }
    }
}

fn check(offset: u32, len: usize) -> Result<(), FlashError> {
    let end = offset as u64 + len as u64;
    if end > u64::from(ParamSector::SECTOR_SIZE * ParamSector::SECTORS) {
        Err(FlashError::OutOfBounds)
    } else {
        Ok(())
    }
}

impl FlashRegion for ParamSector {
    const SECTOR_SIZE: u32 = 0x2_0000;
    const SECTORS: u32 = 2;

    fn read(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        check(offset, buf.len())?;
        self.flash
            .blocking_read(REGION_OFFSET + offset, buf)
            .map_err(|_| FlashError::Hardware)
    }

    fn write(&mut self, offset: u32, data: &[u8]) -> Result<(), FlashError> {
        check(offset, data.len())?;
        self.flash
            .blocking_write(REGION_OFFSET + offset, data)
            .map_err(|_| FlashError::Hardware)
    }

    fn erase(&mut self, sector: u32) -> Result<(), FlashError> {
        if sector >= Self::SECTORS {
            return Err(FlashError::OutOfBounds);
        }
        let start = REGION_OFFSET + sector * Self::SECTOR_SIZE;
        // A 128 KiB sector erase takes 2 s typical, 4 s at most at the x8 parallelism embassy
        // leaves after reset (1 to 2 s at x32: the datasheet's t_ERASE128KB), with the CPU
        // stalled on flash reads. The watchdog (250 ms) would reset the MCU half way: stretch
        // it to its maximum for the erase, then put it back. Only called with the motors off.
        let saved = stretch_watchdog();
        let result = self
            .flash
            .blocking_erase(start, start + Self::SECTOR_SIZE)
            .map_err(|_| FlashError::Hardware);
        restore_watchdog(saved);
        result
    }
}

const IWDG_KEY_RELOAD: u16 = 0xAAAA;
const IWDG_KEY_UNLOCK: u16 = 0x5555;

/// Sets the IWDG to its longest timeout (prescaler 256, reload 4095: 32.8 s on the typical
/// 32 kHz LSI, 22.3 s at the datasheet's fastest 47 kHz, still five times the 4 s worst-case
/// erase) and reloads it; returns the previous (prescaler, reload) registers.
fn stretch_watchdog() -> (u8, u16) {
    use embassy_stm32::pac::iwdg::vals::{Key, Pr};
    let iwdg = embassy_stm32::pac::IWDG;
    let saved = (iwdg.pr().read().pr().to_bits(), iwdg.rlr().read().rl());
    iwdg.kr()
        .write(|w| w.set_key(Key::from_bits(IWDG_KEY_RELOAD)));
    iwdg.kr()
        .write(|w| w.set_key(Key::from_bits(IWDG_KEY_UNLOCK)));
    iwdg.pr().write(|w| w.set_pr(Pr::DIVIDE_BY256));
    iwdg.rlr().write(|w| w.set_rl(0x0FFF));
    // The new values load on the next reload once the LSI domain has taken them (PVU/RVU).
    while iwdg.sr().read().pvu() || iwdg.sr().read().rvu() {}
    iwdg.kr()
        .write(|w| w.set_key(Key::from_bits(IWDG_KEY_RELOAD)));
    saved
}

fn restore_watchdog((pr, rl): (u8, u16)) {
    use embassy_stm32::pac::iwdg::vals::{Key, Pr};
    let iwdg = embassy_stm32::pac::IWDG;
    iwdg.kr()
        .write(|w| w.set_key(Key::from_bits(IWDG_KEY_UNLOCK)));
    iwdg.pr().write(|w| w.set_pr(Pr::from_bits(pr)));
    iwdg.rlr().write(|w| w.set_rl(rl));
    while iwdg.sr().read().pvu() || iwdg.sr().read().rvu() {}
    iwdg.kr()
        .write(|w| w.set_key(Key::from_bits(IWDG_KEY_RELOAD)));
}
