//! The servo-on task: drives the drivers' SON input from the machine's state. SON stays low
//! from power-on until this task runs (the board starts it with the pulse engine running); the
//! servos then hold position, and go off while the machine sleeps (`$SLP`) until a reset.

use embassy_time::{Duration, Timer};
use embedded_hal::digital::{OutputPin, PinState};

use crate::machine::Machine;

/// How often the servo-on output follows the machine's state: well within a person's reach of
/// the axes after `$SLP`.
pub const SERVO_ENABLE_POLL_MS: u64 = 10;

/// Keeps `son` (both drivers' SON, active high) on while the machine wants the servos on.
pub async fn run<P: OutputPin>(machine: &Machine, mut son: P) -> ! {
    loop {
        if son.set_state(PinState::from(machine.servos_on())).is_err() {
            warn!("servo-on output failed");
        }
        Timer::after(Duration::from_millis(SERVO_ENABLE_POLL_MS)).await;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::settings::Settings;
    use crate::status::RunState;
    use core::cell::Cell;
    use core::convert::Infallible;
    use core::pin::pin;
    use core::task::{Context, Waker};

    /// An output pin that remembers its level.
    struct Pin<'a>(&'a Cell<bool>);

    impl embedded_hal::digital::ErrorType for Pin<'_> {
        type Error = Infallible;
    }

    impl OutputPin for Pin<'_> {
        fn set_low(&mut self) -> Result<(), Infallible> {
            self.0.set(false);
            Ok(())
        }

        fn set_high(&mut self) -> Result<(), Infallible> {
            self.0.set(true);
            Ok(())
        }
    }

    #[test]
    fn son_is_low_while_the_machine_sleeps_and_a_reset_wakes_it_in_alarm() {
        crate::sim::clock::reset();
        let machine = Machine::new(Settings::default());
        let son = Cell::new(false);
        let mut task = pin!(run(&machine, Pin(&son)));
        let mut cx = Context::from_waker(Waker::noop());
        let mut step = || {
            let _ = task.as_mut().poll(&mut cx);
            crate::sim::clock::jump_to_next_deadline();
        };
        step();
        assert!(son.get(), "the servos hold position from power-on");
        machine.sleep();
        assert_eq!(machine.state(), RunState::Sleep);
        step();
        assert!(!son.get(), "asleep, the servos are off");
        machine.wake();
        step();
        assert!(son.get());
        assert_eq!(machine.state(), RunState::Alarm, "the axes were free: the position is in doubt");
    }
}
