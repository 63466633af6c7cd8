"""The motor PWM pins PA8 (TIM1_CH1) and PA9 (TIM1_CH2) as a scope would see them: which of
GPIOA's modes (RM0383 section 8, MODER/AFRH/PUPDR/ODR) and, in alternate function 1, what
TIM1 does with the output (`Timer.output_state`: driven, or released by MOE = 0 with OSSI = 0).

`PwmPinWatch` records every moment a pin that TIM1 had been driving is left floating: on the
real board only the bridge's 10 k pull-down would then hold the motor off."""

# Axis -> GPIOA pin: precession PA8, spin PA9 (firmware/src/blackpill/mod.rs).
PWM_PINS = (8, 9)
AF_TIM1 = 1
DRIVEN = ("low", "high", "pwm")


def pwm_pin_state(gpioa, tim1, axis: int) -> str:
    """"low", "high", "pwm", "floating", "pulled-up" or "pulled-down" (a weak GPIO pull, not
    driven) for the axis's PWM pin."""
    g = gpioa.instance
    pin = PWM_PINS[axis]
    mode = (g.MODER >> (2 * pin)) & 3
    if mode == 1:  # general-purpose output
        return "high" if (g.ODR >> pin) & 1 else "low"
    if mode == 2 and (g.AFRH >> (4 * (pin - 8))) & 0xF == AF_TIM1:
        state = tim1.output_state(axis)
        if state != "released":
            return state
    # Input, analog, another alternate function, or TIM1 released the output.
    pull = (g.PUPDR >> (2 * pin)) & 3
    return {1: "pulled-up", 2: "pulled-down"}.get(pull, "floating")


class PwmPinWatch:
    """Checks both PWM pins after every TIM1 and GPIOA write of one boot. A pin counts from the
    first moment TIM1 drives it; between reset and then the pull-downs' job is documented
    (docs/wiring.md) and not what this watch is for."""

    def __init__(self, machine, gpioa, tim1):
        self.m = machine
        self.gpioa = gpioa
        self.tim1 = tim1
        self.driven = [False, False]
        self.states = ["floating", "floating"]

    def check(self, *_):
        for axis in (0, 1):
            state = pwm_pin_state(self.gpioa, self.tim1, axis)
            if state in DRIVEN:
                self.driven[axis] = True
            elif self.driven[axis] and self.states[axis] in DRIVEN:
                # Recorded once per let-go, with the time and what the pin does now.
                self.m.pwm_pin_floats.append((self.m.now_ns, axis, state))
            self.states[axis] = state
