//! Parameters persisted in flash: append-only records with a sequence number, a version and a
//! CRC-32.
//!
//! The region is two (or more) erasable sectors, each a row of fixed-size slots; the slots of
//! all sectors form one ring. Saving programs the slot after the newest record. A sector is
//! erased only to write into it, and never the sector holding the newest record, so at every
//! moment of a save (power may fail at any program or erase step) the last complete record is
//! still in flash: a torn record or a half-erased sector fails its CRC and is skipped. Loading
//! takes the valid record with the highest sequence number. A record of another layout version
//! is never read as this one: defaults are used and the caller reports why. Erasing stalls the
//! CPU (1 to 4 s for a 128 KiB sector): call [`ParamLog::save`] with the motors off.
//!
//! Slot layout (little-endian words): magic `BOWL`, version (u16) + value count (u16),
//! sequence (u32), reserved (u32, 0), `MAX_VALUES` values (i32, unused ones 0), CRC-32 (IEEE)
//! of all the preceding bytes of the slot: the protocol's CRC, `model_core::wire::crc`.

use model_core::wire::crc::crc32;

use super::hal::{FlashError, FlashRegion};

/// `BOWL` in ASCII, little-endian.
pub const MAGIC: u32 = u32::from_le_bytes(*b"BOWL");
/// Layout version of the values: bump when their meaning or order changes.
pub const RECORD_VERSION: u16 = 2;
/// Values a slot can hold.
pub const MAX_VALUES: usize = 48;
/// Bytes per slot: 4 header words, the values, the CRC.
pub const SLOT_BYTES: usize = 16 + 4 * MAX_VALUES + 4;
const ERASED_WORD: u32 = u32::MAX;

/// Why no parameters could be loaded (the caller then uses its defaults).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "blackpill", derive(defmt::Format))]
pub enum LoadError {
    /// The region holds no record at all (a new board, or just erased).
    Empty,
    /// Records exist but none passes its CRC check.
    Corrupt,
    /// The newest valid record has another layout version (found).
    OtherVersion(u16),
    /// The newest valid record holds another number of values (found).
    OtherCount(u16),
    /// The flash could not be read.
    Flash(FlashError),
}

/// Why a save did not happen (the previous record stays in force).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "blackpill", derive(defmt::Format))]
pub enum SaveError {
    /// More values than a slot holds.
    TooManyValues,
    /// Programming or erasing failed.
    Flash(FlashError),
    /// The record read back differs from what was written.
    Verify,
}

/// The parameter log over one flash region.
pub struct ParamLog<F: FlashRegion> {
    flash: F,
}

struct Scan {
    /// The first slot (ring index) never written, if any.
    first_free: Option<u32>,
    /// The newest slot that passed its CRC: (sequence, ring index).
    newest: Option<(u32, u32)>,
    /// Slots written but failing the check.
    corrupt: u32,
}

impl<F: FlashRegion> ParamLog<F> {
    const SLOTS_PER_SECTOR: u32 = F::SECTOR_SIZE / SLOT_BYTES as u32;
    const SLOTS: u32 = Self::SLOTS_PER_SECTOR * F::SECTORS;

    /// Wraps a flash region.
    pub fn new(flash: F) -> Self {
        Self { flash }
    }

    /// Gives the flash region back.
    pub fn into_inner(self) -> F {
        self.flash
    }

    // A region too small for one slot has no slots; these then give offset 0, whose read
    // fails with `OutOfBounds` (never a division by zero).
    fn sector_of(slot: u32) -> u32 {
        slot.checked_div(Self::SLOTS_PER_SECTOR).unwrap_or(0)
    }

    fn offset_of(slot: u32) -> u32 {
        Self::sector_of(slot) * F::SECTOR_SIZE
            + slot.checked_rem(Self::SLOTS_PER_SECTOR).unwrap_or(0) * SLOT_BYTES as u32
    }

    fn read_slot(&mut self, slot: u32) -> Result<[u8; SLOT_BYTES], FlashError> {
        let mut bytes = [0u8; SLOT_BYTES];
        self.flash.read(Self::offset_of(slot), &mut bytes)?;
        Ok(bytes)
    }

    fn is_blank(&mut self, slot: u32) -> Result<bool, FlashError> {
        Ok(self.read_slot(slot)?.iter().all(|&b| b == 0xFF))
    }

