"""The release solenoid, the release button and the exit light gate of the exact Black Pill
image, against the plant's granules (plant-ffi: the simulated rigs' one granule-and-gates
simulation). References: the harness's own record of when the solenoid pin rose and when the
exit gate's edge reached TIM2 CH3, and the Coriolis closed form (`bowl predict`, a different
method from the granule's steps) at the plant's measured speeds."""

import json
import math
import re
import subprocess
import zlib

from checks import check, fresh_flash
from session import BOWL, Session

EVENT = re.compile(rb"\$(E1,(\d+),(\d+),(\d+))\*([0-9A-F]{8})")
RELEASE, EXIT = 0, 1
# docs/protocol.md: the axes are 60 degrees apart (paper Eq. 2).
COS_AXES = 0.5


def gate_events(s: Session):
    """Every gate event frame the board has sent so far: (kind, time us, boot); a frame whose
    CRC is wrong fails the test."""
    sent = s.call(lambda m: bytes(m.tx_bytes))
    events = []
    for m in EVENT.finditer(sent):
        check(zlib.crc32(m.group(1)) == int(m.group(5), 16), f"bad CRC on {m.group(0)!r}")
        events.append((int(m.group(2)), int(m.group(3)), int(m.group(4))))
    return events


def closed_form_residence_s(omega_rad_s: float) -> float:
    out = subprocess.run([BOWL, "predict", "--model", "coriolis", "--omega-rad-s",
                          f"{omega_rad_s:.6f}", "--mu", "0.029", "--ri-m", "0.05",
                          "--rim-radius-m", "0.15", "--json"],
                         capture_output=True, text=True, check=True, timeout=60).stdout
    return json.loads(out)["results"][0]["residence_time_s"]


def test_release_solenoid_and_exit_gate_time_a_granule():
    s = Session(fresh_flash("gates"))
    try:
        s.wait_until_s(0.3)
        check(s.bowl("speed", "2000", "3000").startswith("ok"), "SPEED refused")
        check(s.bowl("start").startswith("ok"), "START refused")
        s.wait_emulated(2.5)
        out = s.bowl("release")
        check(out.startswith("ok"), f"RELEASE: {out}")
        # While the granule is in the bowl: the plant's true speeds, for the reference.
        speeds = []
        give_up = s.now_s() + 3.0
        while s.now_s() < give_up:
            speeds.append(s.call(lambda m: [m.plant.speed_rad_s(a) for a in (0, 1)]))
            granules = s.call(lambda m: list(m.plant.granules))
            if granules and granules[-1][1] is not None:
                break
            s.wait_emulated(0.02)
        check(len(granules) == 1 and granules[0][1] is not None,
              f"the granule did not leave in 3 s: {granules}")
        s.wait_emulated(0.1)
        events = gate_events(s)
        check([e[0] for e in events] == [RELEASE, EXIT], f"gate events {events}")
        measured_us = (events[1][1] - events[0][1]) & 0xFFFF_FFFF
        released_ns, exited_ns = granules[0]
        # The board's two stamps are the moments the harness raised them, to the microsecond.
        check(abs(measured_us - (exited_ns - released_ns) / 1000) <= 2,
              f"board says {measured_us} us, the harness dropped and saw the granule "
              f"{(exited_ns - released_ns) / 1000:.0f} us apart")
        pulses = s.call(lambda m: [list(p) for p in m.solenoid_pulses])
        check(len(pulses) == 1 and pulses[0][1] is not None
              and 39e6 <= pulses[0][1] - pulses[0][0] <= 42e6,
              f"solenoid pulses (on ns, off ns): {pulses}; want one of 40 ms")
        w1 = sum(w[0] for w in speeds) / len(speeds)
        w2 = sum(w[1] for w in speeds) / len(speeds)
        omega = math.sqrt(w1 * w1 + w2 * w2 + 2 * COS_AXES * w1 * w2)
        want_s = closed_form_residence_s(omega)
        measured_s = measured_us * 1e-6
        print(f"   granule: {measured_s:.6f} s in the bowl at {omega:.4f} rad/s "
              f"(closed form {want_s:.6f} s)")
        check(abs(measured_s - want_s) < 0.01 * want_s,
              f"measured {measured_s} s vs closed form {want_s} s")

        # The button, its contacts bouncing for 4 ms: one release event, at the press; it
        # fires no solenoid.
        press_ns = s.call(lambda m: m.now_ns) + 50_000_000
        s.call(lambda m: m.press_button(press_ns, (300_000, 1_100_000, 4_000_000)))
        s.wait_emulated(0.4)
        events = gate_events(s)
        check([e[0] for e in events] == [RELEASE, EXIT, RELEASE], f"after the press: {events}")
        # Board time = harness time + offset, the offset known from the solenoid's stamp.
        offset_us = events[0][1] - pulses[0][0] / 1000
        late_us = events[2][1] - (press_ns / 1000 + offset_us)
        # The interrupt is taken at the end of the slice it was raised in (20 us at most).
        check(0 <= late_us <= 21, f"button stamped {late_us:.1f} us after the press")
        edges = s.call(lambda m: m.board.exti.edges)
        check(edges == 4, f"EXTI saw {edges} falling edges, the button made 4")
        check(s.call(lambda m: len(m.solenoid_pulses)) == 1, "the button fired the solenoid")
        check(s.bowl("stop").startswith("ok"), "STOP refused")
    finally:
        s.close()
