//! The servo task: drives the drivers' SON input from the machine's state, and watches the
//! drivers' alarms and the emergency stop whether the axes move or not (the pulse engine watches
//! them too while they move, at every period). SON stays low from power-on until this task runs
//! (the board starts it with the pulse engine running); the servos then hold position, and go
//! off while the machine sleeps (`$SLP`) until a reset, after a driver alarm until `$X`, and,
//! unless `$1` is 255, once the machine has stood still for `$1` ms. SON comes back on as soon
//! as there is motion to make, and the machine counts the servos ready `$209` ms later: the
//! motion task starts no pulse before (see
//! [`Machine::servos_ready`](crate::machine::Machine::servos_ready)).
//!
//! It drives the pen servo's PWM to where the machine wants the pen (when `$213` names a pen
//! lift) and tells the machine once it has had its settle time (`$212`).
//!
//! It lights the run LED and sounds the buzzer as [`crate::machine_io::signals`] says.
//!
//! It also feeds the board's independent watchdog, while the pulse engine and the motion task
//! make progress (see [`crate::machine_io::watchdog`]); once they do not, it stops, and the watchdog resets
//! the board.

use core::sync::atomic::{Ordering, fence};

use embassy_time::{Duration, Instant, Timer};
use embedded_hal::digital::{OutputPin, PinState};
use embedded_hal::pwm::SetDutyCycle;

use crate::geom::TICKS_PER_US;
use crate::machine::ServoWriter;
use crate::machine_io::inputs::{Debounce, InputLevels, InputSetup};
use crate::machine_io::pen::{PEN_SERVO_PERIOD_US, PenServo};
use crate::machine_io::signals::Signals;
use crate::machine_io::son::ServoEnable;
use crate::machine_io::watchdog::{Look, Progress};
use crate::settings::Settings;

/// How often the task reads the inputs and sets SON: well within a person's reach of the axes
/// after `$SLP`, and an e-stop pressed at rest is an alarm within this (plus the debounce).
pub const SERVO_ENABLE_POLL_MS: u64 = 10;

/// Keeps `son` (both drivers' SON, active high) on while the machine wants the servos on, trips
/// the machine when a driver alarm or the e-stop read through `levels` stays active, drives
/// `pen` (the pen servo's 50 Hz PWM) and `lights` (the run LED and the buzzer, active high), and
/// calls `feed` (the watchdog's) while the machine makes progress.
pub async fn run<P: OutputPin>(
    machine: ServoWriter<'_>,
    mut son: P,
    mut levels: impl FnMut() -> InputLevels,
    mut pen: impl SetDutyCycle,
    mut lights: [P; 2],
    mut feed: impl FnMut(),
) -> ! {
    let mut signals = Signals::default();
    let mut pen_servo = PenServo::default();
    let mut enable = ServoEnable::default();
    let mut debounce = Debounce::default();
    let mut progress = Progress::default();
    let mut stalled = false;
    loop {
        let settings = machine.settings();
        watch_inputs(machine, levels(), &settings, &mut debounce);
        // The clock of the timings below, wrapping as it allows.
        let ms = super::now_ms();
        let on = servos_on(machine, ms, &settings, &mut enable);
        if son.set_state(PinState::from(on)).is_err() {
            warn!("servo-on output failed");
        }
        // The run LED and the buzzer.
        let (led, buzzer) = signals.update(ms, machine.state(), &settings);
        for (pin, on) in lights.iter_mut().zip([led, buzzer]) {
            if pin.set_state(PinState::from(on)).is_err() {
                warn!("run LED or buzzer output failed");
            }
        }
        let order = machine.pen_order();
        let (send, settled) = pen_servo.update(ms, order, &settings);
        // Both fit 16 bits: the pulse is at most PEN_PULSE_MAX_US.
        if let Some(pulse) = send
            && pen.set_duty_cycle_fraction(pulse as u16, PEN_SERVO_PERIOD_US as u16).is_err()
        {
            warn!("pen servo output failed");
        }
        if settled {
            machine.set_pen_settled(order);
        }
        let healthy = progress.healthy(ms, Look::of(&machine));
        if healthy {
            feed();
        } else if !stalled {
            error!("no pulse while the motion should run: the watchdog resets the board");
        }
        stalled = !healthy;
        Timer::after(Duration::from_millis(SERVO_ENABLE_POLL_MS)).await;
    }
}

/// Publishes the input levels `now` and trips the machine when a driver alarm or the e-stop has
/// stayed active for the debounce time.
fn watch_inputs(machine: ServoWriter<'_>, now: InputLevels, settings: &Settings, debounce: &mut Debounce) {
    machine.set_input_levels(now);
    let setup = InputSetup::from_settings(settings);
    let active = setup.stops_active(now);
    // The debounce clock in step ticks, wrapping as it allows.
    let ticks = (Instant::now().as_micros() as u32).wrapping_mul(TICKS_PER_US);
    if let Some(trip) = debounce.sample(active, ticks, setup.debounce_ticks) {
        machine.trip(trip);
        debounce.clear();
    }
}

/// Whether SON is to be high at `ms`, and the drivers' readiness published: on while the machine
/// wants the servos on, off after standing still for `$1` ms.
fn servos_on(machine: ServoWriter<'_>, ms: u32, settings: &Settings, enable: &mut ServoEnable) -> bool {
    let mut idle_off = enable.idle_off(ms, machine.at_standstill(), settings);
    if idle_off && enable.is_on() {
        // Going off for standing still: first no longer ready, then still standing still?
        // The motion task queues its steps before it looks whether the servos are ready, so
        // one of the two sees the other.
        machine.set_servos_ready(false);
        fence(Ordering::SeqCst);
        idle_off = machine.stopped();
    }
    let on = machine.servos_on() && !idle_off;
    machine.set_servos_ready(enable.ready(ms, on, settings));
    on
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::machine::Machine;
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
        let handles = machine.handles().unwrap();
        let son = Cell::new(false);
        let led = Cell::new(false);
        let mut task = pin!(run(
            handles.servo,
            Pin(&son),
            || 0,
            crate::sim::pins::SimPen::default(),
            [Pin(&led), Pin(&led)],
            || {}
        ));
        let mut cx = Context::from_waker(Waker::noop());
        let mut step = || {
            let _ = task.as_mut().poll(&mut cx);
            crate::sim::clock::jump_to_next_deadline();
        };
        step();
        assert!(son.get(), "the servos hold position from power-on");
        handles.host.sleep();
        assert_eq!(machine.state(), RunState::Sleep);
        step();
        assert!(!son.get(), "asleep, the servos are off");
        handles.host.wake();
        step();
        assert!(son.get());
        assert_eq!(machine.state(), RunState::Alarm, "the axes were free: the position is in doubt");
    }
}
