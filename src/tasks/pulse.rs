//! The pulse task: turns `StepCmd`s into PULS/SIGN edges at their deadlines.
//!
//! It owns the step/direction pins and is the only writer of the position counters, so the
//! position is the pulses emitted, always. Deadlines are absolute: each command's interval is
//! added to the previous pulse's deadline, so timer latency never accumulates into drift; only
//! a pulse already late by a whole interval starts a fresh deadline, so lateness never turns
//! into a burst of pulses faster than planned. SIGN is
//! set as soon as the next command is known (right after the previous pulse) and the pulse waits
//! at least the direction setup time after any SIGN change. On target this task runs on the
//! high-priority interrupt executor; nothing here decides anything about motion.

use embassy_time::{Duration, Instant, Timer};
use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;

use crate::geom::{Axis, StepCmd, TICK_HZ};
use crate::machine::Machine;
use crate::settings::Settings;

const _: () = assert!(embassy_time::TICK_HZ == TICK_HZ as u64, "StepCmd ticks must be embassy-time ticks");

/// The step and direction outputs of one servo driver.
pub struct AxisPins<P: OutputPin> {
    pub puls: P,
    pub sign: P,
}

/// Pin timing, read from the settings at the start of every burst of motion.
struct PulseTiming {
    width_ns: u32,
    /// Shortest time between two pulses (`$205`).
    min_period: Duration,
    dir_setup: Duration,
    dir_invert_mask: u8,
}

impl PulseTiming {
    fn from_settings(s: &Settings) -> Self {
        PulseTiming {
            width_ns: (s.pulse_width_us * 1000.0) as u32,
            min_period: Duration::from_ticks(libm::ceilf(TICK_HZ as f32 / s.max_pulse_rate_hz) as u64),
            dir_setup: Duration::from_micros(libm::ceilf(s.dir_setup_us) as u64),
            dir_invert_mask: s.dir_invert_mask,
        }
    }
}

/// Emits pulses forever. `delay` times the pulse width (a few microseconds, busy-waited).
pub async fn run<P: OutputPin, D: DelayNs>(machine: &Machine, mut axes: [AxisPins<P>; 2], mut delay: D) -> ! {
    // Direction level last driven per axis; None forces the first command to drive it.
    let mut sign_level: [Option<bool>; 2] = [None, None];
    for axis in axes.iter_mut() {
        let _ = axis.puls.set_low();
    }
    loop {
        let mut cmd = machine.steps.receive().await;
        machine.set_pulsing(true);
        let timing = PulseTiming::from_settings(&machine.settings());
        let mut deadline = Instant::now();
        let mut last_pulse: Option<Instant> = None;
        loop {
            let mut due = deadline + Duration::from_ticks(cmd.interval_ticks as u64);
            let now = Instant::now();
            if due < now {
                // Late by more than a whole interval (the queue ran dry, or a higher priority
                // held the CPU): start afresh from now instead of catching up in a burst the
                // drivers could not follow.
                due = now;
            }
            if set_directions(&mut axes, &mut sign_level, cmd, timing.dir_invert_mask) {
                due = due.max(now + timing.dir_setup);
            }
            if let Some(last) = last_pulse {
                // A pulse that went out late never makes the next one come too soon.
                due = due.max(last + timing.min_period);
            }
            Timer::at(due).await;
            last_pulse = Some(Instant::now());
            emit(&mut axes, cmd, timing.width_ns, &mut delay);
            machine.emitted(cmd);
            deadline = due;
            match machine.steps.try_receive() {
                Ok(next) => cmd = next,
                Err(_) => break,
            }
        }
        machine.set_pulsing(false);
        machine.pulses_done.signal(());
        machine.changed.signal(());
    }
}

/// Drives SIGN for every axis that steps; true if any level changed.
fn set_directions<P: OutputPin>(
    axes: &mut [AxisPins<P>; 2],
    level: &mut [Option<bool>; 2],
    cmd: StepCmd,
    invert_mask: u8,
) -> bool {
    let mut changed = false;
    for axis in Axis::ALL {
        let d = cmd.step.on(axis);
        if d == 0 {
            continue;
        }
        let i = axis.index();
        let high = (d > 0) != (invert_mask & (1 << i) != 0);
        if level[i] != Some(high) {
            let _ = if high { axes[i].sign.set_high() } else { axes[i].sign.set_low() };
            level[i] = Some(high);
            changed = true;
        }
    }
    changed
}

/// One PULS pulse on every axis that steps, all starting together.
fn emit<P: OutputPin, D: DelayNs>(axes: &mut [AxisPins<P>; 2], cmd: StepCmd, width_ns: u32, delay: &mut D) {
    for axis in Axis::ALL {
        if cmd.step.on(axis) != 0 {
            let _ = axes[axis.index()].puls.set_high();
        }
    }
    delay.delay_ns(width_ns);
    for axis in Axis::ALL {
        if cmd.step.on(axis) != 0 {
            let _ = axes[axis.index()].puls.set_low();
        }
    }
}
