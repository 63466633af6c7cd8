"""One emulated board for a test: the machine runs in a thread (kept to real time), USART2 on
a pty, and `bowl send` talks to it as to a real board. Actions on the machine (reset, a blocked
shaft, a wedged CPU) run in the machine's thread between slices."""

import os
import queue
import re
import subprocess
import threading
import time

from machine import Machine
from plant import RigPlant
from pty_link import PtyLink

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
# Cargo's target directory, as cargo finds it (`CARGO_TARGET_DIR`, else target/ at the root):
# the image, the plant library and `bowl` the same build left there.
TARGET = os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target")
# BLACKPILL_ELF runs another image (e.g. an older build, to see a test fail on it).
ELF = os.environ.get("BLACKPILL_ELF") or os.path.join(TARGET, "thumbv7em-none-eabihf/firmware/firmware")
PLANT_LIB = os.path.join(TARGET, "debug/libplant_ffi.so")
BOWL = os.path.join(TARGET, "debug/bowl")
LOGS = os.path.join(TARGET, "test-logs")
DEFMT_PRINT = os.environ.get("DEFMT_PRINT", "defmt-print")
# The emulation runs below real time with the loop closed: give answers room.
ANSWER_TIMEOUT_MS = 8000


class Session:
    def __init__(self, flash_path: str, realtime: bool = True, seed: int = 1, hse_hz=None,
                 rig_file=None, **board):
        """`board`: the Machine's other settings (lsi_hz, flash_timing)."""
        self.plant = RigPlant(PLANT_LIB, seed, rig_file)
        self.link = PtyLink()
        extra = dict(board) if hse_hz is None else {"hse_hz": hse_hz, **board}
        self.machine = Machine(ELF, flash_path, plant=self.plant, link=self.link,
                               defmt_print=DEFMT_PRINT, log_dir=LOGS, realtime=realtime, **extra)
        self.actions = queue.Queue()
        self.stopping = False
        self.error = None
        self.wall0 = time.monotonic()
        # Like every host tool, the session PINGs once a second of emulated time while it
        # waits, so the rig's link-loss timeout (LINK_TIMEOUT_MS) stays quiet.
        self.heartbeat = True
        self.last_ping_s = 0.0
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        try:
            while not self.stopping:
                while not self.actions.empty():
                    fn, done, box = self.actions.get()
                    box.append(fn(self.machine))
                    done.set()
                self.machine.run_for(0.005)
        except Exception as e:  # reported by the test that uses the session
            self.error = e

    def call(self, fn):
        """Runs `fn(machine)` in the machine thread; returns its result."""
        done, box = threading.Event(), []
        self.actions.put((fn, done, box))
        if not done.wait(120):
            raise TimeoutError(f"the emulated board did not come round (error: {self.error})")
        return box[0]

    def now_s(self) -> float:
        return self.machine.now_ns / 1e9

    def wait_until_s(self, t_s: float):
        """Blocks until the emulated clock has reached `t_s`."""
        while self.now_s() < t_s:
            if self.error:
                raise self.error
            if not self.thread.is_alive():
                raise RuntimeError("the machine thread stopped")
            if self.heartbeat and self.now_s() - self.last_ping_s >= 1.0:
                self.last_ping_s = self.now_s()
                self.bowl("ping")
            time.sleep(0.01)

    def wait_emulated(self, seconds: float):
        self.wait_until_s(self.now_s() + seconds)

    def bowl(self, *words) -> str:
        """`bowl send PTY WORDS`: its output; a non-zero exit raises with what it printed."""
        r = subprocess.run([BOWL, "send", "--timeout-ms", str(ANSWER_TIMEOUT_MS), self.link.path,
                            *words], capture_output=True, text=True, timeout=60)
        out = (r.stdout + r.stderr).strip()
        if r.returncode != 0 and not out.startswith(("rejected", "timeout")):
            raise RuntimeError(f"bowl send {' '.join(words)} exited {r.returncode}: {out}")
        return out

    def status(self) -> dict:
        out = self.bowl("status")
        return dict(re.findall(r"(\w+)=(\S+)", out))

    def params(self) -> dict:
        out = self.bowl("params")
        return {k: int(v) for k, v in re.findall(r"(\w+)=(-?\d+)", out)}

    def speed(self) -> str:
        wall = time.monotonic() - self.wall0
        emu = self.now_s()
        return f"emulated {emu:.2f} s in {wall:.2f} s wall: {emu / wall:.2f}x real time"

    def close(self):
        self.stopping = True
        self.thread.join(timeout=60)
        print(f"   {self.speed()}", flush=True)
        self.machine.close()
        self.link.close()
