//! The machine's own inputs: the limit switches, the drivers' alarm (ALM) outputs and the
//! emergency stop. This module owns what their levels mean (which inputs are wired, which level
//! is active) and the debounce that turns samples of them into a [`Trip`]. Nothing here reads a
//! pin: the board reads all of them at once into one byte of levels ([`InputLevels`]), which the
//! pulse engine samples at every period while the axes move, and the servo task at rest.
//!
//! * Limit switches, one at each end of each axis, with pull-ups: normally open to ground by
//!   default (pressed reads low), normally closed with `$5=1` (pressed reads high). Watched when
//!   hard limits are on (`$21`), and only in the direction the axis moves: a switch pressed
//!   behind the pen never stops it, so the pen can always be moved off a switch.
//! * Driver alarms (`$207`): the EP3L's ALM output conducts while the driver is well and opens
//!   on an alarm, so with a pull-up an alarm (or a broken wire) reads high.
//! * The emergency stop (`$208`): a normally closed button to ground; pressed (or a broken wire)
//!   reads high.
//!
//! An input trips once it has been active at every sample for the debounce time (`$206`): a
//! glitch shorter than that never trips, a switch that bounces trips once it stays closed.

use crate::geom::{Axis, Step, TICK_HZ};
use crate::settings::Settings;

/// Input bits, as [`InputLevels`] and [`InputSetup::active`] hold them.
pub const LIMIT_X_MIN: u8 = 1 << 0;
pub const LIMIT_Y_MIN: u8 = 1 << 1;
pub const LIMIT_X_MAX: u8 = 1 << 2;
pub const LIMIT_Y_MAX: u8 = 1 << 3;
pub const DRIVER_ALARM_X: u8 = 1 << 4;
pub const DRIVER_ALARM_Y: u8 = 1 << 5;
pub const ESTOP: u8 = 1 << 6;
/// The four limit switches.
pub const LIMITS: u8 = LIMIT_X_MIN | LIMIT_Y_MIN | LIMIT_X_MAX | LIMIT_Y_MAX;
/// The inputs watched whichever way the axes move, and at rest.
pub const ALWAYS_WATCHED: u8 = DRIVER_ALARM_X | DRIVER_ALARM_Y | ESTOP;

/// The levels of every input pin, one bit each as above: set where the pin reads high.
pub type InputLevels = u8;

/// What stopped the machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Trip {
    /// A limit switch: the one at the far end of `axis` when `max`, else the one at the near
    /// end.
    Limit { axis: Axis, max: bool },
    /// A driver raised its alarm output.
    DriverAlarm(Axis),
    /// The emergency stop was pressed.
    EStop,
    /// The step timer's interrupt came a whole period late: the timer repeated a period (see
    /// [`crate::motion::pulse`]).
    MissedUpdate,
}

impl Trip {
    /// The trip one of `bits` (at least one set) stands for, the lowest bit first.
    fn of(bits: u8) -> Trip {
        let bit = bits & bits.wrapping_neg();
        match bit {
            LIMIT_X_MIN => Trip::Limit { axis: Axis::X, max: false },
            LIMIT_Y_MIN => Trip::Limit { axis: Axis::Y, max: false },
            LIMIT_X_MAX => Trip::Limit { axis: Axis::X, max: true },
            LIMIT_Y_MAX => Trip::Limit { axis: Axis::Y, max: true },
            DRIVER_ALARM_X => Trip::DriverAlarm(Axis::X),
            DRIVER_ALARM_Y => Trip::DriverAlarm(Axis::Y),
            _ => Trip::EStop,
        }
    }
}

/// The limit switches a step runs towards: the one at the end each of its axes moves to. Its
/// direction bits ([`Step::directions`]) are in the switches' order.
#[inline(always)]
pub const fn limits_toward(step: Step) -> u8 {
    const _: () = assert!(LIMIT_X_MIN == 1 && LIMIT_Y_MIN == 2 && LIMIT_X_MAX == 1 << 2 && LIMIT_Y_MAX == 2 << 2);
    step.directions()
}

/// Which inputs are wired and watched and which of their levels is active, from the settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InputSetup {
    /// Inputs active while their pin reads low.
    active_low: u8,
    /// Inputs that may trip.
    pub watched: u8,
    /// How long an input must stay active to trip, ticks.
    pub debounce_ticks: u32,
}

impl InputSetup {
    pub fn from_settings(s: &Settings) -> InputSetup {
        let mut watched = 0;
        if s.hard_limits {
            watched |= LIMITS;
        }
        if s.driver_alarm_input {
            watched |= DRIVER_ALARM_X | DRIVER_ALARM_Y;
        }
        if s.estop_input {
            watched |= ESTOP;
        }
        InputSetup {
            active_low: if s.limit_pins_invert { 0 } else { LIMITS },
            watched,
            debounce_ticks: s.input_debounce_ms * (TICK_HZ / 1_000),
        }
    }

    /// The watched inputs active at `levels`.
    #[inline(always)]
    pub fn active(&self, levels: InputLevels) -> u8 {
        (levels ^ self.active_low) & self.watched
    }

    /// True when the limit switch of `trip` reads pressed at `levels`, watched or not.
    pub fn pressed(&self, levels: InputLevels, trip: Trip) -> bool {
        let bit = match trip {
            Trip::Limit { axis, max } => (1 << axis.index()) << if max { 2 } else { 0 },
            Trip::DriverAlarm(_) | Trip::EStop | Trip::MissedUpdate => return false,
        };
        (levels ^ self.active_low) & bit != 0
    }

