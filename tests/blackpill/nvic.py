"""NVIC with level-triggered peripheral lines: an interrupt stays pending while its
peripheral's flag is up, also while it is masked (disabled in the NVIC or PRIMASK set), and is
taken once it is unmasked; software pends (ISPR, `InterruptExt::pend`) are edge-like and
cleared on entry, as on the Cortex-M4."""

import ctypes

from qiling.hw.peripheral import QlPeripheral


class Nvic(QlPeripheral):
    class Type(ctypes.Structure):
        _fields_ = [("raw", ctypes.c_uint8 * 0xE04)]

    def __init__(self, ql, label, machine):
        super().__init__(ql, label)
        self.machine = machine
        self.enabled = 0
        self.soft_pending = 0
        self.priority = bytearray(240)
        # irq number -> callable returning the line's level
        self.lines = {}

    def connect(self, irq: int, level):
        self.lines.setdefault(irq, []).append(level)

    def line_pending(self) -> int:
        bits = 0
        for irq, levels in self.lines.items():
            for level in levels:
                if level():
                    bits |= 1 << irq
                    break
        return bits

    def next_irq(self):
        """The enabled pending interrupt to take next (lowest priority value, then number)."""
        ready = (self.soft_pending | self.line_pending()) & self.enabled
        if not ready:
            return None
        best = None
        irq = 0
        while ready:
            if ready & 1 and (best is None or self.priority[irq] < self.priority[best]):
                best = irq
            ready >>= 1
            irq += 1
        return best

    def get_priority(self, irq: int) -> int:
        return self.priority[irq] if irq >= 0 else 0

    def set_pending(self, irq: int):
        """Qiling reports CPU faults here (negative numbers): the image crashed."""
        if irq < 0:
            self.machine.cpu_fault = irq
            self.ql.emu_stop()
        else:
            self.soft_pending |= 1 << irq

    def taken(self, irq: int):
        self.soft_pending &= ~(1 << irq)

    def read(self, offset: int, size: int) -> int:
        value = 0
        if 0x300 <= offset < 0x3F0:
            for i in range(size):
                value |= self.priority[offset - 0x300 + i] << (8 * i)
            return value
        bank = (offset & 0x7F) // 4
        shift = bank * 32
        if offset < 0x080:
            value = self.enabled >> shift
        elif 0x080 <= offset < 0x100:
            value = self.enabled >> shift
        elif 0x100 <= offset < 0x200:
            value = (self.soft_pending | self.line_pending()) >> shift
        return value & 0xFFFFFFFF

    def write(self, offset: int, size: int, value: int):
        if 0x300 <= offset < 0x3F0:
            for i in range(size):
                self.priority[offset - 0x300 + i] = (value >> (8 * i)) & 0xF0
            return
        bits = (value & 0xFFFFFFFF) << (((offset & 0x7F) // 4) * 32)
        if offset < 0x080:
            self.enabled |= bits
        elif offset < 0x100:
            self.enabled &= ~bits
        elif offset < 0x180:
            self.soft_pending |= bits
        elif offset < 0x200:
            self.soft_pending &= ~bits

    @property
    def region(self):
        return [(0, 0x400)]