    // One copy, shared by load and save (inlined into both it would cost flash).
    #[inline(never)]
    fn scan(&mut self) -> Result<Scan, FlashError> {
        let mut scan = Scan {
            first_free: None,
            newest: None,
            corrupt: 0,
        };
        for i in 0..Self::SLOTS {
            // The first word tells an unwritten slot (programs start there) and a foreign one
            // without reading the whole slot; `next_slot` checks a slot in full before use.
            let mut head = [0u8; 4];
            self.flash.read(Self::offset_of(i), &mut head)?;
            let head = u32::from_le_bytes(head);
            if head == ERASED_WORD {
                scan.first_free.get_or_insert(i);
                continue;
            }
            if head != MAGIC {
                scan.corrupt += 1;
                continue;
            }
            let slot = self.read_slot(i)?;
            let (body, crc) = slot.split_at(SLOT_BYTES - 4);
            if u32::from_le_bytes(crc.try_into().unwrap_or([0; 4])) != crc32(body) {
                scan.corrupt += 1;
                continue;
            }
            let seq = word(&slot, 8);
            if scan.newest.is_none_or(|(s, _)| seq >= s) {
                scan.newest = Some((seq, i));
            }
        }
        Ok(scan)
    }

    /// Where the next record goes, and which sector to erase first (if any): the slot after
    /// the newest record (or the first unwritten one) if it is blank; else the start of its
    /// sector, erased, unless that sector holds the newest record, in which case the start of
    /// the following sector, erased. Never the sector of the newest record.
    fn next_slot(&mut self, scan: &Scan) -> Result<(u32, Option<u32>), FlashError> {
        let candidate = match scan.newest {
            Some((_, newest)) => (newest + 1).checked_rem(Self::SLOTS).unwrap_or(0),
            None => scan.first_free.unwrap_or(0),
        };
        if self.is_blank(candidate)? {
            return Ok((candidate, None));
        }
        let sector = Self::sector_of(candidate);
        let erase = if scan.newest.map(|(_, n)| Self::sector_of(n)) == Some(sector) {
            // Dirty after the newest record (a torn write or erase) in the same sector.
            (sector + 1).checked_rem(F::SECTORS).unwrap_or(0)
        } else {
            sector
        };
        Ok((erase * Self::SLOTS_PER_SECTOR, Some(erase)))
    }

    /// The values of the newest valid record, if it has this version and `N` values.
    pub fn load<const N: usize>(&mut self) -> Result<[i32; N], LoadError> {
        let scan = self.scan().map_err(LoadError::Flash)?;
        let Some((_, newest)) = scan.newest else {
            return Err(if scan.corrupt > 0 {
                LoadError::Corrupt
            } else {
                LoadError::Empty
            });
        };
        let slot = self.read_slot(newest).map_err(LoadError::Flash)?;
        let header = word(&slot, 4);
        let version = header as u16;
        let count = (header >> 16) as u16;
        if version != RECORD_VERSION {
            return Err(LoadError::OtherVersion(version));
        }
        if usize::from(count) != N || N > MAX_VALUES {
            return Err(LoadError::OtherCount(count));
        }
        let mut values = [0i32; N];
        for (i, v) in values.iter_mut().enumerate() {
            *v = word(&slot, 16 + 4 * i) as i32;
        }
        Ok(values)
    }

    /// Appends a record with `values` (nothing is written if they equal the newest record's).
    /// May erase a sector first: call only with the motors off.
    pub fn save<const N: usize>(&mut self, values: &[i32; N]) -> Result<(), SaveError> {
        if N > MAX_VALUES {
            return Err(SaveError::TooManyValues);
        }
        if self.load::<N>().ok().as_ref() == Some(values) {
            return Ok(());
        }
        let scan = self.scan().map_err(SaveError::Flash)?;
        let seq = scan.newest.map_or(0, |(s, _)| s.wrapping_add(1));
        let (target, erase) = self.next_slot(&scan).map_err(SaveError::Flash)?;
        if let Some(sector) = erase {
            self.flash.erase(sector).map_err(SaveError::Flash)?;
        }
        let mut slot = [0u8; SLOT_BYTES];
        put_word(&mut slot, 0, MAGIC);
        put_word(&mut slot, 4, u32::from(RECORD_VERSION) | ((N as u32) << 16));
        put_word(&mut slot, 8, seq);
        for (i, &v) in values.iter().enumerate() {
            put_word(&mut slot, 16 + 4 * i, v as u32);
        }
        let crc = crc32(&slot[..SLOT_BYTES - 4]);
        put_word(&mut slot, SLOT_BYTES - 4, crc);
        self.flash
            .write(Self::offset_of(target), &slot)
            .map_err(SaveError::Flash)?;
        if self.read_slot(target).map_err(SaveError::Flash)? != slot {
            return Err(SaveError::Verify);
        }
        Ok(())
    }
}

