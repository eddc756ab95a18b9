//! The simulated plotter's input pins: limit switches at the ends of the travel, the drivers'
//! alarm outputs and the emergency stop, as the board reads them ([`InputLevels`]).
//!
//! The switches are normally open to ground (pressed reads low, `$5=0`) and sit a set distance
//! beyond each end of the travel (`$130`, `$131` either way of the power-on origin, with the
//! settings of power-on); the pen presses one when the pulses emitted take it that far. The
//! drivers' alarms and the emergency stop are wired (they read low until raised) and raised only
//! by an event script: each line is `<time ms> on|off <input>`, the input one of `x-` `x+` `y-`
//! `y+` (a switch forced pressed, as when stuck, or released again), `alarm-x` `alarm-y` (a
//! driver's alarm output), `estop`, or `card-out` (the card taken out of its slot, and put back
//! with `off`; not an input pin: the simulated card slot reads it). `off power` cuts the board's
//! power at that instant: the run ends there ([`InputScript::power_off_us`]); it is no input
//! pin either, comes at most once, and is never switched `on` (a run is a power-on). `#` starts
//! a comment. For example:
//!
//! ```text
//! 1500 on alarm-x     # the X driver faults 1.5 s after power-on
//! 2000 on estop
//! 2300 off estop
//! 400 on y-           # a glitch of 0.2 ms on the Y min switch
//! 400.2 off y-
//! 3000 on card-out    # the card pulled 3 s after power-on
//! 4500 off power      # the power cut 4.5 s after power-on: the run ends
//! ```

use std::cell::RefCell;
use std::format;
use std::rc::Rc;
use std::string::String;
use std::vec::Vec;

use crate::geom::Axis;
use crate::machine_io::inputs::{
    DRIVER_ALARM_X, DRIVER_ALARM_Y, ESTOP, InputLevels, LIMIT_X_MAX, LIMIT_X_MIN, LIMIT_Y_MAX, LIMIT_Y_MIN, LIMITS,
};
use crate::settings::Settings;
use crate::sim::clock;
use crate::sim::pins::PulseTrace;

/// The script's bit for the card taken out of its slot (no input pin's: the pins' bits are the
/// low seven, see [`crate::machine_io::inputs`]).
pub const CARD_OUT: u8 = 1 << 7;
const _: () = assert!((LIMITS | DRIVER_ALARM_X | DRIVER_ALARM_Y | ESTOP) & CARD_OUT == 0);

/// One scripted change of an input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InputEvent {
    pub t_us: u64,
    /// The input (one bit, as in [`crate::machine_io::inputs`]).
    pub input: u8,
    /// Raised (a switch forced pressed, an alarm, the e-stop pressed) or let go.
    pub on: bool,
}

/// A script of input events, in time order, and the power cut, if it has one.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct InputScript {
    events: Vec<InputEvent>,
    power_off_us: Option<u64>,
}

impl InputScript {
    /// Reads an event script (see the module documentation); the error names the line.
    pub fn parse(text: &str) -> Result<InputScript, String> {
        let mut events = Vec::new();
        let mut power_off_us = None;
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let bad = |why: &str| format!("line {}: {why}: `{line}`", n + 1);
            let words: Vec<&str> = line.split_whitespace().collect();
            let [time, state, name] = words[..] else {
                return Err(bad("expected `<time ms> on|off <input>`"));
            };
            let t_ms: f64 = time.parse().map_err(|_| bad("not a time in ms"))?;
            if !(t_ms.is_finite() && t_ms >= 0.0) {
                return Err(bad("not a time in ms"));
            }
            let on = match state {
                "on" => true,
                "off" => false,
                _ => return Err(bad("expected on or off")),
            };
            let t_us = (t_ms * 1_000.0).round() as u64;
            if name == "power" {
                if on {
                    return Err(bad("the power is on from the start: only `off power` cuts it"));
                }
                if power_off_us.is_some() {
                    return Err(bad("the power is cut once: a second `off power`"));
                }
                power_off_us = Some(t_us);
                continue;
            }
            let input = match name {
                "x-" => LIMIT_X_MIN,
                "x+" => LIMIT_X_MAX,
                "y-" => LIMIT_Y_MIN,
                "y+" => LIMIT_Y_MAX,
                "alarm-x" => DRIVER_ALARM_X,
                "alarm-y" => DRIVER_ALARM_Y,
                "estop" => ESTOP,
                "card-out" => CARD_OUT,
                _ => return Err(bad("unknown input")),
            };
            events.push(InputEvent { t_us, input, on });
        }
        events.sort_by_key(|e| e.t_us);
        Ok(InputScript { events, power_off_us })
    }

    /// When the script cuts the power (`off power`), µs after power-on; `None`: it stays on.
    pub fn power_off_us(&self) -> Option<u64> {
        self.power_off_us
    }

    /// Inputs raised by the script at `t_us`.
    fn raised_at(&self, t_us: u64) -> u8 {
        let mut raised = 0;
        for e in self.events.iter().take_while(|e| e.t_us <= t_us) {
            if e.on {
                raised |= e.input;
            } else {
                raised &= !e.input;
            }
        }
        raised
    }
}

