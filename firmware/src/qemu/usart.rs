//! The emulated USART1 of QEMU's STM32F405 (model `stm32f2xx_usart`), driven by raw registers.
//!
//! QEMU transmits a byte synchronously when DR is written (TXE stays set), and hands over the next
//! received byte only after DR has been read, so the host side is flow-controlled and nothing is
//! lost. Reception is by the RXNE interrupt (USART1 = IRQ 37, dispatched from cortex-m-rt's
//! `DefaultHandler`) into a ring buffer that the async reader drains; when the ring is full the
//! interrupt is masked and the byte stays in QEMU until the reader has made room.

use core::cell::RefCell;
use core::convert::Infallible;

use critical_section::Mutex;
use embassy_sync::waitqueue::AtomicWaker;
use heapless::Deque;

const USART1_BASE: usize = 0x4001_1000;
const SR: *mut u32 = USART1_BASE as *mut u32;
const DR: *mut u32 = (USART1_BASE + 0x04) as *mut u32;
const CR1: *mut u32 = (USART1_BASE + 0x0C) as *mut u32;
const SR_RXNE: u32 = 1 << 5;
const SR_TXE: u32 = 1 << 7;
const CR1_UE: u32 = 1 << 13;
const CR1_TE: u32 = 1 << 3;
const CR1_RE: u32 = 1 << 2;
const CR1_RXNEIE: u32 = 1 << 5;
const CR1_ON: u32 = CR1_UE | CR1_TE | CR1_RE;
/// USART1's interrupt number on QEMU's STM32F405 (as on the real part).
pub const USART1_IRQ: i16 = 37;

/// Received bytes waiting for the reader.
const RX_CAPACITY: usize = 256;
static RX: Mutex<RefCell<Deque<u8, RX_CAPACITY>>> = Mutex::new(RefCell::new(Deque::new()));
static RX_WAKER: AtomicWaker = AtomicWaker::new();

/// Enables USART1 (transmitter and receiver). The baud rate register means nothing to QEMU.
pub fn enable() -> (UsartTx, UsartRx) {
    // SAFETY: USART1's registers exist at this address on netduinoplus2; only this module
    // touches them, and `enable` hands out the single TX and RX halves.
    unsafe { CR1.write_volatile(CR1_ON | CR1_RXNEIE) };
    // SAFETY: unmasking USART1's line; its handler (`on_interrupt`) only touches RX state.
    unsafe { cortex_m::peripheral::NVIC::unmask(Usart1Irq) };
    (UsartTx { _private: () }, UsartRx { _private: () })
}

#[derive(Clone, Copy)]
struct Usart1Irq;

// SAFETY: 37 is USART1's interrupt number on this SoC.
unsafe impl cortex_m::interrupt::InterruptNumber for Usart1Irq {
    fn number(self) -> u16 {
        USART1_IRQ as u16
    }
}

fn set_rx_interrupt(on: bool) {
    let cr1 = if on { CR1_ON | CR1_RXNEIE } else { CR1_ON };
    // SAFETY: see `enable`; CR1 holds nothing else we use.
    unsafe { CR1.write_volatile(cr1) };
}

/// USART1 interrupt: moves the received byte into the ring; masks itself when the ring is full
/// (the byte then waits in QEMU until the reader has made room).
pub(crate) fn on_interrupt() {
    critical_section::with(|cs| {
        let mut rx = RX.borrow(cs).borrow_mut();
        if rx.is_full() {
            set_rx_interrupt(false);
            RX_WAKER.wake();
            return;
        }
        // SAFETY: see `enable`; reading SR/DR has no effect beyond the USART model's state.
        if unsafe { SR.read_volatile() } & SR_RXNE != 0 {
            let byte = unsafe { DR.read_volatile() } as u8;
            // Cannot fail: checked `is_full` above under the same critical section.
            let _ = rx.push_back(byte);
            RX_WAKER.wake();
        }
    });
}

/// Transmit half of the emulated USART.
pub struct UsartTx {
    _private: (),
}

/// Receive half of the emulated USART.
pub struct UsartRx {
    _private: (),
}

impl UsartTx {
    /// Writes bytes one by one (QEMU sends each at once).
    pub fn write_blocking(&mut self, bytes: &[u8]) {
        for &b in bytes {
            // SAFETY: see `enable`.
            unsafe {
                while SR.read_volatile() & SR_TXE == 0 {}
                DR.write_volatile(u32::from(b));
            }
        }
    }
}

impl embedded_io_async::ErrorType for UsartTx {
    type Error = Infallible;
}

impl embedded_io_async::Write for UsartTx {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        self.write_blocking(buf);
        Ok(buf.len())
    }

    async fn flush(&mut self) -> Result<(), Infallible> {
        Ok(()) // every byte has left when `write` returns
    }
}

impl embedded_io_async::ErrorType for UsartRx {
    type Error = Infallible;
}

impl embedded_io_async::Read for UsartRx {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        core::future::poll_fn(|cx| {
            RX_WAKER.register(cx.waker());
            let n = critical_section::with(|cs| {
                let mut rx = RX.borrow(cs).borrow_mut();
                let mut n = 0;
                while n < buf.len() {
                    match rx.pop_front() {
                        Some(b) => {
                            buf[n] = b;
                            n += 1;
                        }
                        None => break,
                    }
                }
                if n > 0 {
                    set_rx_interrupt(true); // there is room again
                }
                n
            });
            if n == 0 {
                core::task::Poll::Pending
            } else {
                core::task::Poll::Ready(Ok(n))
            }
        })
        .await
    }
}
