//! A parameter "flash" region for the emulated board, in RAM that survives a reset (QEMU keeps
//! RAM across a guest reset and the startup code does not touch `.uninit`), with NOR semantics:
//! erase sets every byte to 0xFF, programming can only clear bits. After power-on it holds
//! whatever QEMU's RAM held (zeros), which the parameter log sees as written-but-corrupt slots.

use core::mem::MaybeUninit;

use crate::app::hal::{FlashError, FlashRegion};

const SIZE: usize = 1024;

#[unsafe(link_section = ".uninit.bowl_params")]
static mut REGION: MaybeUninit<[u8; SIZE]> = MaybeUninit::uninit();

/// The region; one instance at a time (see [`RamFlash::take`]).
pub struct RamFlash {
    _private: (),
}

impl RamFlash {
    /// The region. The caller keeps a single instance (it is the board's only flash region).
    pub fn take() -> Self {
        Self { _private: () }
    }

    fn bytes(&mut self) -> &mut [u8; SIZE] {
        // SAFETY: `&mut self` of the single instance is the only access path; every bit
        // pattern is a valid byte array.
        unsafe { (*core::ptr::addr_of_mut!(REGION)).assume_init_mut() }
    }
}

fn span(offset: u32, len: usize) -> Result<core::ops::Range<usize>, FlashError> {
    let start = offset as usize;
    let end = start.checked_add(len).ok_or(FlashError::OutOfBounds)?;
    if end > SIZE {
        return Err(FlashError::OutOfBounds);
    }
    Ok(start..end)
}

impl FlashRegion for RamFlash {
    const SECTOR_SIZE: u32 = (SIZE / 2) as u32;
    const SECTORS: u32 = 2;

    fn read(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        let r = span(offset, buf.len())?;
        buf.copy_from_slice(&self.bytes()[r]);
        Ok(())
    }

    fn write(&mut self, offset: u32, data: &[u8]) -> Result<(), FlashError> {
        if !offset.is_multiple_of(4) || !data.len().is_multiple_of(4) {
            return Err(FlashError::OutOfBounds);
        }
        let r = span(offset, data.len())?;
        for (dst, &b) in self.bytes()[r].iter_mut().zip(data) {
            *dst &= b;
        }
        Ok(())
    }

    fn erase(&mut self, sector: u32) -> Result<(), FlashError> {
        let r = span(sector * Self::SECTOR_SIZE, Self::SECTOR_SIZE as usize)?;
        self.bytes()[r].fill(0xFF);
        Ok(())
    }
}
