//! Simulated step/direction outputs and the pulse trace they record.
//!
//! Every PULS rising edge becomes a [`Pulse`] stamped with its exact time in step ticks, with the
//! direction read from the SIGN level at that instant, exactly as a servo driver reads it; every
//! SIGN change is kept too. The pen path in `plot.svg` and every count the tests check are rebuilt
//! from this trace, not from commands, and so are the timings a driver needs (the shortest PULS
//! high and low times, SIGN's set-up before and hold after a pulse).

use std::cell::RefCell;
use std::rc::Rc;
use std::vec::Vec;

use crate::geom::{Axis, Point, Step, TICKS_PER_US};
use crate::sim::clock;

/// One pulse as a servo driver sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pulse {
    /// Its rising edge, step ticks.
    pub t_ticks: u64,
    /// The same in whole microseconds (rounded down).
    pub t_us: u64,
    pub axis: Axis,
    /// SIGN level at the rising edge.
    pub sign_high: bool,
}

/// One change of a SIGN output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SignChange {
    pub t_ticks: u64,
    pub axis: Axis,
    pub high: bool,
}

/// Everything the step/direction pins did.
#[derive(Debug, Default)]
pub struct PulseTrace {
    pub pulses: Vec<Pulse>,
    pub sign_changes: Vec<SignChange>,
    /// Shortest time from a SIGN change to the next PULS rising edge on that axis, ticks.
    pub min_dir_setup_ticks: Option<u64>,
    /// Shortest time from a PULS falling edge to the next SIGN change on that axis, ticks.
    pub min_dir_hold_ticks: Option<u64>,
    /// Shortest PULS high time, and shortest low time between two pulses of one axis, ticks.
    pub min_pulse_width_ticks: Option<u64>,
    pub min_pulse_low_ticks: Option<u64>,
    sign_high: [bool; 2],
    /// Per axis, pulses with SIGN high less those with SIGN low.
    driven: [i64; 2],
    sign_changed_at: [Option<u64>; 2],
    puls_high_since: [Option<u64>; 2],
    puls_low_since: [Option<u64>; 2],
    /// From this step tick on the pins have no power: no edge is made.
    power_off_at_ticks: Option<u64>,
}

/// `at` becomes the smaller of itself and `v`.
fn keep_min(at: &mut Option<u64>, v: u64) {
    *at = Some(at.map_or(v, |m| m.min(v)));
}

impl PulseTrace {
    /// The power goes off at `t_ticks` (step ticks): no edge is made from then on, not even one
    /// the step timer set up before it (a SIGN change stamped its latency ahead).
    pub fn power_off_at(&mut self, t_ticks: u64) {
        self.power_off_at_ticks = Some(t_ticks);
    }

    fn edge(&mut self, axis: Axis, role: Role, high: bool, t: u64) {
        if self.power_off_at_ticks.is_some_and(|off| t >= off) {
            return;
        }
        let i = axis.index();
        match role {
            Role::Sign => {
                if self.sign_high[i] != high {
                    self.sign_high[i] = high;
                    self.sign_changed_at[i] = Some(t);
                    self.sign_changes.push(SignChange { t_ticks: t, axis, high });
                    if let Some(fell) = self.puls_low_since[i] {
                        keep_min(&mut self.min_dir_hold_ticks, t - fell);
                    }
                }
            }
            Role::Puls => match (self.puls_high_since[i], high) {
                (None, true) => {
                    self.puls_high_since[i] = Some(t);
                    let t_us = t / u64::from(TICKS_PER_US);
                    self.pulses.push(Pulse { t_ticks: t, t_us, axis, sign_high: self.sign_high[i] });
                    self.driven[i] += if self.sign_high[i] { 1 } else { -1 };
                    if let Some(changed) = self.sign_changed_at[i].take() {
                        keep_min(&mut self.min_dir_setup_ticks, t - changed);
                    }
                    if let Some(fell) = self.puls_low_since[i] {
                        keep_min(&mut self.min_pulse_low_ticks, t - fell);
                    }
                }
                (Some(since), false) => {
                    self.puls_high_since[i] = None;
                    self.puls_low_since[i] = Some(t);
                    keep_min(&mut self.min_pulse_width_ticks, t - since);
                }
                _ => {}
            },
        }
    }

    /// Per axis, where the pulses so far have driven it: pulses with SIGN high less those with
    /// SIGN low.
    pub fn driven_steps(&self) -> [i64; 2] {
        self.driven
    }

    /// Pulses per axis, counted by direction: `[x_forward, x_backward, y_forward, y_backward]`,
    /// with SIGN high meaning forward (no inversion).
    pub fn counts(&self) -> [u64; 4] {
        let mut c = [0; 4];
        for p in &self.pulses {
            c[p.axis.index() * 2 + usize::from(!p.sign_high)] += 1;
        }
        c
    }

