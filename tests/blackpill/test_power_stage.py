"""The stop that needs no CPU and the motor supply switch on the emulated board: TIM1's break
input on PA6 (an over-current comparator or a driver's fault output pulls it low) and the
supply enable on PB14 (firmware/src/blackpill/power_stage.rs, docs/wiring.md). References:
RM0383's break function as `timers.py` models it (MOE cleared by the line's level with no
instruction executed, MOE not settable while the line is low), the pins as `pins.py` reads them,
the plant's true speed, and the wire's fault words."""

from checks import check, fresh_flash, mean_speed
from session import Session
from test_power_on import check_pins_driven_low, pwm_pins
from timers import BDTR, MOE

# One period of the 20 kHz PWM.
PWM_PERIOD_NS = 50_000


def halted_break(m):
    """Pulls the break line low and lets one PWM period pass with the CPU stopped (only the
    peripherals and the plant run): what the pins and TIM1 do then."""
    before = list(m.board.pwm_pins.states)
    m.pull_break_line(True)
    at_once = list(m.board.pwm_pins.states)
    m.stall(PWM_PERIOD_NS)
    after = list(m.board.pwm_pins.states)
    moe = bool(m.board.tim1.regs[BDTR] & MOE)
    return before, at_once, after, moe, m.now_ns


def supply_now(s: Session) -> bool:
    return s.call(lambda m: m.board.supply_on)


def test_the_break_input_stops_the_pwm_with_the_cpu_halted():
    """Driving at 1 and 2 rad/s, PA6 pulled low with the CPU halted: both PWM pins are driven
    low within one PWM period (MOE cleared by the line alone); the firmware then latches
    `hardware-stop` and cuts the motor supply; CLEAR with the line still low faults again; once
    the line is released CLEAR holds, the supply closes and the rig drives again."""
    s = Session(fresh_flash("break input"))
    try:
        s.wait_until_s(0.3)
        check(supply_now(s), "the motor supply switch is open after boot")
        check(s.bowl("speed", "1000", "2000").startswith("ok"), "SPEED refused")
        check(s.bowl("start").startswith("ok"), "START refused")
        s.wait_emulated(1.5)
        before, at_once, after, moe, t_break = s.call(halted_break)
        check(before == ["pwm", "pwm"], f"not driving before the break: PWM pins {before}")
        check(at_once == ["low", "low"] and after == ["low", "low"],
              f"PWM pins with the CPU halted: {at_once} at once, {after} one PWM period later;"
              " expected both driven low")
        check(not moe, "TIM1's main output still enabled with the break line low")
        check_pins_driven_low(s, "after the break")
        s.wait_emulated(0.1)
        st = s.status()
        check(st.get("state") == "faulted" and st.get("fault") == "hardware-stop",
              f"after the break: {st}")
        cuts = s.call(lambda m: [(t, on) for t, on in m.supply_changes if t >= t_break])
        check(cuts and not cuts[0][1], f"the motor supply was not cut after the break: {cuts}")
        delay_ms = (cuts[0][0] - t_break) / 1e6
        check(delay_ms <= 2.0, f"the supply was cut {delay_ms:.2f} ms after the break (> 2 ms)")
        print(f"   pins low with the CPU halted; supply cut {delay_ms:.2f} ms after the break")

        # CLEAR while the line is still low: the next tick latches it again.
        s.bowl("clear")
        s.wait_emulated(0.1)
        st = s.status()
        check(st.get("fault") == "hardware-stop", f"CLEAR with the break line low held: {st}")
        check(not supply_now(s), "the supply closed again with the break line still low")

        # Released: CLEAR holds, the supply closes, the rig drives again.
        s.call(lambda m: m.pull_break_line(False))
        check(s.bowl("clear").startswith("ok"), "CLEAR refused after the line was released")
        s.wait_emulated(0.1)
        check(supply_now(s), "the supply stayed open after CLEAR")
        # CLEAR leaves the setpoints at zero: set them again, then start.
        check(s.bowl("speed", "1000", "2000").startswith("ok"), "SPEED refused after CLEAR")
        check(s.bowl("start").startswith("ok"), "START refused after the break was cleared")
        s.wait_emulated(2.5)
        w = mean_speed(s, 1, 0.5)
        check(abs(w - 2.0) / 2.0 < 0.05, f"spin after the restart: {w:.3f} rad/s, set 2.0")
        states, floats = pwm_pins(s)
        check(states == ["pwm", "pwm"] and not floats, f"PWM pins after the restart: {states}")
    finally:
        s.close()


