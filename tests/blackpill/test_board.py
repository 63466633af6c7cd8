"""End-to-end tests of the exact Black Pill image on the emulated STM32F411, over the pty with
`bowl send`, against the project's plant. Run by tests/run:

    target/venv-blackpill/bin/python tests/blackpill/test_board.py [NAME...]

Ends with `blackpill: N passed, M failed` and exits non-zero on a failure. Each test states
its reference: the plant's true speed, the timer's registers, the flash file, the wire."""

import os
import re
import shutil
import sys
import time
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from flash import SECTOR_BASES, BACKED_BASE, SECTOR_SIZE  # noqa: E402
# Bytes per parameter slot (firmware/src/app/params.rs: 4 header words, 48 values, the CRC).
SLOT_BYTES = 16 + 4 * 48 + 4
from session import LOGS, ROOT, Session  # noqa: E402
from timers import BDTR, MOE  # noqa: E402
from checks import WORK, check, fill_parameter_region, fresh_flash, mean_speed, wedge_cpu  # noqa: E402
from test_gates import *  # noqa: E402,F401,F403  (the gate tests join this run)
from test_power_on import *  # noqa: E402,F401,F403  (the first-power-on tests join this run)
from test_power_stage import *  # noqa: E402,F401,F403  (the break input and supply switch tests)
from test_console import *  # noqa: E402,F401,F403  (a person typing at picocom)

# The control task's tick counter in the image (`HEARTBEAT` static).
HEARTBEAT = None


def test_boot_says_hello_and_reports_power_on():
    s = Session(fresh_flash("boot"))
    try:
        s.wait_until_s(0.3)
        first = s.call(lambda m: bytes(m.tx_bytes[:4]))
        check(first == b"$H1,", f"first bytes on the link {first!r}, expected a Hello frame '$H1,'")
        st = s.status()
        check(st.get("state") == "idle" and st.get("reset_cause") == "power-on"
              and st.get("reset_count") == "0", f"status after power-on: {st}")
        with open(os.path.join(LOGS, "blackpill-defmt.log"), errors="replace") as f:
            log = f.read()
        check("boot: reset cause PowerOn" in log, "defmt log lacks the boot line")
    finally:
        s.close()


def documented_parameters() -> list:
    """The parameter names of docs/protocol.md's table, in its order."""
    with open(os.path.join(ROOT, "docs", "protocol.md")) as f:
        return re.findall(r"^\| \d+ \| `([A-Z0-9_]+)` \|", f.read(), flags=re.M)


def test_every_command_and_its_refusals():
    s = Session(fresh_flash("commands"))
    try:
        s.wait_until_s(0.3)
        p = s.params()
        # Every parameter docs/protocol.md's table lists (model-core/tests/wire_doc.rs holds
        # that table to the code), in its order.
        check(list(p) == documented_parameters() and p["TEETH1"] == 12
              and p["SPEED_MAX1_MRAD_S"] == 4000 and p["LINK_TIMEOUT_MS"] == 3000
              and p["CUR_SENSE"] == 0,
              f"PARAMS: {p}")
        check(s.bowl("set", "TEETH1", "24").startswith("ok"), "SET TEETH1 24 refused")
        check(s.params()["TEETH1"] == 24, "PARAMS does not show TEETH1 24 after SET")
        check("spin: identified=" in s.bowl("models"), "MODELS answer has no spin axis")
        check(s.bowl("ping").startswith("ok"), "PING not acknowledged")
        out = s.bowl("speed", "5000", "0")
        check("RANGE" in out, f"SPEED above SPEED_MAX1 (4000): {out}")
        out = s.bowl("set", "START_UM", "999999")
        check("RANGE" in out, f"START_UM beyond RIM_UM: {out}")
        out = s.bowl("inject", "stall1")
        check("UNSUPPORTED" in out, f"INJECT on real hardware: {out}")
        check(s.bowl("speed", "1000", "1000").startswith("ok"), "SPEED 1000 1000 refused")
        check(s.bowl("start").startswith("ok"), "START refused")
        s.wait_emulated(0.3)
        st = s.status()
        check(st.get("state") in ("changing-speed", "running"), f"not driving after START: {st}")
        check(s.bowl("stop").startswith("ok"), "STOP refused")
        out = s.bowl("clear")
        check(out.startswith(("ok", "rejected")), f"CLEAR: {out}")
    finally:
        s.close()


