"""The project's plant (`model_core::sim::Plant`, through the plant-ffi C ABI) wired to the
emulated board: it reads TIM1's PWM outputs and the DIR pins (PB12, PB13), steps the physics,
and delivers each sensor edge to TIM2's capture channels at its own time. Its granules drop
when the board's release solenoid (PB5) fires, and the exit light gate's edge goes to TIM2's
channel 3 (PB10) when one reaches the rim."""

import ctypes
import os
from collections import deque

# The plant runs this far ahead of the CPU: one physics step (a quarter control period).
STEP_S = 0.00025
STEP_NS = 250_000
PLANT_TIMER_HZ = 1_000_000
DIR_PINS = (12, 13)
# GPIOB pin of the release solenoid driver.
SOLENOID_PIN = 5
# GPIOB pin of the motor supply switch's enable (high = closed; its pull-down opens it).
SUPPLY_PIN = 14
# TIM2 channel index of the exit light gate (CH3, PB10).
EXIT_GATE_CHANNEL = 2


class RigParams(ctypes.Structure):
    _fields_ = [
        ("supply_v", ctypes.c_float),
        ("coupling", ctypes.c_float),
        ("timer_hz", ctypes.c_uint32),
        ("pulses_per_rev", ctypes.c_uint16 * 2),
        ("tooth_error", ctypes.c_float * 2),
        ("jitter_s", ctypes.c_float * 2),
        ("ripple_nm", ctypes.c_float * 2),
    ]


def load_library(path: str):
    lib = ctypes.CDLL(path)
    lib.plant_params_nominal.argtypes = [ctypes.POINTER(RigParams)]
    lib.plant_new.argtypes = [ctypes.POINTER(RigParams), ctypes.c_uint32]
    lib.plant_new.restype = ctypes.c_void_p
    lib.plant_new_from_rig_file.argtypes = [ctypes.c_char_p, ctypes.c_uint32, ctypes.c_char_p,
                                            ctypes.c_uint32]
    lib.plant_new_from_rig_file.restype = ctypes.c_void_p
    lib.plant_free.argtypes = [ctypes.c_void_p]
    lib.plant_advance.argtypes = [ctypes.c_void_p, ctypes.c_float, ctypes.c_float, ctypes.c_float]
    lib.plant_edges.argtypes = [ctypes.c_void_p, ctypes.c_uint32, ctypes.POINTER(ctypes.c_uint32),
                                ctypes.c_uint32]
    lib.plant_speed_rad_s.argtypes = [ctypes.c_void_p, ctypes.c_uint32]
    lib.plant_speed_rad_s.restype = ctypes.c_float
    lib.plant_inject.argtypes = [ctypes.c_void_p, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_float]
    lib.plant_current_a.argtypes = [ctypes.c_void_p, ctypes.c_uint32]
    lib.plant_current_a.restype = ctypes.c_float
    lib.plant_set_supply.argtypes = [ctypes.c_void_p, ctypes.c_uint32]
    lib.plant_release.argtypes = [ctypes.c_void_p, ctypes.c_uint32]
    lib.plant_exit.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint32)]
    return lib


class RigFileError(ValueError):
    """A rig file the plant library refused; the message names the file, line, key and range."""


