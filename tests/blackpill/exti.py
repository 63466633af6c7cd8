"""The EXTI controller (RM0383 section 10) for lines 0..15: a GPIO edge on a line's selected
port (SYSCFG_EXTICRx) with that edge enabled (RTSR/FTSR) sets the line's pending bit; the
interrupt line is up while a pending bit is unmasked (IMR); software clears a pending bit by
writing 1 to it."""

import ctypes

from qiling.hw.peripheral import QlPeripheral

IMR, EMR, RTSR, FTSR, SWIER, PR = range(0, 0x18, 4)
PORTS = "abcdefgh"


class Exti(QlPeripheral):
    class Type(ctypes.Structure):
        _fields_ = [("raw", ctypes.c_uint32 * 6)]

    def __init__(self, ql, label, syscfg):
        super().__init__(ql, label)
        self.syscfg = syscfg
        self.regs = {IMR: 0, EMR: 0, RTSR: 0, FTSR: 0, SWIER: 0, PR: 0}
        self.edges = 0

    def selected_port(self, line: int) -> str:
        cr = self.syscfg.instance.EXTICR[line // 4]
        return PORTS[(cr >> (4 * (line % 4))) & 0xF]

    def pin_edge(self, port: str, line: int, rising: bool):
        """A level change on pin `line` of GPIO `port` ("a".."h")."""
        if self.selected_port(line) != port:
            return
        enabled = self.regs[RTSR if rising else FTSR]
        if enabled & (1 << line):
            self.edges += 1
            self.regs[PR] |= 1 << line

    def irq_level(self, mask: int) -> bool:
        return bool(self.regs[PR] & self.regs[IMR] & mask)

    def read(self, offset: int, size: int) -> int:
        return self.regs.get(offset, 0)

    def write(self, offset: int, size: int, value: int):
        if offset == PR:
            self.regs[PR] &= ~value  # rc_w1
        elif offset == SWIER:
            self.regs[PR] |= value & self.regs[IMR]
        elif offset in self.regs:
            self.regs[offset] = value & 0x7F_FFFF

    @property
    def region(self):
        return [(0, 0x18)]
