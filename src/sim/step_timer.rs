//! The simulated step timer: the board's PWM timer modelled in virtual time, driving the pulse
//! engine as the hardware does.
//!
//! At every update event the model switches to the preloaded period, then runs the engine's
//! `on_period` (the interrupt); it raises PULS on the period's axes the pulse width before the
//! period ends and lowers them at its end, as PWM mode 2 does. SIGN outputs are the engine's to
//! drive. All edges go to the pulse trace.

use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::{Instant, Timer};
use embedded_hal::digital::OutputPin;

use crate::geom::Axis;
use crate::inputs::InputLevels;
use crate::machine::Machine;
use crate::pulse::{PulseEngine, StepTimer};
use crate::sim::inputs::SimInputs;
use crate::sim::pins::TracePin;

/// Longest period of the board's 16-bit timer at one tick per count.
pub const SIM_MAX_PERIOD_TICKS: u32 = 65_535;

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
        }
    }

    fn puls(&mut self, axes: u8, high: bool) {
        for axis in Axis::ALL {
            if axes & (1 << axis.index()) != 0 {
                let pin = &mut self.puls[axis.index()];
                let _ = if high { pin.set_high() } else { pin.set_low() };
            }
        }
    }
}

impl StepTimer for SimStepTimer {
    const MAX_PERIOD_TICKS: u32 = SIM_MAX_PERIOD_TICKS;

    fn set_sign(&mut self, axis: Axis, high: bool) {
        let pin = &mut self.sign[axis.index()];
        let _ = if high { pin.set_high() } else { pin.set_low() };
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
}

/// Runs the timer forever: waits for the motion task's kick, then counts periods until the
/// engine stops it.
pub async fn run(machine: &Machine, engine: &mut PulseEngine<'_, SimStepTimer>, kicks: &Signal<NoopRawMutex, ()>) -> ! {
    loop {
        kicks.wait().await;
        engine.kick(machine);
        if !core::mem::take(&mut engine.timer_mut().starting) {
            continue;
        }
        let mut update = Instant::now();
        loop {
            // The update event: the preloaded period becomes the active one, then the
            // interrupt runs (and may preload the next one, or stop the timer).
            let (ticks, axes) = engine.timer().preload;
            engine.on_period(machine);
            if !engine.timer().running {
                break;
            }
            let width = engine.timer().width_ticks;
            let end = update + embassy_time::Duration::from_ticks(u64::from(ticks));
            if axes != 0 {
                Timer::at(end - embassy_time::Duration::from_ticks(u64::from(width))).await;
                engine.timer_mut().puls(axes, true);
            }
            Timer::at(end).await;
            if axes != 0 {
                engine.timer_mut().puls(axes, false);
            }
            update = end;
        }
    }
}
