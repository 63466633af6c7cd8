"""The STM32F411's flash interface (RM0383 section 3) and its parameter sectors, backed by a
file so that what the firmware saves survives resets and emulator runs.

NOR semantics: programming only clears bits (the new value is `old & written`), a sector
erase sets all of it to 0xFF. Both stall the CPU (the machine lets time run with the CPU
stopped) for the STM32F411 datasheet's durations ("Flash memory programming" table): word
program t_PROG 16 us typical; 128 KiB sector erase t_ERASE128KB by the program/erase
parallelism FLASH_CR.PSIZE at the STRT write: x8 2 s typical / 4 s maximum, x16 1.3 / 2.6 s,
x32 1 / 2 s. embassy-stm32 0.6's blocking erase leaves PSIZE as it finds it (x8 after reset,
x32 after one of its writes). `Machine(flash_timing="max")` uses the maxima.

A power cut can be scheduled at the N-th program or erase step: that step is left half done
(an erase clears only the sector's first half, a program leaves the word's odd bits as they
were) and the machine powers off at once."""

import ctypes
import os

from qiling.hw.peripheral import QlPeripheral

# Sectors 5, 6, 7 (128 KiB each) sit behind this model; 0..4 hold the image.
BACKED_BASE = 0x0802_0000
BACKED_SIZE = 0x6_0000
SECTOR_BASES = {5: 0x0802_0000, 6: 0x0804_0000, 7: 0x0806_0000}
SECTOR_SIZE = 0x2_0000
PROGRAM_NS = 16_000
# t_ERASE128KB, ns, by PSIZE (0 = x8, 1 = x16, 2 = x32, 3 = x64, which needs an external VPP
# and is taken as x32 here): (typical, maximum).
ERASE_128K_NS = {0: (2_000_000_000, 4_000_000_000), 1: (1_300_000_000, 2_600_000_000),
                 2: (1_000_000_000, 2_000_000_000), 3: (1_000_000_000, 2_000_000_000)}

ACR, KEYR, OPTKEYR, SR, CR, OPTCR = range(0, 0x18, 4)
PG, SER, STRT, LOCK = 1, 2, 1 << 16, 1 << 31
EOP, WRPERR, PGAERR, PGSERR, BSY = 1, 1 << 4, 1 << 5, 1 << 7, 1 << 16
KEYS = (0x4567_0123, 0xCDEF_89AB)


class PowerCut(Exception):
    """Raised by the flash model when the scheduled power cut happens."""


class FlashInterface(QlPeripheral):
    class Type(ctypes.Structure):
        _fields_ = [("raw", ctypes.c_uint32 * 6)]

    def __init__(self, ql, label, machine, store: "FlashStore"):
        super().__init__(ql, label)
        self.machine = machine
        self.store = store
        self.cr = LOCK
        self.sr = 0
        self.acr = 0
        self.key_stage = 0

    def read(self, offset: int, size: int) -> int:
        return {ACR: self.acr, SR: self.sr, CR: self.cr}.get(offset, 0)

    def write(self, offset: int, size: int, value: int):
        if offset == ACR:
            self.acr = value
        elif offset == KEYR:
            if self.key_stage == 0 and value == KEYS[0]:
                self.key_stage = 1
            elif self.key_stage == 1 and value == KEYS[1]:
                self.cr &= ~LOCK
                self.key_stage = 0
            else:
                self.key_stage = 0
        elif offset == SR:
            self.sr &= ~(value & 0xF3)  # rc_w1 error and EOP flags
        elif offset == CR:
            if self.cr & LOCK:
                return
            self.cr = value & ~STRT
            if value & STRT and value & SER:
                sector = (value >> 3) & 0xF
                psize = (value >> 8) & 3
                try:
                    self.store.erase(sector, self.machine, psize)
                except PowerCut:
                    self.machine.cut_power()
                    return
                self.sr |= EOP

    def program(self, address: int, size: int, value: int):
        """A CPU write into the backed sectors."""
        if self.cr & LOCK or not self.cr & PG:
            self.sr |= PGSERR
            return
        try:
            self.store.program(address - BACKED_BASE, size, value, self.machine)
        except PowerCut:
            self.machine.cut_power()
            return
        self.sr |= EOP

    @property
    def region(self):
        return [(0, 0x18)]


class FlashStore:
    """The backed sectors' bytes, kept in a file between runs."""

    def __init__(self, path: str):
        self.path = path
        if os.path.exists(path) and os.path.getsize(path) == BACKED_SIZE:
            with open(path, "rb") as f:
                self.data = bytearray(f.read())
        else:
            self.data = bytearray(b"\xff" * BACKED_SIZE)
        self.steps = 0
        self.cut_at = None
        self.log = []

    def flush(self):
        with open(self.path, "wb") as f:
            f.write(self.data)

    def _step(self, what: str) -> bool:
        """Counts a program/erase step; True if the power is cut during this one."""
        self.steps += 1
        self.log.append(what)
        return self.cut_at is not None and self.steps == self.cut_at

    def erase(self, sector: int, machine, psize: int = 0):
        if sector not in SECTOR_BASES:
            return  # image sectors: the firmware has no business there; leave them
        start = SECTOR_BASES[sector] - BACKED_BASE
        if self._step(f"erase {sector}"):
            self.data[start:start + SECTOR_SIZE // 2] = b"\xff" * (SECTOR_SIZE // 2)
            self.flush()
            raise PowerCut
        self.data[start:start + SECTOR_SIZE] = b"\xff" * SECTOR_SIZE
        self.flush()
        typical, maximum = ERASE_128K_NS[psize]
        machine.stall(maximum if machine.flash_timing == "max" else typical)

    def program(self, offset: int, size: int, value: int, machine):
        old = int.from_bytes(self.data[offset:offset + size], "little")
        new = old & value
        if self._step(f"program {offset:#x}"):
            new = old & (value | 0x5555_5555 & ((1 << (8 * size)) - 1))
            self.data[offset:offset + size] = new.to_bytes(size, "little")
            self.flush()
            raise PowerCut
        self.data[offset:offset + size] = new.to_bytes(size, "little")
        machine.stall(PROGRAM_NS)

    def read(self, offset: int, size: int) -> int:
        return int.from_bytes(self.data[offset:offset + size], "little")
