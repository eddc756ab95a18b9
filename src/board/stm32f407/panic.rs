//! What a panic or a hard fault does on the board: the machine is made safe before anything
//! else, then a line in the log, and the core stops on an undefined instruction; `probe-rs run`
//! reports the stop with a backtrace, which says where it came from.
//!
//! Safe means no pulse and no torque. With interrupts off no task runs on, but the step timer
//! would: its PWM outputs go on pulsing at the last period loaded, so the pen would run on at
//! constant speed. So TIM1 stops, its outputs are cut, PULS (PE9, PE11) becomes a GPIO output
//! driven low, and SON (PE13) goes low, all by register writes that need nothing initialised.
//! A watchdog or any other reset leaves every pin floating until the firmware sets it up: the
//! drivers' optocoupled inputs then see no current, no pulse and servo off.
//!
//! The panic's message and location are not read: reading them keeps every panic message's
//! formatting in the image, about 6 KB of flash.

use embassy_stm32::pac;
use embassy_stm32::pac::gpio::vals::Moder;

/// The X and Y PULS pins on GPIOE (TIM1 CH1 and CH2).
const PULS_PINS: [usize; 2] = [9, 11];
/// The SON pin on GPIOE.
const SON_PIN: usize = 13;

/// Stops every pulse and drops SON, whatever state the firmware is in.
/// At power-on or after any reset, before the clocks: the step and SON outputs low, as a fault
/// leaves them.
pub fn safe_outputs() {
    pac::RCC.ahb1enr().modify(|w| w.set_gpioeen(true));
    stop_the_machine();
    // SAFETY: nothing has run that masks interrupts for a reason of its own.
    unsafe { cortex_m::interrupt::enable() };
}

fn stop_the_machine() {
    cortex_m::interrupt::disable();
    pac::TIM1.cr1().modify(|w| w.set_cen(false));
    pac::TIM1.bdtr().modify(|w| w.set_moe(false));
    pac::GPIOE.bsrr().write(|w| {
        for pin in PULS_PINS.into_iter().chain([SON_PIN]) {
            w.set_br(pin, true);
        }
    });
    pac::GPIOE.moder().modify(|w| {
        for pin in PULS_PINS {
            w.set_moder(pin, Moder::OUTPUT);
        }
    });
}

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    stop_the_machine();
    defmt::error!("panicked: pulses stopped, servos off; see the backtrace");
    cortex_m::asm::udf()
}

crate::firmware::stack::hard_fault_entry!(hard_fault);

fn hard_fault() -> ! {
    stop_the_machine();
    defmt::error!("hard fault (a stack overflow, too): pulses stopped, servos off");
    cortex_m::asm::udf()
}
