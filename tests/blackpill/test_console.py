"""The exact image from a plain serial console: picocom in a terminal (tmux) on the board's
USART, commands typed as the words `bowl send` takes (no `$`, id or CRC), each answer a frame
with request id 0 on the screen. Joins test_board.py's run."""

import os
import subprocess
import time

from checks import check, fresh_flash
from session import Session


def _wait_for(screen, text: str, what: str, limit_s: float = 30.0) -> str:
    started = time.monotonic()
    while True:
        shown = screen()
        if text in shown:
            return shown
        check(time.monotonic() - started < limit_s, f"{what}: no {text!r} on the screen:\n{shown}")
        time.sleep(0.2)


def test_a_person_types_commands_at_picocom():
    s = Session(fresh_flash("console"))
    tmux = ["tmux", "-L", f"bowl-blackpill-console-{os.getpid()}"]
    try:
        s.wait_until_s(0.3)
        subprocess.run(tmux + ["new-session", "-d", "-x", "120", "-y", "40",
                               f"picocom -b 115200 {s.link.path}"], check=True)

        def screen() -> str:
            return subprocess.run(tmux + ["capture-pane", "-p", "-t", "0"],
                                  capture_output=True, text=True).stdout

        def typed(*keys: str):
            subprocess.run(tmux + ["send-keys", "-t", "0", *keys, "Enter"], check=True)

        _wait_for(screen, "$T1,", "telemetry on the console")
        typed("set TELEM_HZ 0")
        _wait_for(screen, "$A1,0*", "the board acknowledges a typed SET")
        typed("status")
        _wait_for(screen, "$S1,0,0,0,", "the board answers a typed STATUS (idle, no fault)")
        typed("statsu")
        _wait_for(screen, "$R1,0,UNKNOWN*", "a typo is refused, not ignored")
        # An arrow key (ESC [ A) typed into the line: refused, not met with silence.
        typed("status", "Up")
        _wait_for(screen, "$R1,0,UNREADABLE*", "a line with an arrow key is refused")
    finally:
        subprocess.run(tmux + ["kill-server"], capture_output=True)
        s.close()
