"""The scenarios of `tests/scenarios/*.toml` on the emulated Black Pill: the exact release image
on the emulated STM32F411 with the project's plant. Each command goes out by `bowl send` on the
board's pty when the board's clock reaches its time (a step no sooner after the previous step's
answer than the scenario spaces them, as on QEMU); `inject WHAT` goes to the plant (the board's
own answer to INJECT is UNSUPPORTED: real hardware cannot fake a fault) and counts as done.

This script only runs the board; the checking is the same Rust code as for the host rig and
QEMU (`host-tools/tests/scenarios_blackpill.rs` reads what it writes): per scenario a
directory with `capture.bin` (everything the board sent, as `bowl serve --capture` writes it)
and `sent.json` (each command's answer and the board times, ms, from just before it was sent to
just after its answer, in file order).

    python tests/blackpill/run_scenarios.py OUTDIR [NAME-PART...]

Without NAME-PARTs it runs the subset in `BLACKPILL_SET` (the emulation runs at 0.25-0.57x real
time: all scenarios would take 11-25 min)."""

import json
import os
import subprocess
import sys
import time
import tomllib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from checks import fresh_flash  # noqa: E402
from session import ANSWER_TIMEOUT_MS, BOWL, ROOT, Session  # noqa: E402

SCENARIOS = os.path.join(ROOT, "tests", "scenarios")
# The scenarios the Black Pill runs in `bash tests/run` (about 67 s of board time): a slow-down,
# a fault and its CLEAR, a speed-up.
BLACKPILL_SET = ("slow-down-3-to-1", "fault-and-clear", "speed-up")
# INJECT's words -> (plant method, axis) or None for "remove every injected fault".
INJECTIONS = {
    "sensor1": ("kill_sensor", 0),
    "sensor2": ("kill_sensor", 1),
    "stall1": ("block_shaft", 0),
    "stall2": ("block_shaft", 1),
    "none": None,
}


def board_ms(s: Session) -> int:
    return int(s.machine.now_ns // 1_000_000)


def answer(rc: int, text: str) -> str:
    """`done`, or the rejection's wire token, as the QEMU runner reads `bowl send`."""
    if rc == 0:
        return "done"
    if rc == 1 and "): " in text:
        rest = text.split("): ", 1)[1].split()
        return rest[0] if rest else "rejected"
    return f"no answer (bowl send exited {rc}: {text.strip()})"


def inject(s: Session, what: str) -> str:
    if what not in INJECTIONS:
        return f"no answer (unknown injection {what!r})"
    spec = INJECTIONS[what]

    def apply(m):
        t = m.plant.time_ns / 1e9
        if spec is None:
            for axis in (0, 1):
                for kind in (0, 1, 2):
                    m.plant._inject(axis, kind, float("inf"))
        else:
            method, axis = spec
            getattr(m.plant, method)(axis, t)

    s.call(apply)
    return "done"


def send(s: Session, words) -> str:
    if words[0] == "inject":
        return inject(s, words[1] if len(words) > 1 else "")
    r = subprocess.run([BOWL, "send", "--timeout-ms", str(ANSWER_TIMEOUT_MS), s.link.path,
                        *words], capture_output=True, text=True, timeout=60)
    return answer(r.returncode, r.stdout + r.stderr)


def run(path: str, out_dir: str):
    with open(path, "rb") as f:
        scenario = tomllib.load(f)
    commands = scenario.get("command", [])
    end_ms = int(scenario["seconds"] * 1000)
    name = os.path.splitext(os.path.basename(path))[0]
    s = Session(fresh_flash("scenario-" + name))
    answers = [""] * len(commands)
    sent = [(0, 0)] * len(commands)
    try:
        order = sorted(range(len(commands)), key=lambda i: commands[i]["at_ms"])
        previous = None  # (scenario time, board time of its last answer)

        def wait_until(due_ms: int):
            s.wait_until_s(due_ms / 1000)

        for i in order:
            c = commands[i]
            if previous is None:
                wait_until(c["at_ms"])
            elif previous[0] != c["at_ms"]:
                wait_until(previous[1] + (c["at_ms"] - previous[0]))
            before = board_ms(s)
            answers[i] = send(s, c["send"].split())
            sent[i] = (before, board_ms(s))
            previous = (c["at_ms"], sent[i][1])
        wait_until(end_ms if previous is None else previous[1] + (end_ms - previous[0]))
        capture = s.call(lambda m: bytes(m.tx_bytes))
    finally:
        s.close()
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "capture.bin"), "wb") as f:
        f.write(capture)
    with open(os.path.join(out_dir, "sent.json"), "w") as f:
        json.dump({"answers": answers, "sent_ms": sent}, f)


def main(argv) -> int:
    if not argv:
        print(__doc__)
        return 2
    out, parts = argv[0], argv[1:] or list(BLACKPILL_SET)
    files = sorted(p for p in os.listdir(SCENARIOS) if p.endswith(".toml"))
    chosen = [p for p in files if any(part in p for part in parts)]
    if not chosen:
        print(f"no scenario in {SCENARIOS} matches {parts}", file=sys.stderr)
        return 2
    for p in chosen:
        t0 = time.monotonic()
        run(os.path.join(SCENARIOS, p), os.path.join(out, os.path.splitext(p)[0]))
        print(f"{p} ran on the emulated Black Pill ({time.monotonic() - t0:.0f} s)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
