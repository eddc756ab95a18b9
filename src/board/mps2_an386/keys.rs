//! The model's keypad: keys tapped by the host on UART 2. Each byte received is one key's
//! legend (`0`-`9`, `A`-`D`, `*`, `#`, as [`KEY_MAP`] prints them; any other byte is ignored),
//! pressed for [`MODEL_KEY_DOWN_MS`] and then released for [`MODEL_KEY_UP_MS`] of the model's
//! time, one after another in the order received: a tap takes the same time however fast or
//! slow the host sends, and is never held into a repeat.
//!
//! The keypad task scans the matrix as on the board ([`crate::board::Column`] driven low one at
//! a time, [`crate::board::Row`] read): the column pins say which column is driven, and a row
//! pin reads low while the key tapped now sits at that row and column. Only the keypad task
//! reads the taps, in thread mode; the state is passed through a critical section, a few bytes.

use core::cell::RefCell;
use core::convert::Infallible;
use core::sync::atomic::{AtomicU8, Ordering};

use critical_section::Mutex;
use embassy_time::Instant;
use embedded_hal::digital::{ErrorType, InputPin, OutputPin};
use servoplot::panel::keypad::{KEY_MAP, KEYPAD_COLS};

use super::regs::{
    self, UART_BAUDDIV, UART_BAUDDIV_MIN, UART_CTRL, UART_DATA, UART_RX_ENABLE, UART_RX_FULL, UART_STATE,
};

/// CMSDK APB UART 2 (QEMU's third `-serial`), polled: the keys' link.
const UART2: usize = 0x4000_6000;

/// How long a tapped key stays down, and then up before the next, ms: longer than the keypad's
/// debounce, far shorter than its repeat delay.
pub const MODEL_KEY_DOWN_MS: u64 = 60;
pub const MODEL_KEY_UP_MS: u64 = 60;

/// Taps received and not yet begun.
const MODEL_KEY_QUEUE: usize = 64;

/// No column driven.
const NO_COLUMN: u8 = u8::MAX;

/// The column the keypad task drives low now.
static DRIVEN: AtomicU8 = AtomicU8::new(NO_COLUMN);

/// The taps: those waiting, and the one under way (its key's index in the matrix, and when it
/// began).
struct Taps {
    queue: heapless::Deque<u8, MODEL_KEY_QUEUE>,
    now: Option<(u8, Instant)>,
}

static TAPS: Mutex<RefCell<Taps>> = Mutex::new(RefCell::new(Taps { queue: heapless::Deque::new(), now: None }));

/// Turns UART 2's receiver on.
pub fn start() {
    regs::write(UART2, UART_BAUDDIV, UART_BAUDDIV_MIN);
    regs::write(UART2, UART_CTRL, UART_RX_ENABLE);
}

/// The matrix index (`row * KEYPAD_COLS + column`) of the key printed `legend`.
fn index_of(legend: u8) -> Option<u8> {
    let mut at = KEY_MAP.iter().flatten().map(|key| key.legend());
    at.position(|c| c == char::from(legend)).map(|i| i as u8)
}

/// The key down now, if any, after taking what UART 2 received.
fn key_down() -> Option<u8> {
    let now = Instant::now();
    critical_section::with(|cs| {
        let mut taps = TAPS.borrow_ref_mut(cs);
        while regs::read(UART2, UART_STATE) & UART_RX_FULL != 0 {
            let byte = regs::read(UART2, UART_DATA) as u8;
            if let Some(index) = index_of(byte) {
                let _ = taps.queue.push_back(index);
            }
        }
        if let Some((_, began)) = taps.now
            && now.duration_since(began).as_millis() >= MODEL_KEY_DOWN_MS + MODEL_KEY_UP_MS
        {
            taps.now = None;
        }
        if taps.now.is_none() {
            taps.now = taps.queue.pop_front().map(|index| (index, now));
        }
        taps.now.filter(|(_, began)| now.duration_since(*began).as_millis() < MODEL_KEY_DOWN_MS).map(|(index, _)| index)
    })
}

/// A column of the matrix: driven low by the keypad task, released high.
pub struct ModelColumn(pub u8);

impl ErrorType for ModelColumn {
    type Error = Infallible;
}

impl OutputPin for ModelColumn {
    fn set_low(&mut self) -> Result<(), Infallible> {
        DRIVEN.store(self.0, Ordering::Relaxed);
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Infallible> {
        let _ = DRIVEN.compare_exchange(self.0, NO_COLUMN, Ordering::Relaxed, Ordering::Relaxed);
        Ok(())
    }
}

/// A row of the matrix: low while the key tapped now joins it to the driven column.
pub struct ModelRow(pub u8);

impl ErrorType for ModelRow {
    type Error = Infallible;
}

impl InputPin for ModelRow {
    fn is_high(&mut self) -> Result<bool, Infallible> {
        self.is_low().map(|low| !low)
    }

    fn is_low(&mut self) -> Result<bool, Infallible> {
        let column = DRIVEN.load(Ordering::Relaxed);
        if column == NO_COLUMN {
            return Ok(false);
        }
        Ok(key_down() == Some(self.0 * KEYPAD_COLS as u8 + column))
    }
}
