"""STM32F4 TIM1/TIM2/TIM5 (RM0383 sections 12-13): an up-counter derived from the RCC clock
tree, prescaler/auto-reload/compare preload taking effect at update events, compare and
capture flags with overcapture, the update flag, DIER-gated interrupt lines, and for the
advanced timer the main output enable (BDTR.MOE) that gates the PWM outputs, with what each
output does then (`output_state`: driven to its idle level, or released to float, per OSSI).

The counter is evaluated lazily from the machine's clock: `sync` brings the flags up to the
current time, and `next_event_ns` tells the machine when the next enabled interrupt is due so
the CPU can sleep until then."""

import ctypes

from qiling.hw.peripheral import QlPeripheral

CR1, CR2, SMCR, DIER, SR, EGR, CCMR1, CCMR2, CCER, CNT, PSC, ARR, RCR = range(0, 0x34, 4)
CCR_BASE, BDTR = 0x34, 0x44
CEN, URS, ARPE = 1 << 0, 1 << 2, 1 << 7
MOE, OSSR, OSSI = 1 << 15, 1 << 11, 1 << 10
BKE, BKP, AOE = 1 << 12, 1 << 13, 1 << 14
UIF = 1
BIF = 1 << 7


class Timer(QlPeripheral):
    class Type(ctypes.Structure):
        _fields_ = [("raw", ctypes.c_uint32 * 21)]

    def __init__(self, ql, label, machine, apb: int, bits: int, advanced: bool = False):
        super().__init__(ql, label)
        self.machine = machine
        self.apb = apb
        self.mask = (1 << bits) - 1
        self.advanced = advanced
        self.regs = {CR1: 0, CR2: 0, SMCR: 0, DIER: 0, SR: 0, CCMR1: 0, CCMR2: 0, CCER: 0, RCR: 0,
                     BDTR: 0}
        self.psc_shadow = 0
        self.psc = 0
        self.arr_shadow = self.mask
        self.arr = self.mask
        self.ccr_shadow = [0, 0, 0, 0]
        self.ccr = [0, 0, 0, 0]
        self.cnt = 0
        # The counter's position is `cnt` at `anchor_ns` plus the ticks since.
        self.anchor_ns = 0
        self.updates = 0
        # Called after every register write (the board watches its output pins with it).
        self.on_write = None
        # The advanced timer's break input (BKIN) as the pin drives it: True = high. Only what
        # reaches the timer: the board routes the pin here while it is in its alternate function.
        self.break_line_high = True
        self.breaks = 0

    # --- time base -------------------------------------------------------------------
    def tick_hz(self) -> float:
        return self.machine.clocks.timer_hz(self.apb) / (self.psc + 1)

    def running(self) -> bool:
        return bool(self.regs[CR1] & CEN)

    def _ticks_between(self, t0_ns: int, t1_ns: int) -> int:
        return int((t1_ns - t0_ns) * self.tick_hz() // 1_000_000_000)

    def _ns_for_ticks(self, ticks: int) -> int:
        # Time at which `ticks` ticks have elapsed since the anchor (rounded up).
        hz = self.tick_hz()
        return self.anchor_ns + int(-(-ticks * 1_000_000_000 // hz))

    def sync(self, now_ns=None):
        """Advances the counter to `now_ns`, raising compare and update flags on the way."""
        now = self.machine.now_ns if now_ns is None else now_ns
        if now <= self.anchor_ns:
            return
        if not self.running():
            self.anchor_ns = now
            return
        ticks = self._ticks_between(self.anchor_ns, now)
        if ticks <= 0:
            return
        t_used = self._ns_for_ticks(ticks)
        while ticks > 0:
            period = self.arr + 1
            to_update = period - self.cnt
            step = min(ticks, to_update)
            self._compare_flags(self.cnt, self.cnt + step)
            if step == to_update:
                self._update_event(from_overflow=True)
                self.cnt = 0
                ticks -= step
                # Many whole periods at once: flags once, counter by modulo.
                whole = ticks // (self.arr + 1)
                if whole:
                    self._compare_flags(0, self.arr + 1)
                    self._update_event(from_overflow=True, times=whole)
                    ticks -= whole * (self.arr + 1)
            else:
                self.cnt += step
                ticks = 0
        self.anchor_ns = t_used

    def _compare_flags(self, start: int, end: int):
        # Counter values start+1 .. end are visited; end == arr+1 stands for the wrap to 0.
        wrapped = end > self.arr
        for ch in range(4):
            if self._capture_mode(ch):
                continue
            c = self.ccr[ch]
            if (start < c < end) or (c == end and not wrapped) or (c == 0 and wrapped):
                self.regs[SR] |= 2 << ch

    def _update_event(self, from_overflow: bool, times: int = 1):
        self.updates += times
        if from_overflow or not self.regs[CR1] & URS:
            self.regs[SR] |= UIF
        self.psc = self.psc_shadow
        self.arr = self.arr_shadow
        for ch in range(4):
            self.ccr[ch] = self.ccr_shadow[ch]

    def _ccmr(self, ch: int) -> int:
        reg = self.regs[CCMR1 if ch < 2 else CCMR2]
        return (reg >> (8 * (ch & 1))) & 0xFF

    def _capture_mode(self, ch: int) -> bool:
        return self._ccmr(ch) & 3 != 0

    def _compare_preload(self, ch: int) -> bool:
        return bool(self._ccmr(ch) & 0x08)

    def next_event_ns(self):
        """When the next enabled interrupt flag will rise, or None."""
        if not self.running():
            return None
        dier = self.regs[DIER]
        sr = self.regs[SR]
        best = None
        period = self.arr + 1
        if dier & UIF and not sr & UIF:
            best = period - self.cnt
        for ch in range(4):
            bit = 2 << ch
            if dier & bit and not sr & bit and not self._capture_mode(ch) and self.ccr[ch] <= self.arr:
                d = (self.ccr[ch] - self.cnt) % period or period
                best = d if best is None else min(best, d)
        if best is None:
            return None
        return self._ns_for_ticks(best)

    def irq_level(self, mask: int) -> bool:
        return bool(self.regs[SR] & self.regs[DIER] & mask)

    # --- capture -----------------------------------------------------------------------
    def capture(self, ch: int, at_ns: int):
        """An input edge on channel `ch` at `at_ns`. A register access in the slice the edge
        fell in may have brought the counter past `at_ns` already: the latched value is still
        the counter at `at_ns`."""
        self.sync(at_ns)
        if not self.running() or not self._capture_mode(ch) or not self.regs[CCER] & (1 << (4 * ch)):
            return
        if self.regs[SR] & (2 << ch):
            self.regs[SR] |= 1 << (9 + ch)
        behind = 0
        if at_ns < self.anchor_ns:
            behind = -(-(self.anchor_ns - at_ns) * self.tick_hz() // 1_000_000_000)
        self.ccr[ch] = int(self.cnt - behind) % (self.arr + 1)
        self.regs[SR] |= 2 << ch

    # --- PWM output --------------------------------------------------------------------
    def pwm_fraction(self, ch: int) -> float:
        """Fraction of each period the channel's output is active (after MOE and CCxE)."""
        self.sync()
        if not self.running() or not self.regs[CCER] & (1 << (4 * ch)):
            return 0.0
        if self.advanced and not self.regs[BDTR] & MOE:
            return 0.0
        mode = (self._ccmr(ch) >> 4) & 7
        high = min(self.ccr[ch], self.arr + 1) / (self.arr + 1)
        frac = {6: high, 7: 1.0 - high, 5: 1.0, 4: 0.0}.get(mode, 0.0)
        if self.regs[CCER] & (2 << (4 * ch)):
            frac = 1.0 - frac
        return frac

    def output_state(self, ch: int) -> str:
        """What the timer does with channel `ch`'s output (RM0383, TIM1's table "Output control
        bits for complementary OCx and OCxN channels with break feature"): "pwm" (switching),
        "low" or "high" (driven steadily), or "released" (not driven by the timer: the pin
        floats unless its GPIO pull holds it).
        - MOE = 0, OSSI = 0: released, whatever CCxE says (the issue's floating PA8/PA9).
        - MOE = 0, OSSI = 1, CCxE or CCxNE set: driven to the idle level OISx (TIMx_CR2).
        - MOE = 1 (or a general-purpose timer), CCxE = 0: released, unless OSSR = 1 and the
          complementary output CCxNE is enabled (then driven inactive, CCxP).
        - MOE = 1, CCxE = 1: OCxREF xor CCxP: the PWM."""
        self.sync()
        ccer = self.regs[CCER] >> (4 * ch)
        cce, ccp, ccne = ccer & 1, ccer & 2, ccer & 4
        bdtr = self.regs[BDTR]
        if self.advanced and not bdtr & MOE:
            if not bdtr & OSSI or not (cce or ccne):
                return "released"
            return "high" if self.regs[CR2] & (1 << (8 + 2 * ch)) else "low"
        if not cce:
            if self.advanced and ccne and bdtr & OSSR:
                return "high" if ccp else "low"
            return "released"
        frac = self.pwm_fraction(ch)
        return "low" if frac == 0.0 else "high" if frac == 1.0 else "pwm"

    # --- break input (RM0383, TIM1 "Using the break function") ---------------------------
    def break_active(self) -> bool:
        bdtr = self.regs[BDTR]
        return bool(self.advanced and bdtr & BKE and self.break_line_high == bool(bdtr & BKP))

    def _apply_break(self):
        """The break acts on the line's level, without the CPU and without the timer's clock:
        MOE is cleared at once (the outputs go to their off state per OSSI) and BIF is set; while
        the break is active MOE cannot be set again (neither by software nor AOE) and BIF cannot
        be cleared."""
        if self.break_active():
            if self.regs[BDTR] & MOE:
                self.breaks += 1
            self.regs[BDTR] &= ~MOE
            self.regs[SR] |= BIF

    def set_break_line(self, high: bool):
        """The break pin's level changed (routed here by the board)."""
        self.break_line_high = high
        self._apply_break()
        if self.on_write is not None:
            self.on_write()

    # --- registers ---------------------------------------------------------------------
    def read(self, offset: int, size: int) -> int:
        self.sync()
        if offset == CNT:
            return self.cnt & self.mask
        if offset == PSC:
            return self.psc_shadow
        if offset == ARR:
            return self.arr_shadow
        if CCR_BASE <= offset < CCR_BASE + 16:
            ch = (offset - CCR_BASE) // 4
            if self._capture_mode(ch):
                self.regs[SR] &= ~(2 << ch)
                return self.ccr[ch]
            return self.ccr_shadow[ch]
        return self.regs.get(offset, 0)

    def write(self, offset: int, size: int, value: int):
        self.sync()
        if offset == SR:
            self.regs[SR] &= value  # rc_w0
        elif offset == EGR:
            if value & 1:
                self.cnt = 0
                self._update_event(from_overflow=False)
                self.anchor_ns = self.machine.now_ns
        elif offset == CNT:
            self.cnt = value & self.mask
            self.anchor_ns = self.machine.now_ns
        elif offset == PSC:
            self.psc_shadow = value & 0xFFFF
        elif offset == ARR:
            self.arr_shadow = value & self.mask
            if not self.regs[CR1] & ARPE:
                self.arr = self.arr_shadow
        elif CCR_BASE <= offset < CCR_BASE + 16:
            ch = (offset - CCR_BASE) // 4
            self.ccr_shadow[ch] = value & self.mask
            if not self._compare_preload(ch):
                self.ccr[ch] = self.ccr_shadow[ch]
        elif offset == CR1:
            was = self.running()
            self.regs[CR1] = value & 0x3FF
            if self.running() and not was:
                self.anchor_ns = self.machine.now_ns
        elif offset in self.regs:
            self.regs[offset] = value
        self._apply_break()
        if self.on_write is not None:
            self.on_write()

    @property
    def region(self):
        return [(0, 0x54)]