fn word(slot: &[u8], at: usize) -> u32 {
    slot.get(at..at + 4)
        .and_then(|w| w.try_into().ok())
        .map_or(ERASED_WORD, u32::from_le_bytes)
}

fn put_word(slot: &mut [u8], at: usize, value: u32) {
    if let Some(w) = slot.get_mut(at..at + 4) {
        w.copy_from_slice(&value.to_le_bytes());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::test_flash::RamFlash;

    /// CRC-32 (IEEE 802.3: reflected polynomial 0xEDB88320, init and final xor all ones) bit by
    /// bit, straight from its definition: the reference the records written before the log
    /// shared the protocol's CRC were checked against.
    fn crc32_by_definition(bytes: &[u8]) -> u32 {
        let mut crc = u32::MAX;
        for &b in bytes {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 != 0 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        !crc
    }

    #[test]
    fn record_crc_is_the_ieee_crc32_so_stored_records_still_load() {
        // The CRC-32/ISO-HDLC check value of "123456789" (Greg Cook's CRC catalogue).
        assert_eq!(crc32_by_definition(b"123456789"), 0xCBF4_3926);
        let mut log = ParamLog::new(RamFlash::<{ 2 * SLOT_BYTES }>::new());
        log.save(&[42, -7, 1_000_000]).unwrap();
        let flash = log.into_inner();
        let slot = &flash.bytes[..SLOT_BYTES];
        let stored = u32::from_le_bytes(slot[SLOT_BYTES - 4..].try_into().unwrap());
        assert_eq!(stored, crc32_by_definition(&slot[..SLOT_BYTES - 4]));
    }

    #[test]
    fn empty_region_reports_empty_then_round_trips() {
        let mut log = ParamLog::new(RamFlash::<{ 4 * SLOT_BYTES }>::new());
        assert_eq!(log.load::<3>(), Err(LoadError::Empty));
        log.save(&[1, -2, 300_000]).unwrap();
        assert_eq!(log.load::<3>(), Ok([1, -2, 300_000]));
    }

    #[test]
    fn newest_record_wins_and_sectors_are_erased_in_turn() {
        // Two sectors of 2 slots each.
        let mut log = ParamLog::new(RamFlash::<{ 4 * SLOT_BYTES }>::new());
        for k in 0..9 {
            log.save(&[k, k * 10]).unwrap();
            assert_eq!(log.load::<2>(), Ok([k, k * 10]));
        }
        // 9 distinct saves into a ring of 4 slots: a sector erased before the 5th, 7th and 9th.
        assert_eq!(log.into_inner().erases, 3);
    }

    /// Flash whose every program or erase step can be the last before a power cut: the step
    /// is left half done (a program lands only its first half, an erase clears only the first
    /// half of the sector) and nothing after it happens.
    struct CutFlash<const S: usize> {
        flash: RamFlash<S>,
        steps: u32,
        cut_at: u32,
    }

    impl<const S: usize> CutFlash<S> {
        fn step(&mut self) -> Result<bool, FlashError> {
            self.steps += 1;
            match self.steps.cmp(&self.cut_at) {
                core::cmp::Ordering::Less => Ok(false),
                core::cmp::Ordering::Equal => Ok(true),
                core::cmp::Ordering::Greater => Err(FlashError::Hardware),
            }
        }
    }

    impl<const S: usize> FlashRegion for CutFlash<S> {
        const SECTOR_SIZE: u32 = (S / 2) as u32;
        const SECTORS: u32 = 2;
        fn read(&mut self, offset: u32, buf: &mut [u8]) -> Result<(), FlashError> {
            self.flash.read(offset, buf)
        }
        fn write(&mut self, offset: u32, data: &[u8]) -> Result<(), FlashError> {
            for (k, chunk) in data.chunks(4).enumerate() {
                let at = offset + 4 * k as u32;
                if self.step()? {
                    self.flash.write(at, &[chunk[0], chunk[1], 0xFF, 0xFF])?;
                    return Err(FlashError::Hardware);
                }
                self.flash.write(at, chunk)?;
            }
            Ok(())
        }
        fn erase(&mut self, sector: u32) -> Result<(), FlashError> {
            if self.step()? {
                let half = S / 2;
                let start = sector as usize * half;
                self.flash.bytes[start..start + half / 2].fill(0xFF);
                return Err(FlashError::Hardware);
            }
            self.flash.erase(sector)
        }
    }

    #[test]
    fn a_power_cut_at_any_step_of_any_save_keeps_the_last_complete_record() {
        // Two sectors of 3 slots: saves 4 and 7 each begin with an erase.
        const S: usize = 6 * SLOT_BYTES;
        for saves in 1..9 {
            // Flash after `saves - 1` complete saves, then every cut point of the next one.
            let mut log = ParamLog::new(RamFlash::<S>::new());
            for k in 0..saves - 1 {
                log.save(&[k, -k]).unwrap();
            }
            let before = log.into_inner().bytes;
            let k = saves - 1;
            let steps = (SLOT_BYTES / 4) as u32 + 1;
            for cut_at in 1..=steps {
                let mut flash = RamFlash::<S>::new();
                flash.bytes = before;
                let mut log = ParamLog::new(CutFlash {
                    flash,
                    steps: 0,
                    cut_at,
                });
                let _ = log.save(&[k, -k]);
                let mut after = ParamLog::new(log.into_inner().flash);
                let loaded = after.load::<2>();
                // The first save has no earlier record to fall back on.
                let fine = loaded == Ok([k, -k])
                    || (k > 0 && loaded == Ok([k - 1, 1 - k]))
                    || (k == 0 && loaded.is_err());
                assert!(
                    fine,
                    "save {saves}, cut at step {cut_at}: loaded {loaded:?}"
                );
                // And the log goes on: the next save lands and loads.
                after.save(&[100 + k, 0]).unwrap();
                assert_eq!(after.load::<2>(), Ok([100 + k, 0]));
            }
        }
    }

    #[test]
    fn unchanged_values_are_not_rewritten() {
        let mut log = ParamLog::new(RamFlash::<{ 2 * SLOT_BYTES }>::new());
        for _ in 0..5 {
            log.save(&[7, 8]).unwrap();
        }
        let flash = log.into_inner();
        assert_eq!(flash.erases, 0);
        assert!(flash.bytes[SLOT_BYTES..].iter().all(|&b| b == 0xFF));
    }

    #[test]
    fn a_torn_write_keeps_the_previous_record_and_the_next_save_skips_it() {
        let mut log = ParamLog::new(RamFlash::<{ 4 * SLOT_BYTES }>::new());
        log.save(&[1, 2]).unwrap();
        let mut flash = log.into_inner();
        flash.cut_next_write_at = Some(40);
        let mut log = ParamLog::new(flash);
        // The cut write verifies wrong, and loading still gives the old record.
        assert_eq!(log.save(&[3, 4]), Err(SaveError::Verify));
        assert_eq!(log.load::<2>(), Ok([1, 2]));
        log.save(&[5, 6]).unwrap();
        assert_eq!(log.load::<2>(), Ok([5, 6]));
    }

    #[test]
    fn flipped_bits_are_detected() {
        let mut log = ParamLog::new(RamFlash::<{ 2 * SLOT_BYTES }>::new());
        log.save(&[123_456, 789]).unwrap();
        let flash = log.into_inner();
        for bit in [0usize, 8 * 17, 8 * 20 + 3, 8 * (SLOT_BYTES - 1) + 7] {
            let mut f = RamFlash::<{ 2 * SLOT_BYTES }>::new();
            f.bytes = flash.bytes;
            f.bytes[bit / 8] ^= 1 << (bit % 8);
            assert_eq!(
                ParamLog::new(f).load::<2>(),
                Err(LoadError::Corrupt),
                "bit {bit}"
            );
        }
    }

    #[test]
    fn other_version_or_count_is_not_read_as_ours() {
        let mut log = ParamLog::new(RamFlash::<{ 2 * SLOT_BYTES }>::new());
        log.save(&[1, 2, 3]).unwrap();
        assert_eq!(log.load::<2>(), Err(LoadError::OtherCount(3)));
        // Rewrite the record as another version with a valid CRC.
        let mut flash = log.into_inner();
        let mut slot: [u8; SLOT_BYTES] = flash.bytes[..SLOT_BYTES].try_into().unwrap();
        let other = RECORD_VERSION + 1;
        put_word(&mut slot, 4, u32::from(other) | (3 << 16));
        let crc = crc32(&slot[..SLOT_BYTES - 4]);
        put_word(&mut slot, SLOT_BYTES - 4, crc);
        flash.bytes[..SLOT_BYTES].copy_from_slice(&slot);
        assert_eq!(
            ParamLog::new(flash).load::<3>(),
            Err(LoadError::OtherVersion(other))
        );
    }
}
