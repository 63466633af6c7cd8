"""First power-on, as a person at the rig sees it: the reset cause the first log line gives
after a probe's reset, the clock fallback when the crystal does not start, the motor PWM pins
PA8/PA9 as the emulated board drives them (`pins.py`: GPIOA's mode and TIM1's output control, OSSI included), and the status
LED on PC13 (`firmware/src/app/led.rs`: one pattern per state). References: RM0383's TIM1
output control table, through the harness's record of every moment a pin that TIM1 drove was
let go (`Machine.pwm_pin_floats`), and the LED's recorded changes (`Machine.led_changes`)."""

import os
import subprocess

from checks import check, fill_parameter_region, fresh_flash, wedge_cpu
from flash import BACKED_BASE, SECTOR_BASES
from iwdg import LSI_HZ, LSI_MAX_HZ, LSI_MIN_HZ
from session import BOWL, ELF, LOGS, Session


def symbol_address(elf: str, mangled_part: str) -> int:
    """The address of a static in the image, by a part of its mangled Rust name."""
    from elftools.elf.elffile import ELFFile
    with open(elf, "rb") as f:
        for sym in ELFFile(f).get_section_by_name(".symtab").iter_symbols():
            if mangled_part in sym.name:
                return sym["st_value"]
    raise RuntimeError(f"{elf}: no symbol like {mangled_part}")


def led_flashes(s: Session, t0_s: float, t1_s: float):
    """The LED's flashes lying wholly inside [t0_s, t1_s): their lengths in ms."""
    changes = s.call(lambda m: list(m.led_changes))
    flashes, on_ns = [], None
    for t, lit in changes:
        if lit:
            on_ns = t
        elif on_ns is not None:
            if t0_s * 1e9 <= on_ns and t <= t1_s * 1e9:
                flashes.append(round((t - on_ns) / 1e6))
            on_ns = None
    return flashes


def pwm_pins(s: Session):
    """The two pins' states now, and every let-go so far (time ns, axis, state)."""
    return s.call(lambda m: (list(m.board.pwm_pins.states), list(m.pwm_pin_floats)))


def check_pins_driven_low(s: Session, when: str):
    states, floats = pwm_pins(s)
    check(not floats, f"{when}: a PWM pin was left floating (time ns, axis, state): {floats}")
    check(states == ["low", "low"], f"{when}: PWM pins {states}, expected both driven low")


def test_a_fault_leaves_the_pwm_pins_driven_low():
    """Idle after boot, both pins are driven low; driving, both switch; a fault (dead spin
    sensor) clears MOE and both pins stay driven low by TIM1 (OSSI = 1), never released to
    float with only the bridge's pull-downs holding the motors off. The LED shows idle,
    driving and fault on the way (checked last, so a pin failure is reported first)."""
    s = Session(fresh_flash("pins"))
    try:
        s.wait_until_s(2.3)
        check_pins_driven_low(s, "idle after boot")
        idle = led_flashes(s, 0.2, 2.3)
        check(s.bowl("speed", "1000", "2000").startswith("ok"), "SPEED refused")
        check(s.bowl("start").startswith("ok"), "START refused")
        t_start = s.now_s()
        s.wait_emulated(2.2)
        states, _ = pwm_pins(s)
        check(states == ["pwm", "pwm"], f"PWM pins while driving: {states}")
        driving = led_flashes(s, t_start + 0.05, s.now_s())
        t_fault = s.call(lambda m: (m.plant.kill_sensor(1, m.plant.time_ns / 1e9), m.now_ns)[1])
        deadline = t_fault / 1e9 + 4.0
        st = s.status()
        while st.get("fault", "none") == "none" and s.now_s() < deadline:
            s.wait_emulated(0.25)
            st = s.status()
        check(st.get("fault") == "no-pulses-spin", f"no sensor fault after 4 s: {st}")
        check_pins_driven_low(s, "after the fault")
        t_faulted = s.now_s()
        s.wait_emulated(1.1)
        fault = led_flashes(s, t_faulted, s.now_s())
        # Idle: one 100 ms flash a second (the 20 ms LED step makes lengths multiples of 20).
        check(len(idle) == 2 and all(90 <= f <= 110 for f in idle), f"idle LED flashes (ms): {idle}")
        # The first flash may have begun in the idle pattern's frame: the full ones after it.
        check(driving and all(890 <= f <= 910 for f in driving[1:])
              and 890 <= driving[-1] <= 910,
              f"LED while driving, expected 900 ms on each second: {driving}")
        check(len(fault) >= 4 and all(90 <= f <= 110 for f in fault),
              f"LED after a fault, expected 100 ms flashes five a second: {fault}")
    finally:
        s.close()


