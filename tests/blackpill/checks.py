"""What every test of the emulated board shares: a scratch directory for flash files, the
check that raises with what went wrong, and the plant's mean true speed."""

import os
import tempfile

WORK = tempfile.mkdtemp(prefix="blackpill-")


def fresh_flash(name: str) -> str:
    path = os.path.join(WORK, name + ".bin")
    if os.path.exists(path):
        os.unlink(path)
    return path


def check(cond, what):
    if not cond:
        raise AssertionError(what)


def mean_speed(s, axis: int, seconds: float, samples: int = 10) -> float:
    """The plant's true speed of `axis`, rad/s, averaged over `seconds` of emulated time."""
    total = 0.0
    for _ in range(samples):
        s.wait_emulated(seconds / samples)
        total += s.call(lambda m: m.plant.speed_rad_s(axis))
    return total / samples