def test_closed_loop_step_reaches_the_setpoints():
    s = Session(fresh_flash("step"))
    try:
        s.wait_until_s(0.3)
        check(s.bowl("speed", "1000", "2000").startswith("ok"), "SPEED refused")
        check(s.bowl("start").startswith("ok"), "START refused")
        t0 = s.now_s()
        s.wait_until_s(t0 + 2.5)
        w = [mean_speed(s, axis, 0.5) for axis in (0, 1)]
        # The plant's true speed, averaged over half a second: within 3 % of the setpoint.
        for axis, target in ((0, 1.0), (1, 2.0)):
            err = abs(w[axis] - target) / target
            check(err < 0.03, f"axis {axis}: true speed {w[axis]:.3f} rad/s, setpoint {target}")
        # Down to a lower speed and to a stop: braking may reverse the drive.
        check(s.bowl("speed", "200", "300").startswith("ok"), "SPEED down refused")
        s.wait_emulated(1.0)
        check(s.bowl("stop").startswith("ok"), "STOP refused")
        s.wait_emulated(1.0)
        bad, turns = s.call(lambda m: (list(m.dir_violations), m.dir_changes))
        print(f"   direction changes: {turns}")
        check(not bad, f"DIR turned while the PWM still drove (time ns, axis, duty): {bad[:5]}")
    finally:
        s.close()


def test_a_bad_rig_file_is_refused_in_words():
    """The plant library refuses a rig file out of range with the file, line, key and range."""
    from plant import RigFileError, RigPlant
    from session import PLANT_LIB
    bad = os.path.join(WORK, "bad-rig.toml")
    with open(bad, "w") as f:
        f.write("[spin]\ninertia_kg_m2 = -1.0\n")
    try:
        RigPlant(PLANT_LIB, rig_file=bad)
        raise AssertionError("a negative inertia was accepted")
    except RigFileError as e:
        text = str(e)
        check("bad-rig.toml" in text and "line 2" in text and "inertia_kg_m2" in text
              and "0.000001 to 100" in text, text)
        print(f"   {text}")


def fault_stops_the_bridge(name: str, inject, expected: str):
    s = Session(fresh_flash(name))
    try:
        s.wait_until_s(0.3)
        s.bowl("speed", "1000", "2000")
        s.bowl("start")
        s.wait_emulated(1.5)
        t_fault = s.call(lambda m: (inject(m.plant, m.plant.time_ns / 1e9), m.now_ns / 1e9)[1])
        deadline = t_fault + 4.0
        st = {}
        while s.now_s() < deadline:
            s.wait_emulated(0.25)
            st = s.status()
            if st.get("fault", "none") != "none":
                break
        check(st.get("fault", "none") != "none", f"no fault within 4 s of the {name}: {st}")
        check(st.get("fault") == expected, f"the {name} faulted {st.get('fault')}, not {expected}")
        s.wait_emulated(0.01)
        duty, moe = s.call(lambda m: ((m.board.tim1.pwm_fraction(0), m.board.tim1.pwm_fraction(1)),
                                      bool(m.board.tim1.regs[BDTR] & MOE)))
        check(duty == (0.0, 0.0), f"PWM still active after the fault: {duty}")
        check(not moe, "TIM1 main output (MOE) still enabled after the fault")
        check_pins_driven_low(s, f"after the {name}")
        print(f"   fault {st.get('fault')} reported within {s.now_s() - t_fault:.2f} s")
    finally:
        s.close()


