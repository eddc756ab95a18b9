//! The model's host links: CMSDK UARTs 0 and 1, interrupt-driven, as embedded-io-async streams.
//!
//! Each direction has a byte ring with one writer and one reader (the receive interrupt fills
//! the receive ring, the reading task empties it; the writing task fills the transmit ring, the
//! transmit interrupt empties it), so neither side ever masks interrupts to pass bytes. QEMU
//! holds a received byte in the UART until it is read and reads no more from the host
//! meanwhile: while the receive ring is full the interrupt leaves the byte there, and the reader
//! pends the interrupt again once it has made room, so no byte is ever lost. QEMU sends at no
//! particular baud rate: a byte written goes out at once.

use core::cell::UnsafeCell;
use core::convert::Infallible;
use core::future::poll_fn;
use core::sync::atomic::{AtomicUsize, Ordering};
use core::task::Poll;

use cortex_m::peripheral::NVIC;
use embassy_sync::waitqueue::AtomicWaker;

use super::regs::{self, *};
use crate::firmware::executor::Irq;

/// Bytes each ring holds: GRBL senders keep at most 128 unanswered bytes in flight, as on the
/// board's UART.
const RING_BYTES: usize = 256;

/// A ring of bytes with one producer and one consumer, each in one context.
struct ByteRing {
    buf: UnsafeCell<[u8; RING_BYTES]>,
    /// Bytes popped and pushed so far, wrapping: the length is their difference.
    popped: AtomicUsize,
    pushed: AtomicUsize,
}

// SAFETY: the producer writes only the slot past the last pushed and then publishes it; the
// consumer reads only published slots and then releases them: no slot is written and read at
// once. Each ring has one producer and one consumer (see the module documentation).
unsafe impl Sync for ByteRing {}

impl ByteRing {
    const fn new() -> Self {
        ByteRing { buf: UnsafeCell::new([0; RING_BYTES]), popped: AtomicUsize::new(0), pushed: AtomicUsize::new(0) }
    }

    /// Appends `byte`; false when full. The producer's side only.
    fn push(&self, byte: u8) -> bool {
        let pushed = self.pushed.load(Ordering::Relaxed);
        if self.is_full() {
            return false;
        }
        // SAFETY: the slot is free (see `Sync`), and only the producer writes.
        unsafe { (*self.buf.get())[pushed % RING_BYTES] = byte };
        self.pushed.store(pushed.wrapping_add(1), Ordering::Release);
        true
    }

    /// The oldest byte, taken. The consumer's side only.
    fn pop(&self) -> Option<u8> {
        let popped = self.popped.load(Ordering::Relaxed);
        if popped == self.pushed.load(Ordering::Acquire) {
            return None;
        }
        // SAFETY: the slot was published by the producer and is not written until released.
        let byte = unsafe { (*self.buf.get())[popped % RING_BYTES] };
        self.popped.store(popped.wrapping_add(1), Ordering::Release);
        Some(byte)
    }

    fn is_empty(&self) -> bool {
        self.popped.load(Ordering::Acquire) == self.pushed.load(Ordering::Acquire)
    }

    fn is_full(&self) -> bool {
        self.pushed.load(Ordering::Acquire).wrapping_sub(self.popped.load(Ordering::Acquire)) == RING_BYTES
    }
}

/// One UART: its registers, interrupt lines, rings and the tasks waiting on them.
pub struct Port {
    base: usize,
    rx_irq: u16,
    tx_irq: u16,
    rx: ByteRing,
    tx: ByteRing,
    rx_waker: AtomicWaker,
    tx_waker: AtomicWaker,
}

impl Port {
    const fn new(base: usize, rx_irq: u16, tx_irq: u16) -> Self {
        Port {
            base,
            rx_irq,
            tx_irq,
            rx: ByteRing::new(),
            tx: ByteRing::new(),
            rx_waker: AtomicWaker::new(),
            tx_waker: AtomicWaker::new(),
        }
    }

