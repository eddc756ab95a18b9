//! The model's peripheral registers (QEMU's `hw/arm/mps2.c` for the AN386 image, and ARM's
//! Cortex-M System Design Kit TRM, DDI0479, for the CMSDK timer, dual timer and UART): their
//! addresses and the bits servoplot uses, and volatile access to them.

/// CMSDK APB timer 0 (the free-running clock) and timer 1 (the step timer).
pub const TIMER0: usize = 0x4000_0000;
pub const TIMER1: usize = 0x4000_1000;
/// A CMSDK timer's registers: control, current value (counts down), reload value, interrupt
/// status (write 1 to clear).
pub const TIMER_CTRL: usize = 0x0;
pub const TIMER_VALUE: usize = 0x4;
pub const TIMER_RELOAD: usize = 0x8;
pub const TIMER_INTCLEAR: usize = 0xC;
/// CTRL: counting, and its interrupt raised each time the value reaches 0 (and is reloaded).
pub const TIMER_ENABLE: u32 = 1 << 0;
pub const TIMER_IRQ_ENABLE: u32 = 1 << 3;

/// CMSDK APB dual timer (an SP804): counter 1 is the time driver's alarm, counter 2 the
/// watchdog; both raise the one combined interrupt.
pub const DUALTIMER1: usize = 0x4000_2000;
pub const DUALTIMER2: usize = 0x4000_2020;
/// A dual timer counter's registers: load (writing it restarts the count), value, control,
/// interrupt clear, masked interrupt status.
pub const DUAL_LOAD: usize = 0x00;
pub const DUAL_CTRL: usize = 0x08;
pub const DUAL_INTCLR: usize = 0x0C;
pub const DUAL_MIS: usize = 0x14;
/// CONTROL: one-shot, 32-bit counter, interrupt enabled, periodic mode, counting.
pub const DUAL_ONESHOT: u32 = 1 << 0;
pub const DUAL_32BIT: u32 = 1 << 1;
pub const DUAL_IRQ_ENABLE: u32 = 1 << 5;
pub const DUAL_PERIODIC: u32 = 1 << 6;
pub const DUAL_ENABLE: u32 = 1 << 7;

/// CMSDK APB UART 0 (the host link) and 1 (the second link).
pub const UART0: usize = 0x4000_4000;
pub const UART1: usize = 0x4000_5000;
/// A UART's registers: data, state, control, interrupt status (write 1 to clear).
pub const UART_DATA: usize = 0x0;
pub const UART_STATE: usize = 0x4;
pub const UART_CTRL: usize = 0x8;
pub const UART_INTSTATUS: usize = 0xC;
pub const UART_BAUDDIV: usize = 0x10;
/// STATE: the transmitter holds a byte it has not sent; a received byte waits.
pub const UART_TX_FULL: u32 = 1 << 0;
pub const UART_RX_FULL: u32 = 1 << 1;
/// CTRL: transmitter and receiver on, their interrupts.
pub const UART_TX_ENABLE: u32 = 1 << 0;
pub const UART_RX_ENABLE: u32 = 1 << 1;
pub const UART_TX_IRQ_ENABLE: u32 = 1 << 2;
pub const UART_RX_IRQ_ENABLE: u32 = 1 << 3;
/// INTSTATUS: a byte went out; a byte came in.
pub const UART_TX_IRQ: u32 = 1 << 0;
pub const UART_RX_IRQ: u32 = 1 << 1;
/// The smallest baud divider the UART takes; the model sends at no particular rate.
pub const UART_BAUDDIV_MIN: u32 = 16;

/// Interrupt lines (the AN386's, as mps2.c wires them).
pub const UART0_RX_IRQ: u16 = 0;
pub const UART0_TX_IRQ: u16 = 1;
pub const UART1_RX_IRQ: u16 = 2;
pub const UART1_TX_IRQ: u16 = 3;
pub const TIMER0_IRQ: u16 = 8;
pub const TIMER1_IRQ: u16 = 9;
pub const DUALTIMER_IRQ: u16 = 10;
/// Lines no device of the model drives: the executors' and the pulse news' software interrupts.
pub const MOTION_EXECUTOR_IRQ: u16 = 14;
pub const THREAD_PENDER_IRQ: u16 = 15;
pub const PULSE_NEWS_IRQ: u16 = 16;
/// External interrupt lines of the model's NVIC.
pub const IRQ_LINES: usize = 32;

/// Reads the register at `base + offset`.
#[inline(always)]
pub fn read(base: usize, offset: usize) -> u32 {
    // SAFETY: every address servoplot passes is a register of a device QEMU maps at it (above);
    // reading one has no effect but the device's own.
    unsafe { core::ptr::read_volatile((base + offset) as *const u32) }
}

/// Writes the register at `base + offset`.
#[inline(always)]
pub fn write(base: usize, offset: usize, value: u32) {
    // SAFETY: as for `read`; each caller owns the device it writes.
    unsafe { core::ptr::write_volatile((base + offset) as *mut u32, value) }
}
