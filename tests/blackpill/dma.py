"""STM32F4 DMA controller (RM0383 section 9): streams move one item per peripheral request,
never on their own; circular mode reloads NDTR; half and full transfer flags with their
interrupt lines; stream disable takes effect at once."""

import ctypes

from qiling.hw.peripheral import QlPeripheral

EN, TEIE, HTIE, TCIE, CIRC, MINC = 1, 1 << 2, 1 << 3, 1 << 4, 1 << 8, 1 << 10
FEIF, DMEIF, TEIF, HTIF, TCIF = 1, 1 << 2, 1 << 3, 1 << 4, 1 << 5
FLAG_SHIFT = [0, 6, 16, 22]


class Stream:
    def __init__(self):
        self.cr = 0
        self.ndtr = 0
        self.par = 0
        self.m0ar = 0
        self.m1ar = 0
        self.fcr = 0x21
        self.loaded = 0
        self.index = 0
        self.flags = 0

    @property
    def chsel(self) -> int:
        return (self.cr >> 25) & 7

    @property
    def enabled(self) -> bool:
        return bool(self.cr & EN)


class Dma(QlPeripheral):
    class Type(ctypes.Structure):
        _fields_ = [("raw", ctypes.c_uint32 * 52)]

    def __init__(self, ql, label, machine):
        super().__init__(ql, label)
        self.machine = machine
        self.streams = [Stream() for _ in range(8)]

    def irq_level(self, n: int) -> bool:
        s = self.streams[n]
        mask = 0
        if s.cr & TCIE:
            mask |= TCIF
        if s.cr & HTIE:
            mask |= HTIF
        if s.cr & TEIE:
            mask |= TEIF
        return bool(s.flags & mask)

    def transfer_one(self, n: int, peripheral):
        """Moves one item for stream `n` (a request from `peripheral` is active)."""
        s = self.streams[n]
        size = 1 << ((s.cr >> 13) & 3)
        direction = (s.cr >> 6) & 3
        mem = s.m0ar + (s.index * size if s.cr & MINC else 0)
        reg = s.par - peripheral.base
        if direction == 0:  # peripheral to memory
            value = peripheral.read(reg, size)
            self.ql.mem.write(mem, (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little"))
        else:
            value = int.from_bytes(self.ql.mem.read(mem, size), "little")
            peripheral.write(reg, size, value)
        s.index += 1
        s.ndtr -= 1
        if s.ndtr == s.loaded // 2:
            s.flags |= HTIF
        if s.ndtr == 0:
            s.flags |= TCIF
            if s.cr & CIRC:
                s.ndtr = s.loaded
                s.index = 0
            else:
                s.cr &= ~EN

    def read(self, offset: int, size: int) -> int:
        if offset in (0, 4):
            value = 0
            for k in range(4):
                value |= self.streams[(offset // 4) * 4 + k].flags << FLAG_SHIFT[k]
            return value
        if offset < 0x10:
            return 0
        n, field = divmod(offset - 0x10, 0x18)
        s = self.streams[n]
        return [s.cr, s.ndtr, s.par, s.m0ar, s.m1ar, s.fcr][field // 4]

    def write(self, offset: int, size: int, value: int):
        if offset in (8, 0xC):
            for k in range(4):
                self.streams[(offset - 8) // 4 * 4 + k].flags &= ~((value >> FLAG_SHIFT[k]) & 0x3D)
        elif offset >= 0x10:
            n, field = divmod(offset - 0x10, 0x18)
            s = self.streams[n]
            field //= 4
            if field == 0:
                if value & EN and not s.enabled:
                    s.loaded = s.ndtr
                    s.index = 0
                s.cr = value
            elif field == 1:
                if not s.enabled:
                    s.ndtr = value & 0xFFFF
            elif field == 2:
                s.par = value
            elif field == 3:
                s.m0ar = value
            elif field == 4:
                s.m1ar = value
            else:
                s.fcr = value
            self.machine.service_dma()

    @property
    def region(self):
        return [(0, 0xD0)]
