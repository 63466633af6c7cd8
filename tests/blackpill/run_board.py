"""Runs the Black Pill image on the emulated STM32F411 with USART2 on a pseudo-terminal.

    python tests/blackpill/run_board.py [--elf ELF] [--seconds S] [--pty-link PATH]

Prints `pty: /dev/pts/N` once the board is up; `bowl send PTY status` then talks to it. The
emulation keeps to real time so the host tools' timeouts mean what they mean on a board. defmt
logs go to target/test-logs/blackpill-defmt.log. Ends after --seconds of emulated time, or on
Ctrl-C, or when a file named by --stop-file appears. --reset-file PATH: when PATH appears the
board gets a pin reset (and PATH is removed). --control-stdin: lines on standard input inject
faults into the emulated plant (the firmware itself refuses INJECT, as a real board does):
`inject sensor1|sensor2` silences a sensor, `inject stall1|stall2` blocks a shaft, `inject none`
repairs both."""

import argparse
import os
import queue
import signal
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)

from machine import EmulationError, Machine  # noqa: E402
from plant import RigFileError, RigPlant  # noqa: E402
from pty_link import PtyLink  # noqa: E402


def default_paths():
    return {
        "elf": os.path.join(ROOT, "target/thumbv7em-none-eabihf/firmware/firmware"),
        "plant": os.path.join(ROOT, "target/debug/libplant_ffi.so"),
        "flash": os.path.join(ROOT, "target/blackpill/flash.bin"),
        "logs": os.path.join(ROOT, "target/test-logs"),
        "defmt_print": os.environ.get("DEFMT_PRINT", "defmt-print"),
    }


def inject(plant, line: str):
    """Applies one `inject WHAT` control line to the plant, from the plant's present time."""
    words = line.split()
    if len(words) != 2 or words[0] != "inject":
        print(f"control: ignored {line!r} (expected `inject sensor1|sensor2|stall1|stall2|none`)",
              file=sys.stderr)
        return
    now_s = plant.time_ns / 1e9
    what = words[1]
    if what == "none":
        for axis in (0, 1):
            plant.kill_sensor(axis, float("inf"))
            plant.block_shaft(axis, float("inf"))
    elif what in ("sensor1", "sensor2"):
        plant.kill_sensor(int(what[-1]) - 1, now_s)
    elif what in ("stall1", "stall2"):
        plant.block_shaft(int(what[-1]) - 1, now_s)
    else:
        print(f"control: unknown fault {what!r}", file=sys.stderr)
        return
    print(f"control: inject {what} at plant time {now_s:.3f} s", flush=True)


def main():
    d = default_paths()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elf", default=d["elf"])
    ap.add_argument("--plant-lib", default=d["plant"])
    ap.add_argument("--flash-file", default=d["flash"])
    ap.add_argument("--log-dir", default=d["logs"])
    ap.add_argument("--defmt-print", default=d["defmt_print"])
    ap.add_argument("--rig-file", default=None,
                    help="the rig the plant simulates (docs/rigs/*.toml); the nominal rig if left out")
    ap.add_argument("--seconds", type=float, default=3600.0)
    ap.add_argument("--pty-link", default=None, help="also make this symlink to the pty")
    ap.add_argument("--stop-file", default=None)
    ap.add_argument("--reset-file", default=None)
    ap.add_argument("--control-stdin", action="store_true",
                    help="take `inject WHAT` lines on standard input")
    args = ap.parse_args()
    for what, path in (("image", args.elf), ("plant library", args.plant_lib)):
        if not os.path.exists(path):
            sys.exit(f"error: the {what} {path} does not exist: build it first "
                     "(cargo fw; cargo build -p plant-ffi)")
    os.makedirs(os.path.dirname(args.flash_file), exist_ok=True)
    try:
        plant = RigPlant(args.plant_lib, rig_file=args.rig_file)
    except RigFileError as e:
        sys.exit(f"error: {e}")
    link = PtyLink(args.pty_link)
    m = Machine(args.elf, args.flash_file, plant=plant, link=link,
                defmt_print=args.defmt_print, log_dir=args.log_dir, realtime=True)
    print(f"pty: {link.path}", flush=True)
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    control = queue.Queue()
    if args.control_stdin:
        def read_control():
            for line in sys.stdin:
                control.put(line.strip())
        threading.Thread(target=read_control, daemon=True).start()
    wall0 = time.monotonic()
    status = 0
    try:
        end = args.seconds
        while m.now_ns / 1e9 < end and not stop:
            m.run_for(0.05)
            if args.stop_file and os.path.exists(args.stop_file):
                break
            if args.reset_file and os.path.exists(args.reset_file):
                os.unlink(args.reset_file)
                m.reset("pin")
            while not control.empty():
                inject(plant, control.get())
    except EmulationError as e:
        print(f"error: {e}", file=sys.stderr)
        status = 1
    finally:
        wall = time.monotonic() - wall0
        emu = m.now_ns / 1e9
        print(f"emulated {emu:.2f} s in {wall:.2f} s wall ({emu / wall if wall else 0:.2f}x real time), "
              f"resets {[k for _, k in m.resets]}", flush=True)
        m.close()
        link.close()
    return status


if __name__ == "__main__":
    sys.exit(main())
