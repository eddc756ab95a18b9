//! The independent watchdog (IWDG), set to the prescaler and reload `servoplot::machine_io::watchdog`
//! chose for a timeout of 3.0 s to 8.3 s over the LSI's 17-47 kHz.
//!
//! embassy-stm32's `IndependentWatchdog` sizes the reload for an LSI of exactly 32 kHz, which
//! DS8626 does not promise: at 47 kHz its 4 s are 2.7 s, shorter than a 2 s sector erase plus
//! the rest of a save with any margin. So the registers are written here, in the order RM0090
//! §21.3 gives: the watchdog started first (KR = 0xCCCC, which also starts the LSI), then PR
//! and RLR unlocked (KR = 0x5555) and written, their update into the LSI's domain awaited (SR's
//! PVU and RVU clear, a few LSI periods), and the counter reloaded with them (KR = 0xAAAA).
//! Until then it counts with the reset values (/4, 0xFFF): at least 0.34 s, far more than the
//! update takes. Should the LSI never run, the wait never ends and that count resets the board.

use embassy_stm32::Peri;
use embassy_stm32::pac;
use embassy_stm32::pac::iwdg::vals::{Key, Pr};
use embassy_stm32::peripherals::IWDG;
use servoplot::machine_io::watchdog::{WATCHDOG_PRESCALER, WATCHDOG_RELOAD};

/// IWDG_PR's code for the prescaler (RM0090 §21.4.2: 4 is /64).
const PRESCALER_CODE: Pr = Pr::DIVIDE_BY64;
const _: () = assert!(WATCHDOG_PRESCALER == 4 << PRESCALER_CODE.to_bits());

/// The running watchdog.
pub struct Watchdog {
    _iwdg: Peri<'static, IWDG>,
}

impl Watchdog {
    /// Starts the watchdog with `servoplot::machine_io::watchdog`'s timeout; it runs until the next reset.
    pub fn start(iwdg: Peri<'static, IWDG>) -> Self {
        let regs = pac::IWDG;
        regs.kr().write(|w| w.set_key(Key::START));
        regs.kr().write(|w| w.set_key(Key::ENABLE));
        regs.pr().write(|w| w.set_pr(PRESCALER_CODE));
        regs.rlr().write(|w| w.set_rl(WATCHDOG_RELOAD as u16));
        while {
            let sr = regs.sr().read();
            sr.pvu() || sr.rvu()
        } {}
        regs.kr().write(|w| w.set_key(Key::RESET));
        Watchdog { _iwdg: iwdg }
    }

    /// Feeds it: the counter starts again from the reload value.
    pub fn feed(&mut self) {
        pac::IWDG.kr().write(|w| w.set_key(Key::RESET));
    }
}