def sensing_session(name: str) -> Session:
    """A board told it measures its motor currents (CUR_SENSE 1), idle long enough for the
    current watch to learn the sensor's offset at zero duty, then driving 1 and 2 rad/s."""
    s = Session(fresh_flash(name))
    s.wait_until_s(0.3)
    check(s.bowl("set", "CUR_SENSE", "1").startswith("ok"), "SET CUR_SENSE 1 refused")
    s.wait_emulated(0.3)
    check(s.bowl("speed", "1000", "2000").startswith("ok"), "SPEED refused")
    check(s.bowl("start").startswith("ok"), "START refused")
    s.wait_emulated(2.0)
    return s


def test_a_shorted_bridge_is_caught_by_the_current_and_the_supply_cut():
    """With the currents measured (PB0/PB1 through the emulated ADC, sampled on TIM1's update):
    the spin bridge shorts (full drive at any duty, zero included). The current is above what
    the duty drives at the measured speed: the rig faults `current-above-model-spin`, and since
    the current still flows after the bridge was told to stop, it opens the supply switch (PB14)
    within a few control ticks; the true speed never passes 1.5 x setpoint + 0.3 rad/s."""
    s = sensing_session("shorted bridge")
    try:
        t0 = s.call(lambda m: (m.plant.short_bridge(1, m.plant.time_ns / 1e9), m.now_ns)[1])
        peak = 0.0
        st = {}
        for _ in range(40):
            s.wait_emulated(0.005)
            peak = max(peak, s.call(lambda m: m.plant.speed_rad_s(1)))
            if not supply_now(s):
                break
        cuts = s.call(lambda m: [(t, on) for t, on in m.supply_changes if t >= t0])
        check(cuts and not cuts[0][1], f"the supply was not cut within 0.2 s: {cuts}")
        cut_ms = (cuts[0][0] - t0) / 1e6
        s.wait_emulated(0.3)
        peak = max(peak, s.call(lambda m: m.plant.speed_rad_s(1)))
        st = s.status()
        check(st.get("fault") in ("current-above-model-spin", "over-current-spin"),
              f"the shorted spin bridge faulted {st.get('fault')}: {st}")
        check(peak < 1.5 * 2.0 + 0.3, f"spin reached {peak:.2f} rad/s (bound 3.3)")
        w = s.call(lambda m: m.plant.speed_rad_s(1))
        check(w < peak, f"spin {w:.2f} rad/s 0.3 s after the cut, peak {peak:.2f}: still driven")
        print(f"   {st.get('fault')}; supply cut {cut_ms:.2f} ms after the short; spin peak "
              f"{peak:.2f} rad/s")
    finally:
        s.close()


def fault_with_currents(name: str, inject) -> dict:
    """The status after `inject(plant, t)` on a sensing board driving 1 and 2 rad/s, and
    whether the supply switch stayed closed."""
    s = sensing_session(name)
    try:
        s.call(lambda m: inject(m.plant, m.plant.time_ns / 1e9))
        st = {}
        for _ in range(16):
            s.wait_emulated(0.25)
            st = s.status()
            if st.get("fault", "none") != "none":
                break
        st["supply_closed"] = supply_now(s)
        return st
    finally:
        s.close()


def test_the_current_tells_a_stall_from_a_dead_sensor():
    """Measured currents: a dead spin sensor on a turning shaft (the back-EMF is still in the
    current) faults `sensor-lost-spin`; a spin shaft blocked at 2 rad/s (its back-EMF gone at
    once: more current than the duty drives at the speed) faults `current-above-model-spin`.
    Without current sense both read `no-pulses-spin` (test_board.py). Neither cuts the supply:
    the bridge stops them."""
    dead = fault_with_currents("dead sensor by current", lambda p, t: p.kill_sensor(1, t))
    check(dead.get("fault") == "sensor-lost-spin", f"a dead spin sensor faulted: {dead}")
    check(dead["supply_closed"], "a dead sensor opened the supply switch")
    held = fault_with_currents("stall by current", lambda p, t: p.block_shaft(1, t))
    check(held.get("fault") == "current-above-model-spin", f"a blocked spin shaft faulted: {held}")
    check(held["supply_closed"], "a blocked shaft opened the supply switch")