def test_link_loss_stops_the_motors_by_default():
    """A driving board that hears nothing (no command, no PING) for LINK_TIMEOUT_MS (3 s by
    default) faults HostSilent and turns the bridge off."""
    s = Session(fresh_flash("link loss"))
    try:
        s.wait_until_s(0.3)
        check(s.bowl("speed", "1000", "2000").startswith("ok"), "SPEED refused")
        check(s.bowl("start").startswith("ok"), "START refused")
        s.heartbeat = False
        t_silent = s.now_s()
        s.wait_emulated(2.5)
        duty = s.call(lambda m: (m.board.tim1.pwm_fraction(0), m.board.tim1.pwm_fraction(1)))
        check(duty != (0.0, 0.0), f"stopped before the 3 s link-loss timeout: {duty}")
        s.wait_emulated(1.0)
        duty, moe = s.call(lambda m: ((m.board.tim1.pwm_fraction(0), m.board.tim1.pwm_fraction(1)),
                                      bool(m.board.tim1.regs[BDTR] & MOE)))
        check(duty == (0.0, 0.0), f"PWM still active {s.now_s() - t_silent:.2f} s into silence")
        check(not moe, "TIM1 main output (MOE) still enabled after the link loss")
        check_pins_driven_low(s, "after the link loss")
        st = s.status()
        check(st.get("state") == "faulted" and st.get("fault") == "link-lost", f"{st}")
    finally:
        s.close()


def test_blocked_shaft_faults_and_the_bridge_goes_off():
    fault_stops_the_bridge("blocked spin shaft", lambda plant, t: plant.block_shaft(1, t),
                           "no-pulses-spin")


def test_dead_sensor_faults_and_the_bridge_goes_off():
    fault_stops_the_bridge("dead spin sensor", lambda plant, t: plant.kill_sensor(1, t),
                           "no-pulses-spin")


def test_stuck_bridge_faults_overspeed_and_the_bridge_goes_off():
    fault_stops_the_bridge("stuck spin bridge", lambda plant, t: plant.stick_bridge(1, t),
                           "overspeed-spin")


def test_no_flash_operation_while_a_motor_is_driven():
    s = Session(fresh_flash("deferred"))
    try:
        s.wait_until_s(0.3)
        s.bowl("speed", "1000", "1000")
        s.bowl("start")
        s.wait_emulated(0.5)
        # A parameter change while driving is refused (so no save can stall the loop) ...
        out = s.bowl("set", "TEETH2", "24")
        check(out.startswith("rejected") and "STATE" in out, f"SET while running: {out}")
        s.wait_emulated(1.0)
        steps = s.call(lambda m: list(m.store.log))
        check(not steps, f"flash written while the motors ran: {steps[:3]}")
        # ... and accepted and saved once the rig is idle again.
        s.bowl("stop")
        deadline = s.now_s() + 8.0
        while s.status().get("state") != "idle" and s.now_s() < deadline:
            s.wait_emulated(0.25)
        out = s.bowl("set", "TEETH2", "24")
        check(out.startswith("ok"), f"SET after STOP: {out}; status {s.status()}")
        s.wait_emulated(1.0)
        steps = s.call(lambda m: list(m.store.log))
        check(steps, "no save after the SET in Idle")
    finally:
        s.close()


def after_a_reset(flash: str, param: str, value: str):
    """SET `param` on a fresh board, let the persistence tick save it, pin reset: the status
    and parameters the board then reports."""
    s = Session(fresh_flash(flash))
    try:
        s.wait_until_s(0.3)
        check(s.bowl("set", param, value).startswith("ok"), f"SET {param} {value} refused")
        s.wait_emulated(1.2)  # the save runs at the next persistence tick
        s.call(lambda m: m.reset("pin"))
        s.wait_emulated(0.3)
        return s.status(), s.params()
    finally:
        s.close()


def test_parameters_survive_a_reset():
    st, p = after_a_reset("persist", "TEETH2", "24")
    check(st.get("reset_cause") == "pin" and st.get("reset_count") == "1", f"status: {st}")
    check(p["TEETH2"] == 24, "TEETH2 not restored from flash after the reset")


def test_telemetry_rate_alone_survives_a_reset():
    # The protocol device keeps the rate, the record keeps it too: a SET of it alone was
    # acknowledged, shown by STATUS, and lost at the next reset.
    st, p = after_a_reset("telem-rate", "TELEM_HZ", "10")
    check(st.get("reset_count") == "1" and st.get("telemetry_hz") == "10" and p["TELEM_HZ"] == 10,
          f"TELEM_HZ 10 not restored from flash after the reset: {st}")


MODEL_FIELDS = ("back_emf_uv_per_rad_s", "friction_ppm", "time_constant_us")


