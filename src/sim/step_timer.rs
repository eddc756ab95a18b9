//! The simulated step timer: the board's PWM timer modelled in virtual time, driving the pulse
//! engine as the hardware does.
//!
//! At every update event the model switches to the preloaded period, counts the event (as the
//! board's update counter does), then runs the engine's `on_period` (the interrupt); it raises
//! PULS on the period's axes the pulse width before the period ends and lowers them at its end,
//! as PWM mode 2 does. The engine drives SIGN; the model puts each SIGN change on the pin as late
//! as the board's interrupt may ([`SIM_SIGN_LATENCY_TICKS`] after the update event), so the trace
//! shows the set-up the board guarantees at worst. All edges go to the pulse trace, stamped with
//! their exact time in step ticks (the tasks' clock counts whole microseconds; the model waits
//! for the microsecond at or after each edge).
//!
//! The model can make the interrupt late ([`LateInterrupt`]): the timer then goes on without
//! it, repeating the preloaded period and its pulse, as the hardware does, and the interrupt
//! runs whole periods later.

use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::{Instant, Timer};

use crate::geom::{Axis, TICKS_PER_US};
use crate::machine::PulseWriter;
use crate::machine_io::inputs::InputLevels;
use crate::motion::pulse::{PulseEngine, StepTimer};
use crate::sim::clock;
use crate::sim::inputs::SimInputs;
use crate::sim::pins::TracePin;

/// Longest period of the board's 16-bit timer at one tick per count.
pub const SIM_MAX_PERIOD_TICKS: u32 = 65_535;

/// The board's worst interrupt latency for a SIGN write (the STM32F407's, see its step timer).
pub const SIM_SIGN_LATENCY_TICKS: u32 = 2 * TICKS_PER_US;

/// An interrupt that comes late: the first update event at or after `at_us` is served
/// `periods` whole periods later.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LateInterrupt {
    pub at_us: u64,
    pub periods: u16,
}

/// The timer's registers and outputs, as the engine sees them.
pub struct SimStepTimer {
    puls: [TracePin; 2],
    sign: [TracePin; 2],
    inputs: SimInputs,
    /// The preloaded period: ticks and the axes pulsed at its end.
    preload: (u32, u8),
    width_ticks: u32,
    running: bool,
    /// `start` was called and the model has not yet made its update event.
    starting: bool,
    /// Update events so far, wrapping: what the board's update counter counts.
    updates: u16,
    /// When the update event the interrupt serves happened, step ticks.
    update_at_ticks: u64,
    late: Option<LateInterrupt>,
}

impl SimStepTimer {
    /// A stopped timer with PULS and SIGN pins per axis, watching `inputs`.
    pub fn new(pins: [(TracePin, TracePin); 2], inputs: SimInputs) -> Self {
        let [(puls_x, sign_x), (puls_y, sign_y)] = pins;
        SimStepTimer {
            puls: [puls_x, puls_y],
            sign: [sign_x, sign_y],
            inputs,
            preload: (0, 0),
            width_ticks: 0,
            running: false,
            starting: false,
            updates: 0,
            update_at_ticks: 0,
            late: None,
        }
    }

    /// Makes one interrupt late, as `late` says.
    pub fn with_late_interrupt(mut self, late: Option<LateInterrupt>) -> Self {
        self.late = late;
        self
    }

    fn puls(&mut self, axes: u8, high: bool, t_ticks: u64) {
        for axis in Axis::ALL {
            if axes & (1 << axis.index()) != 0 {
                self.puls[axis.index()].set_at(high, t_ticks);
            }
        }
    }

    /// Whole periods the interrupt of the update event at `t_ticks` comes late.
    fn late_by(&mut self, t_ticks: u64) -> u16 {
        match self.late {
            Some(late) if t_ticks >= late.at_us * u64::from(TICKS_PER_US) => {
                self.late = None;
                late.periods
            }
            _ => 0,
        }
    }
}

impl StepTimer for SimStepTimer {
    const MAX_PERIOD_TICKS: u32 = SIM_MAX_PERIOD_TICKS;
    const SIGN_LATENCY_TICKS: u32 = SIM_SIGN_LATENCY_TICKS;

    fn set_sign(&mut self, axis: Axis, high: bool) {
        let at = self.update_at_ticks + u64::from(SIM_SIGN_LATENCY_TICKS);
        self.sign[axis.index()].set_at(high, at);
    }

    fn preload(&mut self, ticks: u32, axes: u8) {
        self.preload = (ticks, axes);
    }

    fn start(&mut self, width_ticks: u32) {
        self.width_ticks = width_ticks;
        self.running = true;
        self.starting = true;
    }

    fn stop(&mut self) {
        self.running = false;
    }

    fn halt(&mut self) {
        // The engine halts at an update event, when PULS is low in PWM mode 2.
        self.running = false;
    }

    fn input_levels(&mut self) -> InputLevels {
        self.inputs.levels()
    }

    fn update_count(&mut self) -> u16 {
        self.updates
    }

    /// The model hands the news on after every interrupt (see [`run`]).
    fn pend_news(&mut self) {}
}

/// Waits until the virtual time reaches `t_ticks` (the microsecond at or after it).
async fn until(t_ticks: u64) {
    Timer::at(Instant::from_micros(t_ticks.div_ceil(u64::from(TICKS_PER_US)))).await;
}

/// Runs the timer forever: waits for the motion task's kick, then counts periods until the
/// engine stops it. The pulse interrupt's handle, `machine`, is its own.
pub async fn run(
    machine: PulseWriter<'_>,
    engine: &mut PulseEngine<'_, SimStepTimer>,
    kicks: &Signal<NoopRawMutex, ()>,
) -> ! {
    loop {
        kicks.wait().await;
        engine.kick(machine);
        machine.deliver_pulse_news();
        if !core::mem::take(&mut engine.timer_mut().starting) {
            continue;
        }
        let mut update = clock::now_ticks() * u64::from(TICKS_PER_US);
        // Update events the interrupt has yet to wait through.
        let mut late = 0;
        loop {
            // The update event: the preloaded period becomes the active one and is counted,
            // then the interrupt runs (and may preload the next one, or stop the timer), unless
            // it comes late: then the timer repeats the period.
            let timer = engine.timer_mut();
            timer.updates = timer.updates.wrapping_add(1);
            timer.update_at_ticks = update;
            let (ticks, axes) = timer.preload;
            late += timer.late_by(update);
            if late > 0 {
                late -= 1;
            } else {
                engine.on_period(machine);
                // The news interrupt, below the pulse interrupt, right after it.
                machine.deliver_pulse_news();
                if !engine.timer().running {
                    break;
                }
            }
            let width = engine.timer().width_ticks;
            let end = update + u64::from(ticks);
            if axes != 0 {
                let rise = end - u64::from(width);
                until(rise).await;
                engine.timer_mut().puls(axes, true, rise);
            }
            until(end).await;
            if axes != 0 {
                engine.timer_mut().puls(axes, false, end);
            }
            update = end;
        }
    }
}
