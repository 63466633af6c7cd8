//! NOR flash in RAM for the host tests of the parameter log and the persistence loop.

use super::hal::{FlashError, FlashRegion};

/// NOR flash in RAM, two sectors of `S / 2` bytes: programming can only clear bits, erase sets
/// a sector's bits.
pub(crate) struct RamFlash<const S: usize> {
    pub(crate) bytes: [u8; S],
    pub(crate) erases: u32,
    /// Bytes of the next write that actually land (simulates a reset mid-write).
    pub(crate) cut_next_write_at: Option<usize>,
}

impl<const S: usize> RamFlash<S> {
    pub(crate) fn new() -> Self {
        Self {
            bytes: [0xFF; S],
            erases: 0,
            cut_next_write_at: None,
        }
    }
}

impl<const S: usize> FlashRegion for RamFlash<S> {
    const SECTOR_SIZE: u32 = (S / 2) as u32;
    const SECTORS: u32 = 2;
    fn read(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), FlashError> {
        let o = offset as usize;
        let src = self
            .bytes
            .get(o..o + buf.len())
            .ok_or(FlashError::OutOfBounds)?;
        buf.copy_from_slice(src);
        Ok(())
    }
    fn write(&mut self, offset: u32, data: &[u8]) -> Result<(), FlashError> {
        let o = offset as usize;
        if !o.is_multiple_of(4) || !data.len().is_multiple_of(4) || o + data.len() > S {
            return Err(FlashError::OutOfBounds);
        }
        let n = self.cut_next_write_at.take().unwrap_or(data.len());
        for (dst, &b) in self.bytes[o..o + n].iter_mut().zip(data) {
            *dst &= b;
        }
        Ok(())
    }
    fn erase(&mut self, sector: u32) -> Result<(), FlashError> {
        let half = S / 2;
        let start = sector as usize * half;
        self.bytes
            .get_mut(start..start + half)
            .ok_or(FlashError::OutOfBounds)?
            .fill(0xFF);
        self.erases += 1;
        Ok(())
    }
}
