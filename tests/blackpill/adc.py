"""STM32F411 ADC1 (RM0383 section 11), as much as the motor-current sampling uses: the injected
group (JSQR: up to four channels, results in JDR1..), its hardware trigger from TIM1's TRGO or
CC4 (JEXTSEL 1 / 0, JEXTEN), the end-of-conversion flag and interrupt (JEOC, JEOCIE) and the
flags' rc_w0 clearing.

What a channel reads comes from `inputs`: channel -> a function returning the pin's voltage at
the moment (the board wires PB0/PB1 = IN8/IN9 to the current-sense amplifiers of the plant).
Conversions happen at the trigger; the model converts at each plant step while the trigger is
armed and its timer runs (the plant's current changes only then), and also when the firmware
reads a result register, so a read never sees a value older than the last plant step."""

import ctypes

from qiling.hw.peripheral import QlPeripheral

SR, CR1, CR2, SMPR1, SMPR2 = 0x00, 0x04, 0x08, 0x0C, 0x10
HTR, LTR, SQR1, SQR2, SQR3, JSQR = 0x24, 0x28, 0x2C, 0x30, 0x34, 0x38
JDR_BASE, DR = 0x3C, 0x4C
# SR flags.
JEOC, JSTRT = 1 << 2, 1 << 3
# CR1 bits.
JEOCIE = 1 << 7
# CR2 bits.
ADON, JSWSTART = 1 << 0, 1 << 22
VREF_V = 3.3
FULL_SCALE = 4095


class Adc(QlPeripheral):
    class Type(ctypes.Structure):
        _fields_ = [("raw", ctypes.c_uint32 * 20)]

    def __init__(self, ql, label, tim1):
        super().__init__(ql, label)
        self.tim1 = tim1
        self.regs = {SR: 0, CR1: 0, CR2: 0, SMPR1: 0, SMPR2: 0, HTR: 0xFFF, LTR: 0, SQR1: 0,
                     SQR2: 0, SQR3: 0, JSQR: 0}
        self.jdr = [0, 0, 0, 0]
        # channel -> callable returning volts (unconnected channels read 0 V).
        self.inputs = {}
        self.conversions = 0

    # --- the injected group -------------------------------------------------------------
    def injected_channels(self):
        jsqr = self.regs[JSQR]
        count = ((jsqr >> 20) & 3) + 1
        # RM0383 JSQR: with JL = n-1 the sequence is the last n of JSQ1..JSQ4.
        return [(jsqr >> (5 * k)) & 0x1F for k in range(4 - count, 4)]

    def triggered(self) -> bool:
        """ADC on, the injected trigger enabled on TIM1 TRGO (update) or CC4, the timer running."""
        cr2 = self.regs[CR2]
        if not cr2 & ADON or not (cr2 >> 20) & 3:
            return False
        sel = (cr2 >> 16) & 0xF
        if sel == 1:  # TIM1_TRGO: only if TIM1's master mode sends its update (MMS = 010)
            return self.tim1.running() and ((self.tim1.regs[0x04] >> 4) & 7) == 2
        if sel == 0:  # TIM1_CC4
            return self.tim1.running()
        return False

    def counts(self, channel: int) -> int:
        volts = self.inputs.get(channel, lambda: 0.0)()
        return max(0, min(FULL_SCALE, round(volts / VREF_V * FULL_SCALE)))

    def convert(self):
        """One injected sequence now: the results and JEOC."""
        for k, ch in enumerate(self.injected_channels()):
            self.jdr[k] = self.counts(ch)
        self.regs[SR] |= JEOC | JSTRT
        self.conversions += 1

    def plant_stepped(self):
        if self.triggered():
            self.convert()

    def irq_level(self) -> bool:
        return bool(self.regs[SR] & JEOC and self.regs[CR1] & JEOCIE)

    # --- registers ----------------------------------------------------------------------
    def read(self, offset: int, size: int) -> int:
        if JDR_BASE <= offset < JDR_BASE + 16:
            if self.triggered():
                self.convert()
            return self.jdr[(offset - JDR_BASE) // 4]
        if offset == DR:
            return 0
        return self.regs.get(offset, 0)

    def write(self, offset: int, size: int, value: int):
        if offset == SR:
            self.regs[SR] &= value  # rc_w0
        elif offset == CR2:
            self.regs[CR2] = value & ~JSWSTART
            if value & JSWSTART and value & ADON:
                self.convert()
        elif offset in self.regs:
            self.regs[offset] = value

    @property
    def region(self):
        return [(0, 0x50)]


class AdcCommon(QlPeripheral):
    """ADC_CSR/CCR/CDR: only the clock prescaler is kept (conversions are instantaneous)."""

    class Type(ctypes.Structure):
        _fields_ = [("raw", ctypes.c_uint32 * 3)]

    def __init__(self, ql, label):
        super().__init__(ql, label)
        self.regs = {0x0: 0, 0x4: 0, 0x8: 0}

    def read(self, offset: int, size: int) -> int:
        return self.regs.get(offset, 0)

    def write(self, offset: int, size: int, value: int):
        if offset == 0x4:
            self.regs[0x4] = value

    @property
    def region(self):
        return [(0, 0x0C)]