def models(s: Session) -> list:
    """MODELS per axis: (identified, back-EMF, friction, time constant) from `bowl send`."""
    out = s.bowl("models")
    axes = re.findall(r"identified=([01]) back_emf_uv_per_rad_s=(\d+) "
                      r"friction_ppm=(\d+) time_constant_us=(\d+)", out)
    check(len(axes) == 2, f"MODELS answer: {out}")
    return [(a[0] == "1", int(a[1]), int(a[2]), int(a[3])) for a in axes]


def wait_for_state(s: Session, state: str, seconds: float) -> dict:
    deadline = s.now_s() + seconds
    st = s.status()
    while st.get("state") != state and s.now_s() < deadline:
        s.wait_emulated(0.5)
        st = s.status()
    return st


def test_identified_models_survive_a_reset():
    """On the heavy bowl (docs/rigs/heavy-bowl.toml: 2.25x the precession and 3x the spin
    inertia of the nominal rig, more friction), COMMISSION identifies both motors; the models
    and their identified flags are saved once the rig is idle and come back after a pin reset
    (reference: the MODELS answer before the reset), and the commissioned loop then holds its
    setpoints, which the default gains do not (precession 9 % over after 4 s)."""
    heavy = os.path.join(ROOT, "docs/rigs/heavy-bowl.toml")
    s = Session(fresh_flash("models"), rig_file=heavy)
    try:
        s.wait_until_s(0.3)
        before = models(s)
        check(not before[0][0] and not before[1][0], f"identified before COMMISSION: {before}")
        check(s.bowl("commission").startswith("ok"), "COMMISSION refused")
        s.wait_emulated(1.0)
        st = wait_for_state(s, "idle", 60.0)
        check(st.get("state") == "idle" and st.get("fault") == "none",
              f"commissioning did not end idle: {st}")
        found = models(s)
        check(found[0][0] and found[1][0], f"not identified after COMMISSION: {found}")
        # The heavier shafts answer slower than the nominal models the board starts with.
        for axis, ratio in ((0, 1.5), (1, 2.0)):
            check(found[axis][3] > ratio * before[axis][3],
                  f"axis {axis}: time constant {found[axis][3]} us, nominal {before[axis][3]} us")
        # Saved at the next persistence tick (rate limit 2 s; an erase first takes 2 s at the
        # x8 parallelism embassy leaves after reset: flash.py).
        s.wait_emulated(4.5)
        s.call(lambda m: m.reset("pin"))
        s.wait_emulated(0.3)
        st = s.status()
        check(st.get("reset_cause") == "pin", f"status after the reset: {st}")
        after = models(s)
        check(after == found, f"models after the reset {after}, before {found}")
        check(s.bowl("speed", "1000", "2000").startswith("ok"), "SPEED refused")
        check(s.bowl("start").startswith("ok"), "START refused")
        s.wait_emulated(4.0)
        w = [mean_speed(s, axis, 0.5) for axis in (0, 1)]
        for axis, target in ((0, 1.0), (1, 2.0)):
            err = abs(w[axis] - target) / target
            check(err < 0.03, f"axis {axis}: true speed {w[axis]:.3f} rad/s, setpoint {target}")
        print(f"   time constants {before[0][3]}/{before[1][3]} us nominal, "
              f"{found[0][3]}/{found[1][3]} us identified; speeds {w[0]:.3f}, {w[1]:.3f} rad/s")
    finally:
        s.close()


