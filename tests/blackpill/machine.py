"""The emulated STM32F411 Black Pill: the exact release ELF on qiling's Cortex-M4 (unicorn)
with the peripheral models of this directory, one virtual clock, and resets (pin, software,
watchdog, power cut) that keep what survives on a real board (flash always; RAM, and so the
`.uninit` reset counter, except on a power cut).

Time: the CPU runs in slices of at most SLICE_NS (as many instructions as SYSCLK gives, one
per cycle); register accesses see the slice's start time, and interrupts raised during a slice
are taken at its end, so an interrupt's latency is at most one slice. A slice cut short (WFE,
a reset) is charged in full: unicorn cannot say how many instructions ran. At the executor's WFE (unicorn 2.0.1 rejects the instruction: it is hooked
and skipped) with nothing pending, the clock jumps to the next peripheral or plant event."""

import copy
import os
import time

from qiling import Qiling
from qiling.const import QL_ARCH, QL_INTERCEPT, QL_OS, QL_VERBOSE
from qiling.extensions.mcu.stm32f4 import stm32f411
from unicorn import UC_HOOK_CODE, UcError
from unicorn.arm_const import UC_ARM_REG_FPSCR, UC_ARM_REG_S0

from adc import Adc, AdcCommon
from clock_tree import HSE_HZ, ClockTree
from dma import Dma
from exti import Exti
from flash import BACKED_BASE, BACKED_SIZE, FlashInterface, FlashStore
from iwdg import LSI_HZ, Iwdg
from nvic import Nvic
from pins import PwmPinWatch
from plant import DIR_PINS, SOLENOID_PIN, SUPPLY_PIN
from rtt import RttReader
from timers import BIF, Timer
from usart import Usart

SLICE_NS = 20_000
# memory.x allows the image sectors 0..5 (256 KiB); tests/run holds it to 96 KiB, inside
# sectors 0..4 (128 KiB), so sector 5 can sit behind the flash model with 6 and 7.
CODE_FLASH_SIZE = BACKED_BASE - 0x0800_0000

IRQ_TIM1_BRK, IRQ_TIM1_UP, IRQ_TIM1_CC, IRQ_TIM2, IRQ_TIM5 = 24, 25, 27, 28, 50
IRQ_EXTI0 = 6
IRQ_ADC = 18
# The current-sense amplifiers (docs/wiring.md: INA240A1, 20 V/V, on a 10 mOhm shunt, zero at
# mid-supply): volts at PB0 (ADC1_IN8, precession) and PB1 (IN9, spin) for a motor current.
SENSE_ZERO_V, SENSE_V_PER_A, SENSE_CHANNELS = 1.65, 0.2, (8, 9)
# The release push button: PA0 (the Black Pill's KEY), active low.
BUTTON_PORT, BUTTON_PIN = "a", 0
IRQ_USART2 = 38
IRQ_DMA1_STREAM = {5: 16, 6: 17}
# DMA1 requests (RM0383 table 27): (stream, channel) -> (peripheral label, direction).
DMA1_ROUTES = {(5, 4): ("usart2", "rx"), (6, 4): ("usart2", "tx")}

THUMB_WFE, THUMB_SEV = b"\x20\xbf", b"\x40\xbf"
# The Black Pill's blue LED: PC13, lit when low.
LED_PIN = 13
# RCC_CR's crystal ready flag (RM0383 6.3.1).
HSERDY = 1 << 17
DIR_MASK = sum(1 << pin for pin in DIR_PINS)
# TIM1's break input: PA6 in alternate function 1 (docs/wiring.md), active low on the rig.
BKIN_PIN, AF_TIM1 = 6, 1

# RCC_CSR reset flags (RM0383 6.3.21).
CSR_FLAGS = {
    "power": (1 << 27) | (1 << 26) | (1 << 25),  # POR, PIN, BOR
    "pin": 1 << 26,
    "software": (1 << 28) | (1 << 26),
    "watchdog": (1 << 29) | (1 << 26),
}