class RigPlant:
    def __init__(self, library_path: str, seed: int = 1, rig_file=None):
        """The nominal rig, or the rig a rig file describes (docs/rigs/*.toml; its seed then
        comes from the file)."""
        self.lib = load_library(library_path)
        if rig_file is None:
            params = RigParams()
            if self.lib.plant_params_nominal(ctypes.byref(params)) != 0:
                raise RuntimeError("plant_params_nominal failed")
            params.timer_hz = PLANT_TIMER_HZ
            self.handle = self.lib.plant_new(ctypes.byref(params), seed)
            if not self.handle:
                raise RuntimeError("plant_new failed")
        else:
            message = ctypes.create_string_buffer(1024)
            self.handle = self.lib.plant_new_from_rig_file(os.fsencode(rig_file), PLANT_TIMER_HZ,
                                                           message, len(message))
            if not self.handle:
                raise RigFileError(message.value.decode(errors="replace"))
        self.time_ns = 0
        self.edges = deque()  # (time_ns, axis)
        self.buf = (ctypes.c_uint32 * 64)()
        self.duties = (0.0, 0.0)
        self.exit_us = ctypes.c_uint32(0)
        # (release time ns, exit gate time ns or None) of each granule, for the tests.
        self.granules = []
        # The supply switch as the plant last saw it (open until the board closes it).
        self.supply_on = True
        self.lib.plant_set_supply(self.handle, 1)

    def duties_from_board(self, tim1, gpiob):
        """Each bridge's duty from its PWM and DIR pins. The motor supply switch (PB14, an
        output driven high to close it) goes to the plant's own supply cut: with it open no
        bridge drives, whatever its inputs say or however it failed."""
        duties = []
        odr = gpiob.instance.ODR if gpiob is not None else 0
        supply = gpiob is not None and ((gpiob.instance.MODER >> (2 * SUPPLY_PIN)) & 3) == 1 \
            and bool((odr >> SUPPLY_PIN) & 1)
        if supply != self.supply_on:
            self.supply_on = supply
            self.lib.plant_set_supply(self.handle, int(supply))
        for axis in (0, 1):
            frac = tim1.pwm_fraction(axis) if tim1 is not None else 0.0
            reverse = (odr >> DIR_PINS[axis]) & 1
            duties.append(-frac if reverse else frac)
        return tuple(duties)

    @staticmethod
    def _unwrap_us(ticks: int, start_us: int) -> int:
        # A 32-bit microsecond stamp, unwrapped against the step's start.
        us = start_us + ((ticks - start_us) & 0xFFFF_FFFF)
        if us - start_us > 0x8000_0000:
            us -= 1 << 32
        return us

    def step(self, tim1, gpiob):
        """One physics step from `time_ns` with the board's present outputs held."""
        self.duties = self.duties_from_board(tim1, gpiob)
        start_us = self.time_ns // 1000
        self.lib.plant_advance(self.handle, self.duties[0], self.duties[1], STEP_S)
        for axis in (0, 1):
            n = self.lib.plant_edges(self.handle, axis, self.buf, 64)
            for k in range(max(n, 0)):
                self.edges.append((self._unwrap_us(self.buf[k], start_us) * 1000, axis))
        if self.lib.plant_exit(self.handle, ctypes.byref(self.exit_us)) == 1:
            at_ns = self._unwrap_us(self.exit_us.value, start_us) * 1000
            self.edges.append((at_ns, EXIT_GATE_CHANNEL))
            if self.granules and self.granules[-1][1] is None:
                self.granules[-1] = (self.granules[-1][0], at_ns)
        self.edges = deque(sorted(self.edges))
        self.time_ns += STEP_NS

    def release(self, at_ns: int):
        """The release solenoid fired at `at_ns`: a granule drops at the start radius."""
        if self.lib.plant_release(self.handle, (at_ns // 1000) & 0xFFFF_FFFF) != 0:
            raise RuntimeError("plant_release refused")
        self.granules.append((at_ns, None))

    def speed_rad_s(self, axis: int) -> float:
        return self.lib.plant_speed_rad_s(self.handle, axis)

    def current_a(self, axis: int) -> float:
        return self.lib.plant_current_a(self.handle, axis)

    def _inject(self, axis: int, kind: int, from_s: float):
        if self.lib.plant_inject(self.handle, axis, kind, from_s) != 0:
            raise RuntimeError(f"plant_inject({axis}, {kind}) refused")

    def block_shaft(self, axis: int, from_s: float):
        self._inject(axis, 0, from_s)

    def kill_sensor(self, axis: int, from_s: float):
        self._inject(axis, 1, from_s)

    def stick_bridge(self, axis: int, from_s: float):
        """The bridge stuck on: any nonzero duty drives at full duty (a shorted driver input)."""
        self._inject(axis, 2, from_s)

    def short_bridge(self, axis: int, from_s: float):
        """A shorted bridge: full duty even at zero duty; only the supply switch stops it."""
        self._inject(axis, 3, from_s)

    def next_event_ns(self):
        t = self.time_ns
        if self.edges:
            t = min(t, self.edges[0][0])
        return t

    def close(self):
        if self.handle:
            self.lib.plant_free(self.handle)
            self.handle = None
