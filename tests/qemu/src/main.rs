//! The shared test cases and benchmarks on an emulated Cortex-M4F.
//!
//! Runs under QEMU `netduinoplus2` (STM32F405: Cortex-M4 with FPU, the F411's memory map) with
//! semihosting for output and exit status, and `-icount shift=7` so that virtual time is a fixed
//! multiple of executed instructions. SysTick, clocked from the core clock, then counts
//! instructions exactly: we calibrate ticks per instruction on a block of 400 `nop`s and
//! subtract the cost of an empty call, so each benchmark reports the instructions executed by the
//! function under test alone (including its call and return).
//!
//! Output, one line each: `case NAME ok|FAILED ...`, `bench NAME inputs=.. min=.. mean=.. max=..`,
//! and a closing `qemu-cases: N passed, N failed`. The exit status is 0 only if every case passed
//! and no benchmark exceeded its budget; a panic or a hard fault exits with failure at once.
#![no_std]
#![no_main]

use core::hint::black_box;
use cortex_m::peripheral::{SYST, syst::SystClkSource};
use cortex_m_rt::{ExceptionFrame, entry, exception};
use cortex_m_semihosting::{debug, hprintln};

const SYSTICK_MASK: u32 = 0x00FF_FFFF;

/// Ticks of SysTick (a down-counter) spent in `run(i)`.
#[inline(never)]
fn ticks_of(run: fn(usize) -> f32, i: usize) -> (u32, f32) {
    let run = black_box(run);
    let t0 = SYST::get_current();
    let v = run(black_box(i));
    let t1 = SYST::get_current();
    (t0.wrapping_sub(t1) & SYSTICK_MASK, v)
}

fn empty(_: usize) -> f32 {
    0.0
}

fn calibration_nops(_: usize) -> f32 {
    // SAFETY: only NOPs. 400 of them (800 bytes) keep any literal pool of the function in range.
    unsafe { core::arch::asm!(".rept 400", "nop", ".endr", options(nomem, nostack)) };
    0.0
}

/// Converts measured ticks to instructions, given the calibration.
struct Calibration {
    empty_ticks: u32,
    ticks_per_400: u32,
}

impl Calibration {
    fn measure() -> Self {
        let empty_ticks = (0..8).map(|_| ticks_of(empty, 0).0).min().unwrap_or(0);
        let nops = (0..8)
            .map(|_| ticks_of(calibration_nops, 0).0)
            .min()
            .unwrap_or(0);
        Self {
            empty_ticks,
            ticks_per_400: nops.saturating_sub(empty_ticks).max(1),
        }
    }

    fn instructions(&self, ticks: u32) -> u32 {
        let net = ticks.saturating_sub(self.empty_ticks) as u64;
        ((net * 400 + self.ticks_per_400 as u64 / 2) / self.ticks_per_400 as u64) as u32
    }
}

#[entry]
fn main() -> ! {
    let mut core = cortex_m::Peripherals::take().unwrap();
    core.SYST.set_clock_source(SystClkSource::Core);
    core.SYST.set_reload(SYSTICK_MASK);
    core.SYST.clear_current();
    core.SYST.enable_counter();

    let mut passed = 0u32;
    let mut failed = 0u32;
    for case in bowl_test_cases::all_cases() {
        match (case.run)() {
            Ok(()) => {
                passed += 1;
                hprintln!("case {} ok", case.name);
            }
            Err(f) => {
                failed += 1;
                hprintln!(
                    "case {} FAILED: {}: got {:e}, want {:e}, tolerance {:e}",
                    case.name,
                    f.what,
                    f.got,
                    f.want,
                    f.tolerance
                );
            }
        }
    }

    let cal = Calibration::measure();
    hprintln!(
        "calibration: empty call {} ticks, 400 instructions {} ticks",
        cal.empty_ticks,
        cal.ticks_per_400
    );
    for bench in bowl_test_cases::all_benches() {
        let (mut min, mut max, mut sum) = (u32::MAX, 0u32, 0u64);
        for i in 0..bench.inputs {
            let (ticks, _) = ticks_of(bench.run, i);
            let n = cal.instructions(ticks);
            min = min.min(n);
            max = max.max(n);
            sum += n as u64;
        }
        let mean = sum / bench.inputs.max(1) as u64;
        match bench.budget_instructions {
            Some(budget) => {
                let within = max <= budget;
                if within {
                    passed += 1;
                } else {
                    failed += 1;
                }
                hprintln!(
                    "bench {} inputs={} min={} mean={} max={} budget={} {}",
                    bench.name,
                    bench.inputs,
                    min,
                    mean,
                    max,
                    budget,
                    if within { "ok" } else { "OVER BUDGET" }
                );
            }
            None => hprintln!(
                "bench {} inputs={} min={} mean={} max={}",
                bench.name,
                bench.inputs,
                min,
                mean,
                max
            ),
        }
    }

    hprintln!("qemu-cases: {} passed, {} failed", passed, failed);
    debug::exit(if failed == 0 {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("PANIC: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    hprintln!("HARD FAULT at pc {:#010x}", frame.pc());
    debug::exit(debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}