class EmulationError(RuntimeError):
    pass


def _board_env():
    env = copy.deepcopy(stm32f411)
    env["FLASH"]["size"] = CODE_FLASH_SIZE
    env["REMAP"]["kwargs"]["size"] = CODE_FLASH_SIZE
    env["REMAP REGION"]["size"] = CODE_FLASH_SIZE
    del env["NVIC"]
    return env


def _find_opcodes(elf_path: str, opcode: bytes):
    """Addresses of a 16-bit Thumb opcode in the image's executable sections."""
    from elftools.elf.elffile import ELFFile
    found = []
    with open(elf_path, "rb") as f:
        elf = ELFFile(f)
        for sec in elf.iter_sections():
            if sec["sh_flags"] & 0x4 and sec["sh_type"] == "SHT_PROGBITS":
                data = sec.data()
                base = sec["sh_addr"]
                for off in range(0, len(data) - 1, 2):
                    if data[off:off + 2] == opcode:
                        found.append(base + off)
    return found


def _it_blocks_split_by_a_page(elf_path: str):
    """The Thumb IT instructions of the image whose block reaches into the next 1 KiB page.

    unicorn 2.0.1 (QEMU's translator) ends a translation block at a 1 KiB page boundary, so such
    an IT block is split between two blocks; when an instruction count ends a slice there, the
    emulation resumes inside the IT block with one of its instructions executed twice (seen:
    `it hi; addhi.w r0, r0, #0x20000` across 0x...c00 added twice, a parameter-flash read out
    of bounds at boot; unicorn issue #853 is the same family). The harness stops before each of
    these IT instructions and runs the block on its own ([`Machine.step`])."""
    from elftools.elf.elffile import ELFFile
    sites = {}
    with open(elf_path, "rb") as f:
        elf = ELFFile(f)
        for sec in elf.iter_sections():
            if not (sec["sh_flags"] & 0x4 and sec["sh_type"] == "SHT_PROGBITS"):
                continue
            data, base = sec.data(), sec["sh_addr"]
            for off in range(0, len(data) - 1, 2):
                mask = data[off] & 0x0F
                if data[off + 1] != 0xBF or not mask:
                    continue
                # Instructions in the block: 4 minus the trailing zeros of the mask.
                count = 4 - (mask & -mask).bit_length() + 1
                at = off + 2
                for _ in range(count):
                    if at + 1 >= len(data):
                        break
                    first = data[at] | data[at + 1] << 8
                    at += 4 if first >= 0xE800 else 2
                start = base + off
                if (start >> 10) != ((base + at - 1) >> 10):
                    sites[start] = count
    return sites


