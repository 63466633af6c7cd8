"""What every test of the emulated board shares: a scratch directory for flash files, the
check that raises with what went wrong, the plant's mean true speed, and a parameter region
filled so the next save must erase."""

import os
import tempfile

from flash import BACKED_BASE, SECTOR_BASES, SECTOR_SIZE

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


def fill_parameter_region(path: str):
    """Fills every slot of the parameter region (sectors 6 and 7) of the flash file `path` with
    the firmware's own record, so the next save must erase: the image wrote the first slot of
    sector 6; the copies are byte for byte the same."""
    with open(path, "r+b") as f:
        data = bytearray(f.read())
        first = SECTOR_BASES[6] - BACKED_BASE
        used = data[first:first + SECTOR_SIZE]
        end = len(used.rstrip(b"\xff"))
        check(end > 0, "the first save left sector 6 blank")
        record = bytes(used[:(end + 3) // 4 * 4])
        for sector in (6, 7):
            start = SECTOR_BASES[sector] - BACKED_BASE
            n = SECTOR_SIZE // len(record)
            data[start:start + n * len(record)] = record * n
        f.seek(0)
        f.write(data)


def wedge_cpu(m):
    """The control task never returns: interrupts off, the CPU spinning on `b .`."""
    spin = 0x2000_0100
    m.board.ql.mem.write(spin, b"\xfe\xe7")
    m.board.ql.arch.regs.write("primask", 1)
    m.board.ql.arch.regs.pc = spin
    return m.now_ns
