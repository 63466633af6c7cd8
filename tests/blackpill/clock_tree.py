"""STM32F411 clock tree read from the emulated RCC registers (RM0383 section 6).

Every timer, the USART's baud rate and the instruction clock are derived here, never
hard-wired, so a firmware that programs the PLL wrongly runs visibly wrong in emulation."""

HSI_HZ = 16_000_000
# The Black Pill's crystal.
HSE_HZ = 25_000_000

_AHB_DIV = {8: 2, 9: 4, 10: 8, 11: 16, 12: 64, 13: 128, 14: 256, 15: 512}
_APB_DIV = {4: 2, 5: 4, 6: 8, 7: 16}


class ClockTree:
    """Reads RCC_CR/PLLCFGR/CFGR on each query (they change during `embassy_stm32::init`)."""

    def __init__(self, rcc, hse_hz: float = HSE_HZ):
        self.rcc = rcc
        self.hse_hz = hse_hz
        self._key = None
        self._sysclk = HSI_HZ

    def sysclk_hz(self) -> float:
        key = (self.rcc.instance.CFGR & 0xC, self.rcc.instance.PLLCFGR)
        if key != self._key:
            self._sysclk = self._compute_sysclk()
            self._key = key
        return self._sysclk

    def _compute_sysclk(self) -> float:
        cfgr = self.rcc.instance.CFGR
        sws = (cfgr >> 2) & 3
        if sws == 0:
            return HSI_HZ
        if sws == 1:
            return self.hse_hz
        pll = self.rcc.instance.PLLCFGR
        src = self.hse_hz if pll & (1 << 22) else HSI_HZ
        m = pll & 0x3F
        n = (pll >> 6) & 0x1FF
        p = (((pll >> 16) & 3) + 1) * 2
        if m < 2 or n < 50:
            raise RuntimeError(f"PLL misprogrammed: PLLM={m}, PLLN={n} (RM0383: PLLM >= 2, PLLN >= 50)")
        return src / m * n / p

    def hclk_hz(self) -> float:
        hpre = (self.rcc.instance.CFGR >> 4) & 0xF
        return self.sysclk_hz() / _AHB_DIV.get(hpre, 1)

    def _apb_div(self, shift: int) -> int:
        return _APB_DIV.get((self.rcc.instance.CFGR >> shift) & 7, 1)

    def pclk1_hz(self) -> float:
        return self.hclk_hz() / self._apb_div(10)

    def pclk2_hz(self) -> float:
        return self.hclk_hz() / self._apb_div(13)

    def timer_hz(self, apb: int) -> float:
        """Timer kernel clock: the APB clock, doubled when the APB prescaler is not 1."""
        div = self._apb_div(10 if apb == 1 else 13)
        pclk = self.hclk_hz() / div
        return pclk if div == 1 else 2 * pclk