class Board:
    """One boot of the MCU: a fresh core and peripherals on the machine's clock."""

    def __init__(self, machine, reset_kind: str, ram: bytes = None):
        m = machine
        self.m = m
        ql = Qiling([m.elf], archtype=QL_ARCH.CORTEX_M, ostype=QL_OS.MCU, env=_board_env(),
                    verbose=QL_VERBOSE.DISABLED)
        self.ql = ql
        self.uc = ql.uc
        for label in ("rcc", "pwr", "gpioa", "gpiob", "gpioc", "syscfg", "dbgmcu"):
            ql.hw.create(label)
        self.rcc = ql.hw.rcc
        self.clocks = ClockTree(self.rcc, m.hse_hz)
        self.rcc.instance.CSR = (self.rcc.instance.CSR & 0x00FF_FFFF) | CSR_FLAGS[reset_kind]
        self.gpiob = ql.hw.gpiob

        def add(label, entity, base):
            ql.hw.entity[label] = entity
            ql.hw.region[label] = [(lo + base, hi + base) for lo, hi in entity.region]
            return entity

        self.nvic = add("nvic", Nvic(ql, "nvic", m), 0xE000E100)
        self.tim1 = add("tim1", Timer(ql, "tim1", m, apb=2, bits=16, advanced=True), 0x4001_0000)
        self.tim2 = add("tim2", Timer(ql, "tim2", m, apb=1, bits=32), 0x4000_0000)
        self.tim5 = add("tim5", Timer(ql, "tim5", m, apb=1, bits=32), 0x4000_0C00)
        self.usart2 = add("usart2", Usart(ql, "usart2", m, apb=1, transmit=m.link_out), 0x4000_4400)
        self.dma1 = add("dma1", Dma(ql, "dma1", m), 0x4002_6000)
        self.iwdg = add("iwdg", Iwdg(ql, "iwdg", m), 0x4000_3000)
        self.flash = add("flash", FlashInterface(ql, "flash", m, m.store), 0x4002_3C00)
        self.exti = add("exti", Exti(ql, "exti", ql.hw.syscfg), 0x4001_3C00)
        self.adc1 = add("adc1", Adc(ql, "adc1", self.tim1), 0x4001_2000)
        self.adc_common = add("adc_common", AdcCommon(ql, "adc_common"), 0x4001_2300)
        for axis, channel in enumerate(SENSE_CHANNELS):
            self.adc1.inputs[channel] = lambda a=axis: self.sense_volts(a)
        self.timers = (self.tim1, self.tim2, self.tim5)
        self.clocked = (self.tim1, self.tim2, self.tim5, self.usart2, self.iwdg)
        self.stepping = [e for k, e in ql.hw.stepable.items() if k in ("rcc", "pwr")]

        self.nvic.connect(IRQ_TIM1_BRK, lambda: self.tim1.irq_level(BIF))
        self.nvic.connect(IRQ_TIM1_UP, lambda: self.tim1.irq_level(0x01))
        self.nvic.connect(IRQ_TIM1_CC, lambda: self.tim1.irq_level(0x1E))
        self.nvic.connect(IRQ_TIM2, lambda: self.tim2.irq_level(0x1F))
        self.nvic.connect(IRQ_TIM5, lambda: self.tim5.irq_level(0x1F))
        self.nvic.connect(IRQ_USART2, self.usart2.irq_level)
        self.nvic.connect(IRQ_EXTI0, lambda: self.exti.irq_level(1 << BUTTON_PIN))
        self.nvic.connect(IRQ_ADC, self.adc1.irq_level)
        for stream, irq in IRQ_DMA1_STREAM.items():
            self.nvic.connect(irq, lambda s=stream: self.dma1.irq_level(s))

        ql.mem.map_mmio(BACKED_BASE, BACKED_SIZE, self._flash_read, self._flash_write,
                        info="[param flash]")
        scb = ql.hw.scb
        scb.hook_write(self._scb_write)
        self.dir_pins = self.gpiob.instance.ODR & DIR_MASK
        self.solenoid_on = False
        # The motor supply switch's enable (PB14): off in reset (its pull-down).
        self.supply_on = False
        self.gpiob.hook_write(self._gpiob_written, intercept=QL_INTERCEPT.EXIT)
        # The PWM pins after every write that can change them (GPIOA's mode, TIM1's outputs).
        self.pwm_pins = PwmPinWatch(m, ql.hw.gpioa, self.tim1)
        ql.hw.gpioa.hook_write(self._gpioa_written, intercept=QL_INTERCEPT.EXIT)
        self.route_break_line()
        self.tim1.on_write = self.pwm_pins.check
        # The status LED on PC13 (active low): each change, as (time ns, lit).
        self.led_lit = False
        ql.hw.gpioc.hook_write(self._gpioc_written, intercept=QL_INTERCEPT.EXIT)

        for addr in m.split_it_sites:
            self.uc.hook_add(UC_HOOK_CODE, self._on_split_it, begin=addr, end=addr)
        # The IT instruction the CPU was stopped before (it runs next, on its own), and the one
        # whose hook lets it pass once.
        self.at_split_it = None
        self.split_it_pass = None
        for addr in m.wfe_sites:
            self.uc.hook_add(UC_HOOK_CODE, self._on_wfe, begin=addr, end=addr)
        for addr in m.sev_sites:
            self.uc.hook_add(UC_HOOK_CODE, self._on_sev, begin=addr, end=addr)
        if ram is not None:
            ql.mem.write(0x2000_0000, ram)
        # Vector table at the start of flash.
        ql.arch.regs.msp = ql.mem.read_ptr(0x0800_0000)
        ql.arch.regs.pc = ql.mem.read_ptr(0x0800_0004)
        self.event = False
        self.sleeping = False
        self.at_wfe = None
        self.in_isr = False

    def sense_volts(self, axis: int) -> float:
        """The amplifier's output for the plant's motor current (rails at 0 and 3.3 V); 0 V
        without a plant (nothing connected)."""
        if self.m.plant is None:
            return 0.0
        v = SENSE_ZERO_V + SENSE_V_PER_A * self.m.plant.current_a(axis)
        return max(0.0, min(3.3, v))

    # --- hooks -------------------------------------------------------------------------
    def _flash_read(self, ql, offset, size):
        return self.m.store.read(offset, size)

    def _flash_write(self, ql, offset, size, value):
        self.flash.program(BACKED_BASE + offset, size, value)

    def _scb_write(self, scb, access, offset, size, value):
        # AIRCR with VECTKEY and SYSRESETREQ: a software reset (the panic path).
        if offset == 0x0C and (value >> 16) == 0x05FA and value & 4:
            self.m.request_reset("software")

    def _gpioa_written(self, *args):
        self.route_break_line()
        self.pwm_pins.check()

    def route_break_line(self):
        """PA6's level (the rig's break line: pulled up, pulled low by a comparator or a
        driver fault) in GPIOA's input register and, while PA6 is in alternate function 1, at
        TIM1's break input. Elsewhere the timer's input reads the inactive (high) level: the
        firmware enables the break only after routing the pin."""
        g = self.ql.hw.gpioa.instance
        high = not self.m.break_line_low
        g.IDR = (g.IDR & ~(1 << BKIN_PIN)) | (int(high) << BKIN_PIN)
        routed = ((g.MODER >> (2 * BKIN_PIN)) & 3) == 2 and \
            ((g.AFRL >> (4 * BKIN_PIN)) & 0xF) == AF_TIM1
        level = high if routed else True
        if level != self.tim1.break_line_high:
            self.tim1.set_break_line(level)

    def _gpiob_written(self, gpio, access, offset, size, value):
        # A DIR pin that turns while its PWM channel still drives the bridge drives the new
        # direction with the old duty: the harness records every such moment.
        out_mode = ((gpio.instance.MODER >> (2 * SUPPLY_PIN)) & 3) == 1
        supply = out_mode and bool(gpio.instance.ODR & (1 << SUPPLY_PIN))
        if supply != self.supply_on:
            self.supply_on = supply
            self.m.supply_changes.append((self.m.now_ns, supply))
        solenoid = bool(gpio.instance.ODR & (1 << SOLENOID_PIN))
        if solenoid != self.solenoid_on:
            self.solenoid_on = solenoid
            self.m.solenoid_changed(solenoid)
        pins = gpio.instance.ODR & DIR_MASK
        changed = pins ^ self.dir_pins
        self.dir_pins = pins
        for axis, pin in enumerate(DIR_PINS):
            if changed & (1 << pin):
                self.m.dir_changes += 1
            if changed & (1 << pin) and self.tim1.pwm_fraction(axis) > 0.0:
                self.m.dir_violations.append((self.m.now_ns, axis, self.tim1.pwm_fraction(axis)))

    def _gpioc_written(self, gpio, access, offset, size, value):
        lit = not gpio.instance.ODR & (1 << LED_PIN)
        if lit != self.led_lit:
            self.led_lit = lit
            self.m.led_changes.append((self.m.now_ns, lit))

    def _on_wfe(self, uc, address, size, user_data):
        # Stop before the instruction (unicorn 2.0.1 would fault on it); `resume_after_wfe`
        # steps over it.
        self.at_wfe = address
        uc.emu_stop()

    def _on_split_it(self, uc, address, size, user_data):
        # Inside an interrupt handler qiling runs the handler to its end in one call: no slice
        # ends there, nothing to guard (and a stop would cut the handler short).
        if self.in_isr:
            return
        if self.split_it_pass == address:
            self.split_it_pass = None
            return
        self.at_split_it = address
        uc.emu_stop()

    def resume_after_wfe(self):
        """At a WFE: skip it; sleep unless an event (SEV, an interrupt) is latched."""
        self.ql.arch.regs.pc = self.at_wfe + 2
        self.at_wfe = None
        if self.event:
            self.event = False
        else:
            self.sleeping = True

    def _on_sev(self, uc, address, size, user_data):
        self.event = True

    # --- interrupts --------------------------------------------------------------------
    def take_interrupt(self) -> bool:
        regs = self.ql.arch.regs
        if regs.primask & 1 or regs.ipsr > 1:
            return False
        irq = self.nvic.next_irq()
        if irq is None:
            return False
        basepri = regs.basepri & 0xF0
        if basepri and basepri <= self.nvic.priority[irq]:
            return False
        self.nvic.taken(irq)
        # The exception frame qiling pushes holds the integer registers only; keep the
        # caller-saved FPU registers as the hardware's lazy stacking would.
        fpu = [self.uc.reg_read(UC_ARM_REG_S0 + i) for i in range(16)]
        fpscr = self.uc.reg_read(UC_ARM_REG_FPSCR)
        self.in_isr = True
        try:
            self.ql.arch.interrupt_handler(self.ql, irq)
        finally:
            self.in_isr = False
        for i, v in enumerate(fpu):
            self.uc.reg_write(UC_ARM_REG_S0 + i, v)
        self.uc.reg_write(UC_ARM_REG_FPSCR, fpscr)
        self.event = True
        self.m.interrupts += 1
        return True

    def sync_peripherals(self):
        for p in self.clocked:
            p.sync()
        for p in self.stepping:
            p.step()
        if not self.m.hse_hz:
            # No crystal on this board: qiling's RCC sets HSERDY with HSEON; a dead oscillator
            # never does.
            self.rcc.instance.CR &= ~HSERDY

    def next_event_ns(self):
        times = [t for t in (p.next_event_ns() for p in self.clocked) if t is not None]
        return min(times) if times else None