def saves_in(log: list) -> int:
    """Saves among flash steps: the distinct parameter slots programmed."""
    slots = set()
    for step in log:
        if step.startswith("program "):
            offset = int(step.split()[1], 16)
            for sector, base in SECTOR_BASES.items():
                start = base - BACKED_BASE
                if start <= offset < start + SECTOR_SIZE:
                    slots.add((sector, (offset - start) // SLOT_BYTES))
    return len(slots)


def test_saves_are_rate_limited():
    """Ten parameter changes, one every 0.3 s: without a limit the persistence loop (every
    0.5 s) would save about six times; with the 2 s limit at most three saves happen, and the
    last value is the one stored (it survives a reset)."""
    s = Session(fresh_flash("rate limit"))
    try:
        s.wait_until_s(0.3)
        t0 = s.now_s()
        for i, teeth in enumerate(range(13, 23)):
            s.wait_until_s(t0 + 0.3 * i)
            check(s.bowl("set", "TEETH2", str(teeth)).startswith("ok"), f"SET TEETH2 {teeth}")
        span = s.now_s() - t0
        s.wait_emulated(3.0)
        n = s.call(lambda m: saves_in(m.store.log))
        print(f"   {n} saves for 10 changes over {span:.1f} s")
        check(1 <= n <= 3 and n <= span / 2.0 + 2, f"{n} saves in {span:.1f} s of changes")
        s.call(lambda m: m.reset("pin"))
        s.wait_emulated(0.3)
        check(s.params()["TEETH2"] == 22, "the last change was not the one stored")
    finally:
        s.close()


def test_a_clock_tree_that_does_not_fit_the_board_is_caught():
    """The clocks come from the RCC registers the image writes and from the board's crystal,
    never hard-wired: on a board with an 8 MHz crystal the image's PLL setting (made for the
    Black Pill's 25 MHz) gives 32 MHz instead of 100 MHz, USART2 runs at 36,864 baud instead of
    115,200, and the PC's adapter reads garbage: no answer, as on a real misclocked board."""
    s = Session(fresh_flash("wrong crystal"), hse_hz=8_000_000)
    try:
        s.wait_until_s(0.3)
        sysclk, baud = s.call(lambda m: (m.board.clocks.sysclk_hz(), m.board.usart2.baud()))
        check(abs(sysclk - 32e6) < 1e3, f"SYSCLK {sysclk / 1e6:.3f} MHz, expected 32")
        check(abs(baud / 115_200 - 0.32) < 0.01, f"USART2 at {baud:.0f} baud")
        out = s.bowl("status")
        check(out.startswith("timeout"), f"a misclocked board answered: {out}")
        errors = s.call(lambda m: m.board.usart2.baud_errors)
        check(errors > 0, "no byte was garbled")
    finally:
        s.close()
    s = Session(fresh_flash("right crystal"))
    try:
        s.wait_until_s(0.3)
        sysclk, baud = s.call(lambda m: (m.board.clocks.sysclk_hz(), m.board.usart2.baud()))
        check(abs(sysclk - 100e6) < 1e3, f"SYSCLK {sysclk / 1e6:.3f} MHz on the 25 MHz board")
        check(abs(baud / 115_200 - 1) < 0.01, f"USART2 at {baud:.0f} baud")
        check(s.bowl("status").startswith("status"), "the right board does not answer")
    finally:
        s.close()


def test_wedged_cpu_is_reset_by_the_watchdog():
    s = Session(fresh_flash("watchdog"))
    try:
        s.wait_until_s(0.3)
        t_wedge = s.call(wedge_cpu)
        s.wait_emulated(0.6)
        resets = s.call(lambda m: list(m.resets))
        check(resets and resets[0][1] == "watchdog", f"resets after the wedge: {resets}")
        after_ms = (resets[0][0] - t_wedge) / 1e6
        # IWDG timeout 250 ms (firmware); LSI 32 kHz as modelled.
        check(after_ms <= 260, f"watchdog reset {after_ms:.0f} ms after the wedge (limit 260)")
        st = s.status()
        check(st.get("reset_cause") == "watchdog" and st.get("reset_count") == "1",
              f"status after the watchdog reset: {st}")
    finally:
        s.close()


def test_late_control_ticks_starve_the_watchdog():
    s = Session(fresh_flash("deadline"))
    try:
        s.wait_until_s(0.3)
        ticks = s.call(lambda m: bytes(m.board.ql.mem.read(HEARTBEAT, 8)))
        # 3 ms held every 10 ms: the control task still ticks (its count advances) but ticks
        # end more than one period late.
        t0 = s.call(lambda m: (m.hold_cpu_periodically(0.010, 0.003), m.now_ns)[1])
        s.wait_emulated(0.15)
        later = s.call(lambda m: bytes(m.board.ql.mem.read(HEARTBEAT, 8)))
        check(later != ticks, "the control task stopped ticking: this test wants late ticks")
        s.wait_emulated(0.5)
        resets = s.call(lambda m: list(m.resets))
        check(resets and resets[0][1] == "watchdog",
              f"no watchdog reset while ticks missed their deadline: {resets}")
        after_ms = (resets[0][0] - t0) / 1e6
        check(after_ms <= 300, f"watchdog reset {after_ms:.0f} ms after ticks began to be late")
        st = s.status()
        check(st.get("reset_cause") == "watchdog", f"status: {st}")
    finally:
        s.close()


def save_and_count_steps(path: str, value: str):
    """Boots on `path`, sets TEETH2, waits for the save; returns the flash steps it took."""
    s = Session(path, realtime=False)
    try:
        s.wait_until_s(0.3)
        check(s.bowl("set", "TEETH2", value).startswith("ok"), "SET refused")
        # The save starts within one persistence period (0.5 s); an erase first takes 2 s (x8).
        s.wait_emulated(3.0)
        return s.call(lambda m: list(m.store.log))
    finally:
        s.close()


def boot_with_cut(path: str, cut_at: int, value: str):
    """Like save_and_count_steps, with the power cut at step `cut_at`; returns TEETH2 after the
    reboot and whether the cut happened."""
    s = Session(path, realtime=False)
    try:
        s.call(lambda m: setattr(m.store, "cut_at", cut_at))
        s.wait_until_s(0.3)
        s.bowl("set", "TEETH2", value)
        # The save starts within one persistence period (0.5 s), after an erase (2 s at x8) if
        # it needs one; the board then boots again.
        deadline = s.now_s() + 3.0
        cut_at_s = None
        while cut_at_s is None and s.now_s() < deadline:
            s.wait_emulated(0.05)
            cut_at_s = s.call(lambda m: next((t / 1e9 for t, k in m.resets if k == "power"), None))
        if cut_at_s is not None:
            s.wait_until_s(cut_at_s + 0.3)
        return s.params().get("TEETH2"), cut_at_s is not None
    finally:
        s.close()


def power_cut_sweep(base: str, value: str, previous: int):
    steps = save_and_count_steps(shutil.copy(base, base + ".probe"), value)
    check(steps, "the save programmed nothing")
    bad = []
    for k in range(1, len(steps) + 1):
        path = shutil.copy(base, base + f".cut{k}")
        teeth, cut = boot_with_cut(path, k, value)
        if not cut or teeth not in (previous, int(value)):
            bad.append((k, steps[k - 1], teeth, cut))
    check(not bad, f"after a power cut at (step, what, TEETH2 found, cut happened): {bad}; "
          f"expected {previous} or {value}")
    return len(steps)


def test_power_cut_at_every_step_of_a_save_keeps_the_last_record():
    base = fresh_flash("powercut")
    save_and_count_steps(base, "24")  # the last good record: TEETH2 24
    n = power_cut_sweep(base, "36", 24)
    print(f"   power cut swept over {n} program/erase steps")


def test_power_cut_during_the_erase_of_a_full_region_keeps_the_last_record():
    base = fresh_flash("powercut-full")
    save_and_count_steps(base, "24")
    fill_parameter_region(base)
    steps = save_and_count_steps(shutil.copy(base, base + ".probe"), "36")
    check(any(s.startswith("erase") for s in steps), f"the save did not erase: {steps[:3]}...")
    n = power_cut_sweep(base, "36", 24)
    print(f"   power cut swept over {n} program/erase steps")


def heartbeat_address(elf: str) -> int:
    """The address of the image's HEARTBEAT static (a mangled Rust name)."""
    from elftools.elf.elffile import ELFFile
    with open(elf, "rb") as f:
        for sym in ELFFile(f).get_section_by_name(".symtab").iter_symbols():
            if "9HEARTBEAT" in sym.name:
                return sym["st_value"]
    raise RuntimeError(f"{elf}: no HEARTBEAT symbol")


TESTS = [v for k, v in sorted(globals().items()) if k.startswith("test_")]


def main(names):
    global HEARTBEAT
    from session import ELF
    HEARTBEAT = heartbeat_address(ELF)
    passed = failed = 0
    t_all = time.monotonic()
    for t in TESTS:
        if names and t.__name__ not in names:
            continue
        t0 = time.monotonic()
        try:
            t()
            passed += 1
            print(f"ok   {t.__name__} ({time.monotonic() - t0:.1f} s)", flush=True)
        except Exception:
            failed += 1
            print(f"FAIL {t.__name__} ({time.monotonic() - t0:.1f} s)", flush=True)
            traceback.print_exc()
    print(f"blackpill: {passed} passed, {failed} failed ({time.monotonic() - t_all:.0f} s)")
    shutil.rmtree(WORK, ignore_errors=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
