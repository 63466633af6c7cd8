//! Reset test of the emulated board: the reset counter (`.uninit` RAM) and the parameter log
//! (version + CRC records, here in a RAM region with NOR semantics) survive resets.
//!
//! Boot 0 finds no valid record, saves record A and resets itself (SYSRESETREQ); boot 1 must
//! load A, saves B and resets; boot 2 must load B and count 2 resets. Prints `check ...` lines
//! and exits 0 only if all passed.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use firmware::app::binding::{PERSISTED_COUNT, default_persisted};
use firmware::app::params::{LoadError, ParamLog};
use firmware::app::reset;
use firmware::qemu::{self, ram_flash::RamFlash};
use model_core::wire::ParamId;

fn record(start_um: i32) -> [i32; PERSISTED_COUNT] {
    let mut v = default_persisted();
    v[ParamId::StartUm.index()] = start_um;
    v
}

fn check(name: &str, ok: bool) -> bool {
    hprintln!("check {} {}", name, if ok { "ok" } else { "FAILED" });
    ok
}

#[entry]
fn main() -> ! {
    let boot = reset::count_this_boot();
    let mut log = ParamLog::new(RamFlash::take());
    let loaded = log.load::<PERSISTED_COUNT>();
    hprintln!(
        "boot {}: load -> {:?}",
        boot,
        loaded.as_ref().map(|v| v[ParamId::StartUm.index()])
    );
    let ok = match boot {
        0 => {
            let fresh = matches!(loaded, Err(LoadError::Corrupt | LoadError::Empty));
            check("boot0-no-record", fresh)
                && check("boot0-save", log.save(&record(41_000)).is_ok())
        }
        1 => {
            check("boot1-loads-record-a", loaded == Ok(record(41_000)))
                && check("boot1-save", log.save(&record(42_000)).is_ok())
        }
        _ => {
            let ok = check("boot2-loads-record-b", loaded == Ok(record(42_000)))
                & check("boot2-reset-count", boot == 2);
            qemu::exit(ok)
        }
    };
    if !ok {
        qemu::exit(false);
    }
    cortex_m::peripheral::SCB::sys_reset()
}

firmware::test_image_handlers!();
