//! A reset counter that survives resets (not power loss) in RAM that the startup code leaves
//! alone, guarded by a magic word and an inverted copy so power-on garbage is never taken for
//! a count.

/// Marks a valid counter record.
const MAGIC: u32 = 0x5253_5431; // "RST1"

/// The raw record kept in uninitialised RAM: magic, count, !count.
pub type ResetRecord = [u32; 3];

/// Counts this boot: returns the number of resets since power-on (0 on the first boot after
/// power-on, when the record is garbage) and the record to store back.
pub fn count_boot(record: ResetRecord) -> (u32, ResetRecord) {
    let [magic, count, inverted] = record;
    let count = if magic == MAGIC && inverted == !count {
        count.saturating_add(1)
    } else {
        0
    };
    (count, [MAGIC, count, !count])
}

/// Updates the board's record in `.uninit` RAM and returns the resets since power-on.
/// Call once at boot, before anything could reset the MCU again.
#[cfg(target_os = "none")]
pub fn count_this_boot() -> u32 {
    use core::mem::MaybeUninit;
    #[unsafe(link_section = ".uninit.bowl_reset")]
    static mut RECORD: MaybeUninit<ResetRecord> = MaybeUninit::uninit();
    // SAFETY: called once at boot before any task runs, so nothing else touches RECORD; any bit
    // pattern is a valid [u32; 3] (after power-on it is garbage, which `count_boot` rejects).
    unsafe {
        let slot = core::ptr::addr_of_mut!(RECORD).cast::<ResetRecord>();
        let (count, next) = count_boot(slot.read_volatile());
        slot.write_volatile(next);
        count
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn garbage_starts_at_zero_then_counts() {
        for garbage in [[0, 0, 0], [0xFFFF_FFFF; 3], [MAGIC, 5, 5], [0x1234, 1, !1]] {
            let (n, mut rec) = count_boot(garbage);
            assert_eq!(n, 0, "{garbage:x?}");
            for want in 1..5 {
                let (n, next) = count_boot(rec);
                assert_eq!(n, want);
                rec = next;
            }
        }
    }
}