    /// The watched driver alarms and e-stop active at `levels`: what trips the machine whether
    /// it moves or not, and what `$X` must not unlock over.
    pub fn stops_active(&self, levels: InputLevels) -> u8 {
        self.active(levels) & ALWAYS_WATCHED
    }
}

/// Turns samples of the active inputs into a trip; see the module documentation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Debounce {
    /// Inputs active at every sample since `since_ticks`.
    held: u8,
    since_ticks: u32,
}

impl Debounce {
    /// Takes a sample: `active` inputs at `now_ticks` (a wrapping clock). The trip, once one of
    /// them has been active at every sample for `debounce_ticks`.
    #[inline(always)]
    pub fn sample(&mut self, active: u8, now_ticks: u32, debounce_ticks: u32) -> Option<Trip> {
        let held = self.held & active;
        if held == 0 {
            // Nothing held on: whatever is active now starts its time.
            self.held = active;
            self.since_ticks = now_ticks;
            if active == 0 || debounce_ticks > 0 {
                return None;
            }
            return Some(Trip::of(active));
        }
        self.held = held;
        if now_ticks.wrapping_sub(self.since_ticks) >= debounce_ticks { Some(Trip::of(held)) } else { None }
    }

    /// True while an input is held on, not yet for the debounce time.
    #[inline(always)]
    pub fn holding(&self) -> bool {
        self.held != 0
    }

    /// Forgets what was held: sampling starts over (after a trip, or a pause in sampling).
    pub fn clear(&mut self) {
        self.held = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setup(configure: impl FnOnce(&mut Settings)) -> InputSetup {
        let mut s = Settings::default();
        configure(&mut s);
        InputSetup::from_settings(&s)
    }

    #[test]
    fn only_wired_inputs_are_watched_and_limit_switches_follow_their_setting() {
        let all_high = 0x7F;
        assert_eq!(setup(|_| {}).active(0), 0, "nothing is watched by default");
        let hard = setup(|s| s.hard_limits = true);
        // Normally open to ground: pressed reads low.
        assert_eq!(hard.active(all_high & !LIMIT_Y_MAX), LIMIT_Y_MAX);
        assert_eq!(hard.active(all_high), 0);
        let nc = setup(|s| {
            s.hard_limits = true;
            s.limit_pins_invert = true;
        });
        assert_eq!(nc.active(LIMIT_X_MIN), LIMIT_X_MIN);
        let stops = setup(|s| {
            s.driver_alarm_input = true;
            s.estop_input = true;
        });
        assert_eq!(stops.active(all_high), DRIVER_ALARM_X | DRIVER_ALARM_Y | ESTOP);
        assert_eq!(stops.active(0), 0);
    }

    #[test]
    fn a_glitch_shorter_than_the_debounce_never_trips_and_a_bouncing_switch_trips_once_closed() {
        let mut d = Debounce::default();
        let bit = LIMIT_X_MAX;
        // A 900-tick glitch against a 1000-tick debounce, sampled every 100 ticks.
        let mut t = 0;
        for k in 0..30 {
            let active = if (5..14).contains(&k) { bit } else { 0 };
            assert_eq!(d.sample(active, t, 1_000), None, "sample {k}");
            t += 100;
        }
        // A bouncing contact: closed, open, closed... then closed for good.
        let bounce = [bit, 0, bit, bit, 0, bit];
        for active in bounce {
            assert_eq!(d.sample(active, t, 1_000), None);
            t += 100;
        }
        let closed_at = t - 100;
        let mut tripped = None;
        while tripped.is_none() {
            tripped = d.sample(bit, t, 1_000).map(|trip| (trip, t));
            t += 100;
        }
        assert_eq!(tripped, Some((Trip::Limit { axis: Axis::X, max: true }, closed_at + 1_000)));
    }

    #[test]
    fn no_debounce_trips_at_the_first_sample_and_the_clock_may_wrap() {
        let mut d = Debounce::default();
        assert_eq!(d.sample(ESTOP | DRIVER_ALARM_Y, 5, 0), Some(Trip::DriverAlarm(Axis::Y)));
        let mut d = Debounce::default();
        assert_eq!(d.sample(ESTOP, u32::MAX - 10, 50), None);
        assert_eq!(d.sample(ESTOP, 39, 50), Some(Trip::EStop));
        assert_eq!(Trip::of(LIMIT_Y_MIN), Trip::Limit { axis: Axis::Y, max: false });
        assert_eq!(Trip::of(DRIVER_ALARM_X), Trip::DriverAlarm(Axis::X));
        assert_eq!(Trip::of(ESTOP), Trip::EStop);
    }

    #[test]
    fn a_step_runs_toward_the_switches_at_the_ends_it_moves_to() {
        // X forward, Y back; Y forward alone; X back alone; both back; nothing.
        assert_eq!(limits_toward(Step::new(1, -1)), LIMIT_X_MAX | LIMIT_Y_MIN);
        assert_eq!(limits_toward(Step::new(0, 1)), LIMIT_Y_MAX);
        assert_eq!(limits_toward(Step::new(-1, 0)), LIMIT_X_MIN);
        assert_eq!(limits_toward(Step::new(-1, -1)), LIMIT_X_MIN | LIMIT_Y_MIN);
        assert_eq!(limits_toward(Step::NONE), 0);
    }
}