def test_a_dead_crystal_falls_back_to_the_internal_clock():
    """A board whose crystal never starts (HSERDY never rises) boots on the HSI instead of
    hanging in the HSE wait: SYSCLK 100 MHz from 16 MHz / 8 * 100 / 2, the link at 115 200
    baud answers, the log says so, and every fourth second of the LED's idle pattern is three
    60 ms flashes."""
    s = Session(fresh_flash("no crystal"), hse_hz=0)
    try:
        s.wait_until_s(4.6)
        sysclk, baud = s.call(lambda m: (m.board.clocks.sysclk_hz(), m.board.usart2.baud()))
        check(abs(sysclk - 100e6) < 1e3, f"SYSCLK {sysclk / 1e6:.3f} MHz on the HSI fallback")
        check(abs(baud / 115_200 - 1) < 0.01, f"USART2 at {baud:.0f} baud")
        st = s.status()
        # flags: 4 the clock fallback, 1 a new board's empty parameter flash.
        check(st.get("state") == "idle" and st.get("flags") == "5", f"status on the HSI: {st}")
        with open(os.path.join(LOGS, "blackpill-defmt.log"), errors="replace") as f:
            log = f.read()
        check("crystal did not start" in log, "the log does not say the crystal failed")
        flashes = led_flashes(s, 0.3, 4.6)
        warning = [f for f in flashes if f < 80]
        idle = [f for f in flashes if f >= 80]
        check(len(warning) == 3 and all(50 <= f <= 70 for f in warning) and len(idle) >= 2,
              f"LED flashes (ms) over 4 s on the fallback: {flashes}")
    finally:
        s.close()


def test_a_probe_reset_is_not_taken_for_a_panic():
    """A debug probe resets through SYSRESETREQ, as the panic handler does, so RCC_CSR shows
    SFTRSTF (and PINRSTF) for both. Without the firmware's own mark in RAM the boot says
    `reset cause Debugger` and the wire says `pin` (the protocol's "NRST pin: reset button,
    debugger"); docs/bring-up.md says what the first log line after `cargo flash-rig` is."""
    s = Session(fresh_flash("probe reset"))
    try:
        s.wait_until_s(0.3)
        s.call(lambda m: m.reset("software"))
        s.wait_emulated(0.3)
        st = s.status()
        check(st.get("reset_cause") == "pin" and st.get("reset_count") == "1",
              f"status after a probe reset: {st}")
        with open(os.path.join(LOGS, "blackpill-defmt.log"), errors="replace") as f:
            log = f.read()
        check("boot: reset cause Debugger, resets since power-on 1" in log,
              "the boot line after a probe reset does not say Debugger")
        # The firmware's own reset (panic, hard fault, failed startup) leaves its mark first.
        mark = symbol_address(ELF, "13SOFTWARE_MARK")
        words = (0x5357_5253).to_bytes(4, "little") + (~0x5357_5253 & 0xFFFF_FFFF).to_bytes(4, "little")
        s.call(lambda m: (m.board.ql.mem.write(mark, words), m.reset("software")))
        s.wait_emulated(0.3)
        st = s.status()
        check(st.get("reset_cause") == "software", f"status after the firmware's own reset: {st}")
    finally:
        s.close()


# The firmware's IWDG timeout (firmware/src/bin/firmware.rs, WATCHDOG_TIMEOUT_US), computed
# for the typical LSI.
WATCHDOG_TIMEOUT_MS = 250


