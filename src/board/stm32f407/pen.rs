//! The pen servo's PWM: TIM3 counting microseconds, a 20 ms frame, PWM mode 1 on CH1 (PC6),
//! the compare value preloaded so a new pulse width starts with the next frame. No pulse until
//! the servo task sets one (an RC servo without pulses holds nothing).

use embassy_stm32::Peri;
use embassy_stm32::peripherals::TIM3;
use embassy_stm32::timer::low_level::{OutputCompareMode, Timer};
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{Ch1, Channel};
use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use servoplot::machine_io::pen::PEN_SERVO_PERIOD_US;

/// The counter's rate: one count per microsecond, so the duty cycle is the pulse in µs.
const PEN_TICK_HZ: u32 = 1_000_000;

/// TIM3 driving the pen servo's signal.
pub struct PenPwm {
    timer: Timer<'static, TIM3>,
    _pin: PwmPin<'static, TIM3, Ch1>,
}

impl PenPwm {
    /// TIM3, counting at `timer_hz` from the clocks, on `pin`.
    pub fn new(tim: Peri<'static, TIM3>, pin: PwmPin<'static, TIM3, Ch1>, timer_hz: u32) -> Self {
        let timer = Timer::new(tim);
        let regs = timer.regs_gp16();
        // Both fit 16 bits: 83 and 19 999.
        regs.psc().write_value((timer_hz / PEN_TICK_HZ - 1) as u16);
        regs.arr().write(|w| w.set_arr((PEN_SERVO_PERIOD_US - 1) as u16));
        timer.set_output_compare_mode(Channel::Ch1, OutputCompareMode::PwmMode1);
        timer.set_output_compare_preload(Channel::Ch1, true);
        timer.enable_channel(Channel::Ch1, true);
        // Load the prescaler now, and count.
        regs.egr().write(|w| w.set_ug(true));
        regs.cr1().modify(|w| {
            w.set_arpe(true);
            w.set_cen(true);
        });
        PenPwm { timer, _pin: pin }
    }
}

impl ErrorType for PenPwm {
    type Error = core::convert::Infallible;
}

impl SetDutyCycle for PenPwm {
    fn max_duty_cycle(&self) -> u16 {
        PEN_SERVO_PERIOD_US as u16
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        self.timer.set_compare_value(Channel::Ch1, duty);
        Ok(())
    }
}