    /// The receive interrupt: moves received bytes into the ring while it has room.
    pub fn on_receive(&self) {
        regs::write(self.base, UART_INTSTATUS, UART_RX_IRQ);
        let mut received = false;
        while regs::read(self.base, UART_STATE) & UART_RX_FULL != 0 {
            // Room first: a byte read from the UART must find a place.
            if self.rx.is_full() {
                break;
            }
            self.rx.push(regs::read(self.base, UART_DATA) as u8);
            received = true;
        }
        if received {
            self.rx_waker.wake();
        }
    }

    /// The transmit interrupt (or the writer's nudge): sends what the ring holds.
    pub fn on_transmit(&self) {
        regs::write(self.base, UART_INTSTATUS, UART_TX_IRQ);
        while regs::read(self.base, UART_STATE) & UART_TX_FULL == 0 {
            match self.tx.pop() {
                Some(byte) => regs::write(self.base, UART_DATA, u32::from(byte)),
                None => break,
            }
        }
        self.tx_waker.wake();
    }
}

/// UART 0, the host link, and UART 1, the second link.
pub static UART0_PORT: Port = Port::new(UART0, UART0_RX_IRQ, UART0_TX_IRQ);
pub static UART1_PORT: Port = Port::new(UART1, UART1_RX_IRQ, UART1_TX_IRQ);

/// Turns `port` on, its interrupts at `priority`, and hands out its two ends.
pub fn open(port: &'static Port, priority: u8) -> (UartRx, UartTx) {
    regs::write(port.base, UART_BAUDDIV, UART_BAUDDIV_MIN);
    regs::write(port.base, UART_CTRL, UART_TX_ENABLE | UART_RX_ENABLE | UART_TX_IRQ_ENABLE | UART_RX_IRQ_ENABLE);
    // SAFETY: priorities are set before the lines are unmasked; the handlers touch only `port`.
    unsafe {
        let mut core = cortex_m::Peripherals::steal();
        for irq in [port.rx_irq, port.tx_irq] {
            core.NVIC.set_priority(Irq(irq), priority);
            NVIC::unmask(Irq(irq));
        }
    }
    (UartRx { port }, UartTx { port })
}

/// The receiving end.
pub struct UartRx {
    port: &'static Port,
}

/// The sending end.
pub struct UartTx {
    port: &'static Port,
}

impl embedded_io_async::ErrorType for UartRx {
    type Error = Infallible;
}

impl embedded_io_async::ErrorType for UartTx {
    type Error = Infallible;
}

impl embedded_io_async::Read for UartRx {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        let port = self.port;
        poll_fn(|cx| {
            port.rx_waker.register(cx.waker());
            let mut n = 0;
            while n < buf.len() {
                match port.rx.pop() {
                    Some(byte) => {
                        buf[n] = byte;
                        n += 1;
                    }
                    None => break,
                }
            }
            if n == 0 && !buf.is_empty() {
                return Poll::Pending;
            }
            // Room again: a byte the UART held back comes in now.
            NVIC::pend(Irq(port.rx_irq));
            Poll::Ready(Ok(n))
        })
        .await
    }
}

impl embedded_io_async::Write for UartTx {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        let port = self.port;
        poll_fn(|cx| {
            port.tx_waker.register(cx.waker());
            let n = buf.iter().take_while(|&&byte| port.tx.push(byte)).count();
            // The transmit interrupt sends them; nudged, since an idle UART raises none.
            NVIC::pend(Irq(port.tx_irq));
            if n == 0 && !buf.is_empty() { Poll::Pending } else { Poll::Ready(Ok(n)) }
        })
        .await
    }

    async fn flush(&mut self) -> Result<(), Infallible> {
        let port = self.port;
        poll_fn(|cx| {
            port.tx_waker.register(cx.waker());
            if port.tx.is_empty() { Poll::Ready(Ok(())) } else { Poll::Pending }
        })
        .await
    }
}