def test_watchdog_margins_at_the_lsi_extremes():
    """The firmware computes its watchdog timeouts for the typical 32 kHz LSI; the datasheet
    allows 17 to 47 kHz. At 47 kHz (every timeout 32/47 as long: 170 ms, and 22.3 s while
    stretched) a save that must erase a full region, the erase at its datasheet maximum (4 s at
    x8), completes with no watchdog reset, and the feeding keeps a margin. At 17 kHz (timeouts
    32/17 as long) a wedged CPU is still reset, within 250 ms x 32/17 = 471 ms."""
    base = fresh_flash("lsi fast")
    s = Session(base, realtime=False)
    try:
        s.wait_until_s(0.3)
        check(s.bowl("set", "TEETH2", "24").startswith("ok"), "SET refused")
        s.wait_emulated(1.5)
    finally:
        s.close()
    fill_parameter_region(base)
    s = Session(base, realtime=False, lsi_hz=LSI_MAX_HZ, flash_timing="max")
    try:
        s.wait_until_s(0.3)
        check(s.bowl("set", "TEETH2", "36").startswith("ok"), "SET refused")
        # A persistence tick (0.5 s), the 4 s erase, the program steps, some running after.
        s.wait_emulated(6.0)
        steps, resets, margin = s.call(lambda m: (list(m.store.log), list(m.resets),
                                                  m.board.iwdg.min_margin_ns))
        check(any(x.startswith("erase") for x in steps), f"the save did not erase: {steps[:3]}")
        check(not resets, f"resets at LSI {LSI_MAX_HZ} Hz with a 4 s erase: {resets}")
        check(s.params().get("TEETH2") == 36, "the save after the erase did not stick")
        timeout_ms = WATCHDOG_TIMEOUT_MS * LSI_HZ / LSI_MAX_HZ
        check(margin is not None and margin > 0, f"watchdog margin {margin}")
        print(f"   LSI {LSI_MAX_HZ / 1e3:.0f} kHz: timeout {timeout_ms:.0f} ms, least margin at a "
              f"feed {margin / 1e6:.0f} ms, a 4 s erase survived")
    finally:
        s.close()
    s = Session(fresh_flash("lsi slow"), lsi_hz=LSI_MIN_HZ)
    try:
        s.wait_until_s(0.3)
        t_wedge = s.call(wedge_cpu)
        s.wait_emulated(0.8)
        resets = s.call(lambda m: list(m.resets))
        check(resets and resets[0][1] == "watchdog", f"resets after the wedge: {resets}")
        after_ms = (resets[0][0] - t_wedge) / 1e6
        limit_ms = WATCHDOG_TIMEOUT_MS * LSI_HZ / LSI_MIN_HZ
        check(after_ms <= limit_ms + 10, f"reset {after_ms:.0f} ms after the wedge at "
              f"{LSI_MIN_HZ} Hz (limit {limit_ms:.0f} ms)")
        print(f"   LSI {LSI_MIN_HZ / 1e3:.0f} kHz: wedged CPU reset after {after_ms:.0f} ms "
              f"(timeout {limit_ms:.0f} ms)")
    finally:
        s.close()


def test_parameter_flash_trouble_is_reported_on_the_wire():
    """Defaults instead of a stored record are no longer a log line only: STATUS carries
    `flags` bit 1 (`model_core::wire::status_flags::PARAMS_DEFAULTS`), which `bowl send status`
    prints with its words. A new board (empty flash) says so; after a save and a reset it does
    not; a record damaged in flash (as by a bad power cut) says so again."""
    s = Session(fresh_flash("flash trouble"))
    try:
        s.wait_until_s(0.3)
        out = s.bowl("status")
        check("flags=1" in out and "booted on default parameters" in out,
              f"status of a new board: {out}")
        # The monitor asks STATUS itself when it opens the port and says the board's condition.
        mon = subprocess.run([BOWL, "monitor", s.link.path, "--plain", "--seconds", "8"],
                             capture_output=True, text=True, timeout=60)
        check("the rig reports: booted on default parameters" in mon.stdout,
              f"the monitor on a new board: {mon.stdout[-2000:]} {mon.stderr[-500:]}")
        check(s.bowl("set", "TEETH2", "24").startswith("ok"), "SET refused")
        s.wait_emulated(1.2)
        s.call(lambda m: m.reset("pin"))
        s.wait_emulated(0.3)
        st = s.status()
        check(st.get("flags") == "0" and s.params()["TEETH2"] == 24,
              f"status after a save and a reset: {st}")
        first = SECTOR_BASES[6] - BACKED_BASE

        def damage(m):
            m.store.data[first + 20] ^= 0xFF  # a value byte of the only record: its CRC fails
            m.reset("pin")
        s.call(damage)
        s.wait_emulated(0.3)
        st = s.status()
        check(st.get("flags") == "1" and s.params()["TEETH2"] == 12,
              f"status after the record was damaged: {st}")
    finally:
        s.close()
