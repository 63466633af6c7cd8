"""STM32F4 USART (RM0383 section 19) as the firmware's host link: bytes take their frame time
(10 bits at the baud rate that BRR and the APB1 clock give), a byte that arrives while RXNE is
still set is lost with ORE, IDLE rises one frame after the last received byte, and RXNE/TXE
raise DMA requests when CR3 enables them."""

import ctypes
from collections import deque

from qiling.hw.peripheral import QlPeripheral

SR, DR, BRR, CR1, CR2, CR3, GTPR = range(0, 0x1C, 4)
# The USB-serial adapter on the PC side runs at the protocol's rate (docs/protocol.md). A UART
# samples each bit at the middle of where it expects it: over the 10 bits of a frame the two
# ends' rates may differ by about 4 % before the stop bit is sampled in the wrong place.
ADAPTER_BAUD = 115_200
BAUD_TOLERANCE = 0.04
ORE, IDLE, RXNE, TC, TXE = 1 << 3, 1 << 4, 1 << 5, 1 << 6, 1 << 7
RE, TE, IDLEIE, RXNEIE, TCIE, TXEIE, UE = 1 << 2, 1 << 3, 1 << 4, 1 << 5, 1 << 6, 1 << 7, 1 << 13
EIE, DMAR, DMAT = 1 << 0, 1 << 6, 1 << 7


class Usart(QlPeripheral):
    class Type(ctypes.Structure):
        _fields_ = [("raw", ctypes.c_uint32 * 7)]

    def __init__(self, ql, label, machine, apb: int, transmit):
        super().__init__(ql, label)
        self.machine = machine
        self.apb = apb
        self.transmit = transmit  # called with each byte as its stop bit ends
        self.regs = {SR: TC | TXE, BRR: 0, CR1: 0, CR2: 0, CR3: 0, GTPR: 0}
        self.rx_data = 0
        self.rx_queue = deque()
        self.next_rx_ns = None
        self.idle_at_ns = None
        self.sr_read = False
        self.shift = None  # (byte, end_ns)
        self.holding = None
        self.lost_rx = 0
        self.baud_errors = 0

    def frame_ns(self) -> int:
        brr = self.regs[BRR] or 1
        pclk = self.machine.clocks.pclk1_hz() if self.apb == 1 else self.machine.clocks.pclk2_hz()
        return int(10 * brr * 1e9 / pclk)

    def baud(self) -> float:
        brr = self.regs[BRR] or 1
        pclk = self.machine.clocks.pclk1_hz() if self.apb == 1 else self.machine.clocks.pclk2_hz()
        return pclk / brr

    def garbled(self, byte: int) -> int:
        """A byte as the other end samples it: intact while the two rates agree within the
        tolerance, otherwise shifted by the accumulated bit slip (and the stop bit lost)."""
        ratio = self.baud() / ADAPTER_BAUD
        if abs(ratio - 1.0) <= BAUD_TOLERANCE:
            return byte
        self.baud_errors += 1
        # Bit k is sampled where the other end's bit k * ratio lies.
        out = 0
        for k in range(8):
            src = int((k + 0.5) * ratio)
            if src < 8 and byte >> src & 1:
                out |= 1 << k
        return out

    def enabled(self, bit: int) -> bool:
        return bool(self.regs[CR1] & UE and self.regs[CR1] & bit)

    # --- host side ---------------------------------------------------------------------
    def receive(self, data: bytes):
        self.rx_queue.extend(data)
        if self.next_rx_ns is None and self.rx_queue:
            self.next_rx_ns = self.machine.now_ns + self.frame_ns()

    # --- time --------------------------------------------------------------------------
    def next_event_ns(self):
        times = [t for t in (self.next_rx_ns, self.idle_at_ns) if t is not None]
        if self.shift is not None:
            times.append(self.shift[1])
        return min(times) if times else None

    def sync(self):
        now = self.machine.now_ns
        changed = False
        while self.shift is not None and self.shift[1] <= now:
            byte, end = self.shift
            self.transmit(self.garbled(byte))
            if self.holding is not None:
                self.shift = (self.holding, end + self.frame_ns())
                self.holding = None
                self.regs[SR] |= TXE
            else:
                self.shift = None
                self.regs[SR] |= TC
            changed = True
        while self.next_rx_ns is not None and self.next_rx_ns <= now:
            at = self.next_rx_ns
            if not self.rx_queue:
                self.next_rx_ns = None
                break
            byte = self.garbled(self.rx_queue.popleft())
            if self.enabled(RE):
                if self.regs[SR] & RXNE:
                    self.regs[SR] |= ORE
                    self.lost_rx += 1
                else:
                    self.rx_data = byte
                    self.regs[SR] |= RXNE
                self.idle_at_ns = at + self.frame_ns()
            self.next_rx_ns = at + self.frame_ns() if self.rx_queue else None
            changed = True
            # DMA takes the byte before the next one lands.
            self.machine.service_dma()
        if self.idle_at_ns is not None and self.idle_at_ns <= now and self.next_rx_ns is None:
            self.regs[SR] |= IDLE
            self.idle_at_ns = None
            changed = True
        if changed:
            self.machine.service_dma()

    def irq_level(self) -> bool:
        sr, cr1, cr3 = self.regs[SR], self.regs[CR1], self.regs[CR3]
        return bool(
            (cr1 & IDLEIE and sr & IDLE)
            or (cr1 & RXNEIE and sr & (RXNE | ORE))
            or (cr1 & TCIE and sr & TC)
            or (cr1 & TXEIE and sr & TXE)
            or (cr3 & EIE and sr & ORE)
        )

    # --- DMA requests ------------------------------------------------------------------
    def dma_request(self, kind: str) -> bool:
        if kind == "rx":
            return bool(self.regs[CR3] & DMAR and self.regs[SR] & RXNE)
        return bool(self.regs[CR3] & DMAT and self.regs[SR] & TXE and self.enabled(TE))

    # --- registers ---------------------------------------------------------------------
    def _write_data(self, value: int):
        self.regs[SR] &= ~TC
        if not self.enabled(TE):
            return
        if self.shift is None:
            self.shift = (value & 0xFF, self.machine.now_ns + self.frame_ns())
        else:
            self.holding = value & 0xFF
            self.regs[SR] &= ~TXE

    def read(self, offset: int, size: int) -> int:
        self.sync()
        if offset == SR:
            self.sr_read = True
            return self.regs[SR]
        if offset == DR:
            if self.sr_read:
                self.regs[SR] &= ~(IDLE | ORE)
            self.sr_read = False
            self.regs[SR] &= ~RXNE
            return self.rx_data
        return self.regs.get(offset, 0)

    def write(self, offset: int, size: int, value: int):
        self.sync()
        if offset == DR:
            self._write_data(value)
        elif offset == SR:
            # rc_w0 for RXNE and TC; the others are read-only.
            self.regs[SR] &= value | ~(RXNE | TC)
        elif offset in self.regs:
            self.regs[offset] = value
        self.machine.service_dma()

    @property
    def region(self):
        return [(0, 0x1C)]