    /// The steps the drivers took, in order, with their times in µs (rounded down); pulses on
    /// both axes at the same instant form one diagonal step. `invert_mask` is the `$3` setting
    /// in force.
    pub fn steps(&self, invert_mask: u8) -> Vec<(u64, Step)> {
        self.steps_ticks(invert_mask).into_iter().map(|(t, s)| (t / u64::from(TICKS_PER_US), s)).collect()
    }

    /// [`steps`](Self::steps), with their exact times in step ticks.
    pub fn steps_ticks(&self, invert_mask: u8) -> Vec<(u64, Step)> {
        let mut out: Vec<(u64, Step)> = Vec::new();
        for p in &self.pulses {
            let inverted = invert_mask & (1 << p.axis.index()) != 0;
            let d = if p.sign_high != inverted { 1 } else { -1 };
            let mut step = match out.last() {
                Some((t, s)) if *t == p.t_ticks && s.on(p.axis) == 0 => out.pop().map(|(_, s)| s).unwrap_or_default(),
                _ => Step::NONE,
            };
            match p.axis {
                Axis::X => step.x = d,
                Axis::Y => step.y = d,
            }
            out.push((p.t_ticks, step));
        }
        out
    }

    /// The lattice points the pen passed through, starting at the origin.
    pub fn path(&self, invert_mask: u8) -> Vec<Point> {
        let mut p = Point::ORIGIN;
        let mut path = std::vec![p];
        for (_, s) in self.steps(invert_mask) {
            p = p.stepped(s);
            path.push(p);
        }
        path
    }
}

#[derive(Clone, Copy, Debug)]
enum Role {
    Puls,
    Sign,
}

/// A PULS or SIGN output of one axis, recording into a shared trace.
pub struct TracePin {
    trace: Rc<RefCell<PulseTrace>>,
    axis: Axis,
    role: Role,
}

impl TracePin {
    /// The PULS and SIGN pins of `axis`.
    pub fn pair(trace: &Rc<RefCell<PulseTrace>>, axis: Axis) -> (TracePin, TracePin) {
        (
            TracePin { trace: trace.clone(), axis, role: Role::Puls },
            TracePin { trace: trace.clone(), axis, role: Role::Sign },
        )
    }
}

impl TracePin {
    /// Drives the pin to `high` at `t_ticks` (step ticks, not before the last edge recorded).
    pub fn set_at(&mut self, high: bool, t_ticks: u64) {
        self.trace.borrow_mut().edge(self.axis, self.role, high, t_ticks);
    }
}

/// An output whose every change of level is recorded with its virtual time (the servo-on
/// output); it starts low.
#[derive(Clone, Default)]
pub struct LevelPin(Rc<RefCell<Vec<(u64, bool)>>>);

impl LevelPin {
    /// Every change, in order.
    pub fn changes(&self) -> Vec<(u64, bool)> {
        self.0.borrow().clone()
    }

    fn set(&self, high: bool) {
        let mut changes = self.0.borrow_mut();
        if changes.last().map_or(high, |c| c.1 != high) {
            changes.push((clock::now_ticks(), high));
        }
    }
}

impl embedded_hal::digital::ErrorType for LevelPin {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::OutputPin for LevelPin {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.set(false);
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.set(true);
        Ok(())
    }
}

/// The board's independent watchdog: remembers the longest time it went unfed, in virtual time.
#[derive(Clone, Default)]
pub struct SimWatchdog(Rc<RefCell<(u64, u64)>>);

impl SimWatchdog {
    /// The firmware feeds it.
    pub fn feed(&self) {
        let now = clock::now_ticks();
        let (last, longest) = &mut *self.0.borrow_mut();
        *longest = (*longest).max(now - *last);
        *last = now;
    }

    /// The longest time it went unfed, up to `end_us`, µs.
    pub fn longest_unfed_us(&self, end_us: u64) -> u64 {
        let (last, longest) = *self.0.borrow();
        longest.max(end_us.saturating_sub(last))
    }
}

/// The pen servo's PWM: every change of its pulse width, µs, with its virtual time (a 50 Hz
/// frame, so the duty cycle counts in µs). No pulse at all until the firmware drives it.
#[derive(Clone, Default)]
pub struct SimPen(Rc<RefCell<Vec<(u64, u16)>>>);

impl SimPen {
    /// Every change, in order.
    pub fn changes(&self) -> Vec<(u64, u16)> {
        self.0.borrow().clone()
    }
}

impl embedded_hal::pwm::ErrorType for SimPen {
    type Error = core::convert::Infallible;
}

impl embedded_hal::pwm::SetDutyCycle for SimPen {
    fn max_duty_cycle(&self) -> u16 {
        crate::machine_io::pen::PEN_SERVO_PERIOD_US as u16
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        let mut changes = self.0.borrow_mut();
        if changes.last().is_none_or(|c| c.1 != duty) {
            changes.push((clock::now_ticks(), duty));
        }
        Ok(())
    }
}
