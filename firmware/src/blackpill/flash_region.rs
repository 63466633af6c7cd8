//! Flash sector 7 of the STM32F411CE (0x0806_0000, 128 KiB) as the parameter region.
//! The image (under 64 KiB) never reaches it; docs/wiring.md notes the reservation.

use embassy_stm32::flash::{Blocking, Flash};

use crate::app::hal::{FlashError, FlashRegion};

/// Offset of sector 7 from the start of flash.
const SECTOR7_OFFSET: u32 = 0x6_0000;

/// The parameter sector.
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
    if end > u64::from(ParamSector::SIZE) {
        Err(FlashError::OutOfBounds)
    } else {
        Ok(())
    }
}

impl FlashRegion for ParamSector {
    const SIZE: u32 = 0x2_0000;

    fn read(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        check(offset, buf.len())?;
        self.flash
            .blocking_read(SECTOR7_OFFSET + offset, buf)
            .map_err(|_| FlashError::Hardware)
    }

    fn write(&mut self, offset: u32, data: &[u8]) -> Result<(), FlashError> {
        check(offset, data.len())?;
        self.flash
            .blocking_write(SECTOR7_OFFSET + offset, data)
            .map_err(|_| FlashError::Hardware)
    }

    fn erase(&mut self) -> Result<(), FlashError> {
        self.flash
            .blocking_erase(SECTOR7_OFFSET, SECTOR7_OFFSET + Self::SIZE)
            .map_err(|_| FlashError::Hardware)
    }
}
