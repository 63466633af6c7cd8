"""The independent watchdog (RM0383 section 17): counts down from RLR at LSI/(4 << PR) once
started with 0xCCCC; 0xAAAA reloads; 0x5555 unlocks PR and RLR. At zero the machine resets
with IWDGRSTF set.

The LSI is an RC oscillator: the STM32F411 datasheet gives 17 kHz minimum, 32 kHz typical,
47 kHz maximum ("LSI oscillator characteristics"). The firmware computes its timeout for
32 kHz, so `Machine(lsi_hz=...)` runs it at either extreme; `min_margin_ns` is the least time
that was left on the countdown at a reload (how close the feeding came to a reset)."""

import ctypes

from qiling.hw.peripheral import QlPeripheral

# The datasheet's LSI: typical 32 kHz, 17 to 47 kHz.
LSI_HZ = 32_000
LSI_MIN_HZ, LSI_MAX_HZ = 17_000, 47_000


class Iwdg(QlPeripheral):
    class Type(ctypes.Structure):
        _fields_ = [("raw", ctypes.c_uint32 * 4)]

    def __init__(self, ql, label, machine):
        super().__init__(ql, label)
        self.machine = machine
        self.pr = 0
        self.rlr = 0xFFF
        self.unlocked = False
        self.expires_ns = None
        self.reloads = 0
        self.min_margin_ns = None

    def period_ns(self) -> int:
        return int((self.rlr + 1) * (4 << self.pr) * 1e9 / self.machine.lsi_hz)

    def next_event_ns(self):
        return self.expires_ns

    def sync(self):
        if self.expires_ns is not None and self.machine.now_ns >= self.expires_ns:
            self.expires_ns = None
            self.machine.request_reset("watchdog")

    def read(self, offset: int, size: int) -> int:
        return {4: self.pr, 8: self.rlr}.get(offset, 0)

    def write(self, offset: int, size: int, value: int):
        self.sync()
        if offset == 0:
            key = value & 0xFFFF
            if key == 0xCCCC:
                self.expires_ns = self.machine.now_ns + self.period_ns()
            elif key == 0xAAAA:
                self.unlocked = False
                if self.expires_ns is not None:
                    self.reloads += 1
                    left = self.expires_ns - self.machine.now_ns
                    if self.min_margin_ns is None or left < self.min_margin_ns:
                        self.min_margin_ns = left
                    self.expires_ns = self.machine.now_ns + self.period_ns()
            elif key == 0x5555:
                self.unlocked = True
        elif offset == 4 and self.unlocked:
            self.pr = value & 7
        elif offset == 8 and self.unlocked:
            self.rlr = value & 0xFFF

    @property
    def region(self):
        return [(0, 0x10)]