/// Where the simulated limit switches sit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Switches {
    /// How far beyond each end of the travel, mm.
    pub beyond_travel_mm: f32,
}

/// The input pins of the simulated plotter; shared by the step timer and the servo task.
#[derive(Clone)]
pub struct SimInputs {
    trace: Rc<RefCell<PulseTrace>>,
    script: Rc<InputScript>,
    /// Per axis, the pulses (SIGN high counting up) at which its min and max switches close;
    /// none without switches.
    switch_at: Option<[(i64, i64); 2]>,
    /// `$3` at power-on: which axes count up on SIGN low.
    invert_mask: u8,
}

impl SimInputs {
    pub fn new(
        trace: Rc<RefCell<PulseTrace>>,
        switches: Option<Switches>,
        script: InputScript,
        settings: &Settings,
    ) -> Self {
        let switch_at = switches.map(|s| {
            Axis::ALL.map(|axis| {
                let i = axis.index();
                let at = (f64::from(settings.max_travel_mm[i] + s.beyond_travel_mm)
                    * f64::from(settings.steps_per_mm[i]))
                .round() as i64;
                (-at, at)
            })
        });
        SimInputs { trace, script: Rc::new(script), switch_at, invert_mask: settings.dir_invert_mask }
    }

    /// True while the script has the card out of its slot.
    pub fn card_out(&self) -> bool {
        self.script.raised_at(clock::now_ticks()) & CARD_OUT != 0
    }

    /// The pins' levels now.
    pub fn levels(&self) -> InputLevels {
        let mut pressed = 0;
        if let Some(at) = self.switch_at {
            let driven = self.trace.borrow().driven_steps();
            for axis in Axis::ALL {
                let i = axis.index();
                let sign = if self.invert_mask & (1 << i) != 0 { -1 } else { 1 };
                let p = driven[i] * sign;
                let (min, max) = at[i];
                if p <= min {
                    pressed |= [LIMIT_X_MIN, LIMIT_Y_MIN][i];
                }
                if p >= max {
                    pressed |= [LIMIT_X_MAX, LIMIT_Y_MAX][i];
                }
            }
        }
        let raised = (self.script.raised_at(clock::now_ticks()) & !CARD_OUT) | pressed;
        // Switches pressed read low; alarms and the e-stop raised read high.
        (LIMITS & !raised) | (raised & !LIMITS)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scripts_read_in_time_order_and_bad_lines_are_named() {
        let s = InputScript::parse("2000 off estop\n# comment\n1500 on estop  # pressed\n0.5 on x+\n").unwrap();
        assert_eq!(s.events[0], InputEvent { t_us: 500, input: LIMIT_X_MAX, on: true });
        assert_eq!(s.raised_at(1_600_000), ESTOP | LIMIT_X_MAX);
        assert_eq!(s.raised_at(2_000_000), LIMIT_X_MAX);
        assert_eq!(InputScript::parse("1 on z+").unwrap_err(), "line 1: unknown input: `1 on z+`");
        assert!(InputScript::parse("\n-3 on estop").unwrap_err().starts_with("line 2: not a time"));
        assert!(InputScript::parse("5 up estop").is_err());
        assert!(InputScript::parse("5 on").is_err());
        assert_eq!(s.power_off_us(), None, "no cut: the power stays on");
    }

    #[test]
    fn off_power_cuts_the_power_once_and_is_no_input() {
        let s = InputScript::parse("1500 on estop\n2750.5 off power  # the plug pulled\n3000 off estop\n").unwrap();
        assert_eq!(s.power_off_us(), Some(2_750_500));
        assert_eq!(s.events.len(), 2, "the cut is no input event");
        assert_eq!(s.raised_at(2_800_000), ESTOP, "and raises no input bit");
        assert_eq!(InputScript::parse("0 off power").unwrap().power_off_us(), Some(0), "a cut before anything");
    }

    #[test]
    fn power_switched_on_or_cut_twice_is_refused_with_its_line() {
        assert_eq!(
            InputScript::parse("# power\n100 on power").unwrap_err(),
            "line 2: the power is on from the start: only `off power` cuts it: `100 on power`"
        );
        assert_eq!(
            InputScript::parse("100 off power\n200 on estop\n300 off power").unwrap_err(),
            "line 3: the power is cut once: a second `off power`: `300 off power`"
        );
        assert!(InputScript::parse("-1 off power").unwrap_err().starts_with("line 1: not a time"));
    }
}