class Machine:
    def __init__(self, elf: str, flash_path: str, plant=None, link=None, defmt_print=None,
                 log_dir=None, realtime=False, hse_hz=HSE_HZ, lsi_hz=LSI_HZ,
                 flash_timing="typical"):
        self.elf = elf
        # The crystal on the emulated board (the Black Pill's is 25 MHz; 0: none, or dead).
        self.hse_hz = hse_hz
        # The LSI's frequency (iwdg.py: 17 to 47 kHz on silicon) and the flash's durations
        # ("typical" or "max": flash.py).
        self.lsi_hz = lsi_hz
        self.flash_timing = flash_timing
        self.store = FlashStore(flash_path)
        self.plant = plant
        self.link = link
        self.realtime = realtime
        self.now_ns = 0
        self.wfe_sites = _find_opcodes(elf, THUMB_WFE)
        self.sev_sites = _find_opcodes(elf, THUMB_SEV)
        self.split_it_sites = _it_blocks_split_by_a_page(elf)
        self.split_it_runs = 0
        self.reset_request = None
        self.power_cut = False
        self.in_dma = False
        self.held = None  # (every_ns, hold_ns, next_ns): the CPU held periodically
        self.dir_violations = []
        # Each moment a PWM pin that TIM1 drove was left floating: (time ns, axis, state).
        self.pwm_pin_floats = []
        # The status LED's changes (time ns, lit), across resets.
        self.led_changes = []
        # The break line PA6 pulled low from outside (a comparator, a driver fault), and the
        # motor supply switch's changes (time ns, closed), across resets.
        self.break_line_low = False
        self.supply_changes = []
        self.dir_changes = 0
        self.resets = []
        self.interrupts = 0
        self.slices = 0
        self.tx_bytes = bytearray()
        # Input changes from outside the board (the release button): sorted (time ns, action).
        self.inputs = []
        # Each release solenoid pulse: [on ns, off ns or None].
        self.solenoid_pulses = []
        self.rtt = None
        if defmt_print and log_dir:
            os.makedirs(log_dir, exist_ok=True)
            self.rtt = RttReader(elf, defmt_print, os.path.join(log_dir, "blackpill-defmt.log"))
        self.board = Board(self, "power")
        self.wall0 = time.monotonic()
        self.next_poll_ns = 0

    # --- called by peripherals ----------------------------------------------------------
    @property
    def clocks(self):
        return self.board.clocks

    def service_dma(self):
        """Serves active DMA requests (not re-entered: a transfer's own register access
        must not start the next transfer before the stream has counted this one)."""
        b = getattr(self, "board", None)
        if b is None or self.in_dma:
            return
        self.in_dma = True
        try:
            self._serve_dma_requests(b)
        finally:
            self.in_dma = False

    def _serve_dma_requests(self, b):
        for (stream, channel), (label, kind) in DMA1_ROUTES.items():
            s = b.dma1.streams[stream]
            periph = b.ql.hw.entity[label]
            guard = 0
            while s.enabled and s.chsel == channel and periph.dma_request(kind) and guard < 4:
                b.dma1.transfer_one(stream, periph)
                guard += 1

    def link_out(self, byte: int):
        self.tx_bytes.append(byte)
        if self.link is not None:
            self.link.send(bytes([byte]))

    def solenoid_changed(self, on: bool):
        """PB5 changed: a rising edge energises the release solenoid and drops a granule."""
        if on:
            self.solenoid_pulses.append([self.now_ns, None])
            if self.plant is not None:
                self.plant.release(self.now_ns)
        elif self.solenoid_pulses:
            self.solenoid_pulses[-1][1] = self.now_ns

    def press_button(self, at_ns: int, bounces_ns=()):
        """The release button pressed at `at_ns` (PA0 falls), its contacts bouncing open and
        shut again at each of `at_ns + bounces_ns[k]`, then released 200 ms later."""
        board_edge = lambda falling: lambda b: b.exti.pin_edge(BUTTON_PORT, BUTTON_PIN,
                                                               rising=not falling)
        self.inputs.append((at_ns, board_edge(True)))
        for d in bounces_ns:
            self.inputs.append((at_ns + d - 1000, board_edge(False)))
            self.inputs.append((at_ns + d, board_edge(True)))
        self.inputs.append((at_ns + 200_000_000, board_edge(False)))
        self.inputs.sort(key=lambda e: e[0])

    def pull_break_line(self, low: bool):
        """An over-current comparator or a driver's fault output pulls PA6 low (or lets go)."""
        self.break_line_low = low
        self.board.route_break_line()

    def request_reset(self, kind: str):
        self.reset_request = kind
        b = getattr(self, "board", None)
        if b is not None:
            b.uc.emu_stop()

    def cut_power(self):
        """The supply is gone: the CPU stops here; the next step powers the board up again."""
        self.power_cut = True
        b = getattr(self, "board", None)
        if b is not None:
            b.uc.emu_stop()

    def hold_cpu_periodically(self, every_s: float, hold_s: float):
        """From now on, stop the CPU for `hold_s` every `every_s` (as an interrupt storm or a
        runaway flash operation would): control ticks end late while they still advance."""
        self.held = (int(every_s * 1e9), int(hold_s * 1e9), self.now_ns)

    def stall(self, ns: int):
        """The CPU is stopped for `ns` (a flash operation) while the peripherals run on."""
        end = self.now_ns + ns
        while self.now_ns < end and self.reset_request is None:
            nxt = self._next_event_ns()
            self.now_ns = end if nxt is None else max(self.now_ns, min(nxt, end))
            self._process_events()

    # --- host side -----------------------------------------------------------------------
    def send(self, data: bytes):
        self.board.usart2.receive(data)

    def reset(self, kind: str):
        """Resets the MCU; a power cut also loses RAM."""
        self.store.flush()
        ram = None
        if kind != "power":
            ram = bytes(self.board.ql.mem.read(0x2000_0000, 0x2_0000))
        self.resets.append((self.now_ns, kind))
        self.board = Board(self, kind, ram)
        self.reset_request = None
        self.power_cut = False

    # --- the loop ------------------------------------------------------------------------
    def _next_event_ns(self):
        t = self.board.next_event_ns()
        if self.inputs:
            t = self.inputs[0][0] if t is None else min(t, self.inputs[0][0])
        if self.plant is not None:
            p = self.plant.next_event_ns()
            t = p if t is None else min(t, p)
        return t

    def _process_events(self):
        b = self.board
        while self.inputs and self.inputs[0][0] <= self.now_ns:
            _, action = self.inputs.pop(0)
            action(b)
        if self.plant is not None:
            while self.plant.edges and self.plant.edges[0][0] <= self.now_ns:
                at, axis = self.plant.edges.popleft()
                b.tim2.capture(axis, at)
            while self.plant.time_ns <= self.now_ns:
                self.plant.step(b.tim1, b.gpiob)
                b.adc1.plant_stepped()
        b.sync_peripherals()

    def _poll_host(self):
        if self.rtt is not None:
            self.rtt.poll(self.board.ql.mem)
        if self.link is not None:
            data = self.link.receive()
            if data:
                self.send(data)
        if self.realtime:
            ahead = self.now_ns / 1e9 - (time.monotonic() - self.wall0)
            if ahead > 0.002:
                time.sleep(ahead)

    def run_for(self, seconds: float, until=None):
        """Runs `seconds` of emulated time (or until `until()` is true)."""
        end = self.now_ns + int(seconds * 1e9)
        while self.now_ns < end:
            if until is not None and until():
                return True
            self.step(end)
        return False

    def step(self, horizon_ns: int):
        b = self.board
        if self.reset_request is not None or self.power_cut:
            self.reset("power" if self.power_cut else self.reset_request)
            return
        if self.now_ns >= self.next_poll_ns:
            self._poll_host()
            self.next_poll_ns = self.now_ns + 1_000_000
        if self.held is not None and self.now_ns >= self.held[2]:
            every, hold, at = self.held
            self.held = (every, hold, at + every)
            self.stall(hold)
            return
        if b.take_interrupt():
            return
        nxt = self._next_event_ns()
        if b.sleeping:
            b.sleeping = False
            target = horizon_ns if nxt is None else min(nxt, horizon_ns)
            if self.realtime:
                target = min(target, self.next_poll_ns)
            self.now_ns = max(self.now_ns, target)
            self._process_events()
            return
        limit = self.now_ns + SLICE_NS
        if nxt is not None:
            limit = min(limit, max(nxt, self.now_ns + 100))
        count = max(1, int((limit - self.now_ns) * self.clocks.sysclk_hz() / 1e9))
        pc = b.ql.arch.regs.pc
        if b.at_split_it == pc:
            # An IT block split by a page boundary: the IT instruction (counted), its block (not
            # counted by unicorn) and the next instruction, in one run that cannot end inside it.
            b.at_split_it = None
            b.split_it_pass = pc
            count = 2
            self.split_it_runs += 1
        try:
            b.uc.emu_start(pc | 1, 0, 0, count)
        except UcError as e:
            raise EmulationError(f"CPU fault at pc {b.ql.arch.regs.pc:#010x}: {e}") from e
        self.slices += 1
        if b.at_wfe is not None:
            b.resume_after_wfe()
        self.now_ns = limit
        self._process_events()

    def close(self):
        self.store.flush()
        if self.rtt is not None:
            self.rtt.poll(self.board.ql.mem)
            self.rtt.close()
        if self.plant is not None:
            self.plant.close()
