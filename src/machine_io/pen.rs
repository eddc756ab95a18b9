//! The pen lift: an RC servo that holds the pen up or down, and which moves need the pen where.
//! Pure logic; the servo task drives the servo's PWM from [`Machine::pen`](crate::machine::Machine::pen)
//! and counts the settle time, the motion task changes the pen only at rest and starts no pulse
//! before the pen has settled.
//!
//! `$213` says how the pen is lifted ([`PenLift`]): not at all (no pen servo: the pen is
//! always down, as on a plotter with a fixed pen), by `M3`/`M4` (down) and `M5` (up), or by
//! itself as well: up for rapid moves (`G0`), down for every drawing move (`G1`–`G3` and the
//! curve commands). GRBL's laser mode (`$32`) does the same under `M3`/`M4`: up for rapids,
//! down for drawing moves.
//!
//! How far down the pen goes is a [`PenDepth`]: `M3 S…` sets it from the S word, between `$31`
//! (the pen-up pulse, `$210`) and `$30` (the pen-down pulse, `$211`), as the pen-plotter G-code
//! of SVG-to-G-code tools expects; an `M3` before any S word puts the pen fully down.

use crate::settings::Settings;

/// The RC servo's frame: one pulse every 20 ms (50 Hz).
pub const PEN_SERVO_PERIOD_US: u32 = 20_000;

/// Where the pen is held.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Pen {
    Up,
    Down,
}

/// How far down the pen goes when it is down, per mille of the way from the pen-up pulse
/// (`$210`) to the pen-down pulse (`$211`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct PenDepth(u16);

impl PenDepth {
    /// All the way down: the pulse of `$211`.
    pub const FULL: PenDepth = PenDepth(PEN_DEPTH_FULL_PERMILLE);

    /// The depth the S word `spindle_speed` of `M3 S…` sets: none at or below `$31`, full at or
    /// above `$30`, in proportion between; an `M3` with no S word yet (`None`) is full.
    pub fn of_spindle_speed(settings: &Settings, spindle_speed: Option<f32>) -> PenDepth {
        let Some(s) = spindle_speed else { return PenDepth::FULL };
        let (min, max) = (settings.spindle_min, settings.spindle_max);
        let share = ((s - min) / (max - min)).clamp(0.0, 1.0);
        PenDepth(crate::math::round(share * f32::from(PEN_DEPTH_FULL_PERMILLE)) as u16)
    }

    pub const fn permille(self) -> u16 {
        self.0
    }

    /// The depth kept as [`permille`](Self::permille), at most [`PenDepth::FULL`].
    pub fn from_permille(permille: u16) -> PenDepth {
        PenDepth(permille.min(PEN_DEPTH_FULL_PERMILLE))
    }
}

/// [`PenDepth::FULL`], per mille.
const PEN_DEPTH_FULL_PERMILLE: u16 = 1_000;

/// The bits of a [`PenOrder`] below its count: bit 0 down, then the depth.
const PEN_ORDER_DEPTH_SHIFT: u32 = 1;
const PEN_ORDER_COUNT_SHIFT: u32 = 11;

/// One order to the pen: where, how deep, and which order it is (bit 0 set for down, bits 1-10
/// the depth per mille, above them a count of the orders). An order the servo task settled is
/// told apart from a later one to the same place, so a pen sent away and back while the servo
/// task looked elsewhere never counts as settled early.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PenOrder(u32);

impl PenOrder {
    /// The order kept as `bits` (see [`bits`](Self::bits)).
    pub const fn from_bits(bits: u32) -> PenOrder {
        PenOrder(bits)
    }

    /// The order as kept in one word.
    pub const fn bits(self) -> u32 {
        self.0
    }

    pub fn pen(self) -> Pen {
        if self.0 & 1 != 0 { Pen::Down } else { Pen::Up }
    }

    /// How deep the pen goes when it is down.
    pub fn depth(self) -> PenDepth {
        PenDepth(
            ((self.0 >> PEN_ORDER_DEPTH_SHIFT) & ((1 << (PEN_ORDER_COUNT_SHIFT - PEN_ORDER_DEPTH_SHIFT)) - 1)) as u16,
        )
    }

    /// The order that sends the pen to `pen`, `depth` deep when down; `None` when it is there
    /// already (up, or down as deep).
    pub fn then(self, pen: Pen, depth: PenDepth) -> Option<PenOrder> {
        let down = pen == Pen::Down;
        let same = self.pen() == pen && (!down || self.depth() == depth);
        let count = (self.0 >> PEN_ORDER_COUNT_SHIFT).wrapping_add(1);
        let depth = if down { depth } else { self.depth() };
        (!same).then(|| {
            PenOrder((count << PEN_ORDER_COUNT_SHIFT) | (u32::from(depth.0) << PEN_ORDER_DEPTH_SHIFT) | u32::from(down))
        })
    }
}

/// The pen servo as the servo task drives it: the pulse sent last, for which order, and since
/// when.
#[derive(Clone, Copy, Debug, Default)]
pub struct PenServo {
    sent: Option<(PenOrder, u32, u32)>,
}

impl PenServo {
    /// At `now_ms` (a wrapping clock), with the machine's last `order`: the pulse to send now,
    /// µs, if it changed, and whether the pen has settled where the order says. Without a pen
    /// lift nothing is sent and the pen is where it is told at once.
    pub fn update(&mut self, now_ms: u32, order: PenOrder, settings: &Settings) -> (Option<u32>, bool) {
        if PenLift::of(settings) == PenLift::None {
            return (None, true);
        }
        let pulse = pulse_us(settings, order);
        let mut send = None;
        if self.sent.is_none_or(|(o, p, _)| (o, p) != (order, pulse)) {
            self.sent = Some((order, pulse, now_ms));
            send = Some(pulse);
        }
        let settled = self.sent.is_some_and(|(_, _, since)| now_ms.wrapping_sub(since) >= settings.pen_settle_ms);
        (send, settled)
    }
}

/// How the pen is lifted (`$213`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PenLift {
    /// No pen servo: nothing lifts the pen.
    None,
    /// `M3`/`M4` lower it, `M5` raises it.
    Spindle,
    /// As [`PenLift::Spindle`], and each move sets it: up for rapids, down for drawing.
    Auto,
}

impl PenLift {
    /// The mode `$213` names.
    pub fn of(settings: &Settings) -> PenLift {
        match settings.pen_lift {
            0 => PenLift::None,
            1 => PenLift::Spindle,
            _ => PenLift::Auto,
        }
    }

    /// True when the pen, at `pen`, draws: always without a pen lift.
    pub fn draws(self, pen: Pen) -> bool {
        self == PenLift::None || pen == Pen::Down
    }
}

/// The servo pulse that holds the pen where `order` sends it, µs: down, the depth's share of
/// the way from `$210` to `$211`.
pub fn pulse_us(settings: &Settings, order: PenOrder) -> u32 {
    let (up, down) = (settings.pen_up_us as i32, settings.pen_down_us as i32);
    match order.pen() {
        Pen::Up => settings.pen_up_us,
        Pen::Down => {
            let depth = i32::from(order.depth().0);
            (up + (down - up) * depth / i32::from(PEN_DEPTH_FULL_PERMILLE)) as u32
        }
    }
}

/// Where a keypad drawing needs the pen: down, and raised again once it is drawn; `None` when
/// nothing lifts the pen.
pub fn for_keypad_drawing(settings: &Settings) -> Option<Pen> {
    (PenLift::of(settings) != PenLift::None).then_some(Pen::Down)
}

/// Where a homing move needs the pen: up, homing never draws; `None` when nothing lifts it.
pub fn for_homing(settings: &Settings) -> Option<Pen> {
    (PenLift::of(settings) != PenLift::None).then_some(Pen::Up)
}

/// Where a program's end (M2/M30, which turn the spindle off) leaves the pen: up; `None` when
/// nothing lifts it.
pub fn at_program_end(settings: &Settings) -> Option<Pen> {
    for_homing(settings)
}

/// Where a line's spindle words send the pen, at rest: M3/M4 down (as deep as the S word in
/// force says), M5 up, and a new S word under M3/M4 to its new depth. `spindle_on` is the
/// spindle after the line, `spindle_word` and `s_word` whether the line has an M3/M4/M5 and an
/// S word; `None` when the line leaves the pen where it is, or nothing lifts it.
pub fn for_spindle_words(
    settings: &Settings,
    spindle_on: bool,
    spindle_word: bool,
    s_word: bool,
    spindle_speed: Option<f32>,
) -> Option<(Pen, PenDepth)> {
    if PenLift::of(settings) == PenLift::None || !(spindle_word || (s_word && spindle_on)) {
        return None;
    }
    let depth = PenDepth::of_spindle_speed(settings, spindle_speed);
    Some((if spindle_on { Pen::Down } else { Pen::Up }, depth))
}

/// Where a move needs the pen, a rapid (`G0`) or not, with the spindle (`M3`/`M4`) on or not;
/// `None` when nothing lifts the pen.
pub fn for_move(settings: &Settings, rapid: bool, spindle_on: bool) -> Option<Pen> {
    match PenLift::of(settings) {
        PenLift::None => None,
        PenLift::Auto if rapid => Some(Pen::Up),
        PenLift::Auto => Some(Pen::Down),
        // Laser mode: the laser is off in rapids.
        PenLift::Spindle if settings.laser_mode && rapid => Some(Pen::Up),
        PenLift::Spindle => Some(if spindle_on { Pen::Down } else { Pen::Up }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_ends_ask_one_policy() {
        let (none, lift) = (Settings::default(), Settings { pen_lift: 1, ..Settings::default() });
        assert_eq!((for_keypad_drawing(&none), for_homing(&none), at_program_end(&none)), (None, None, None));
        assert_eq!(
            (for_keypad_drawing(&lift), for_homing(&lift), at_program_end(&lift)),
            (Some(Pen::Down), Some(Pen::Up), Some(Pen::Up))
        );
        let half = PenDepth::of_spindle_speed(&lift, Some(500.0));
        assert_eq!(for_spindle_words(&lift, true, true, false, None), Some((Pen::Down, PenDepth::FULL)), "M3");
        assert_eq!(for_spindle_words(&lift, false, true, false, None), Some((Pen::Up, PenDepth::FULL)), "M5");
        assert_eq!(for_spindle_words(&lift, true, false, true, Some(500.0)), Some((Pen::Down, half)), "S under M3");
        assert_eq!(for_spindle_words(&lift, false, false, true, Some(500.0)), None, "S with the spindle off");
        assert_eq!(for_spindle_words(&lift, true, false, false, Some(500.0)), None, "neither word");
        assert_eq!(for_spindle_words(&none, true, true, true, None), None, "no pen lift");
    }

    #[test]
    fn each_mode_puts_the_pen_where_a_move_needs_it() {
        let mode = |pen_lift| Settings { pen_lift, ..Settings::default() };
        assert_eq!(for_move(&mode(0), true, true), None, "no pen servo");
        assert_eq!(for_move(&mode(1), true, true), Some(Pen::Down), "M3: down, rapid or not");
        assert_eq!(for_move(&mode(1), false, false), Some(Pen::Up), "M5: up, drawing or not");
        assert_eq!(for_move(&mode(2), true, true), Some(Pen::Up), "auto: rapids travel up");
        assert_eq!(for_move(&mode(2), false, false), Some(Pen::Down), "auto: drawing moves draw");
        let laser = Settings { pen_lift: 1, laser_mode: true, ..Settings::default() };
        assert_eq!(for_move(&laser, true, true), Some(Pen::Up), "laser mode: M3 rapids travel up");
        assert_eq!(for_move(&laser, false, true), Some(Pen::Down), "laser mode: M3 drawing moves draw");
        assert_eq!(for_move(&laser, false, false), Some(Pen::Up), "laser mode: M5 keeps the pen up");
        let s = Settings::default();
        let up = PenOrder::from_bits(0);
        let down = up.then(Pen::Down, PenDepth::FULL).unwrap();
        assert_eq!((pulse_us(&s, up), pulse_us(&s, down)), (1_000, 2_000));
    }

    #[test]
    fn the_s_word_sets_the_pulse_between_the_up_and_down_pulses() {
        // $31 = 0 holds the pen up, $30 = 1000 puts it fully down (the defaults).
        let s = Settings::default();
        let pulse = |speed| {
            pulse_us(&s, PenOrder::from_bits(0).then(Pen::Down, PenDepth::of_spindle_speed(&s, speed)).unwrap())
        };
        assert_eq!(pulse(None), 2_000, "M3 with no S word yet: fully down");
        assert_eq!(pulse(Some(1_000.0)), 2_000);
        assert_eq!(pulse(Some(5_000.0)), 2_000, "beyond $30: fully down");
        assert_eq!(pulse(Some(500.0)), 1_500);
        assert_eq!(pulse(Some(0.0)), 1_000, "at $31: the pen-up pulse");
        // An inverted servo ($210 above $211) and a servo-angle S range ($31=20, $30=90).
        let angles = Settings { pen_up_us: 2_000, pen_down_us: 1_000, spindle_min: 20.0, spindle_max: 90.0, ..s };
        let at = |speed| {
            pulse_us(
                &angles,
                PenOrder::from_bits(0).then(Pen::Down, PenDepth::of_spindle_speed(&angles, Some(speed))).unwrap(),
            )
        };
        assert_eq!((at(20.0), at(55.0), at(90.0), at(10.0)), (2_000, 1_500, 1_000, 2_000));
    }

    #[test]
    fn a_new_depth_is_a_new_order_only_when_down() {
        let up = PenOrder::from_bits(0);
        let half = PenDepth::of_spindle_speed(&Settings::default(), Some(500.0));
        assert_eq!(up.then(Pen::Up, half), None, "up already, whatever the depth");
        let down = up.then(Pen::Down, PenDepth::FULL).unwrap();
        assert_eq!(down.then(Pen::Down, PenDepth::FULL), None);
        let shallower = down.then(Pen::Down, half).unwrap();
        assert_eq!((shallower.pen(), shallower.depth()), (Pen::Down, half));
        let raised = shallower.then(Pen::Up, PenDepth::FULL).unwrap();
        assert_eq!((raised.pen(), raised.depth()), (Pen::Up, half), "raising keeps the depth bits");
    }

    #[test]
    fn an_order_counts_and_the_servo_settles_for_the_last_one() {
        let first = PenOrder::from_bits(0);
        assert_eq!(first.then(Pen::Up, PenDepth::FULL), None, "up already");
        let down = first.then(Pen::Down, PenDepth::FULL).unwrap();
        let up_again = down.then(Pen::Up, PenDepth::FULL).unwrap();
        assert_ne!(up_again, first, "sent away and back: another order");
        let s = Settings { pen_lift: 1, pen_settle_ms: 200, ..Settings::default() };
        let mut servo = PenServo::default();
        assert_eq!(servo.update(0, first, &s), (Some(1_000), false));
        assert_eq!(servo.update(199, first, &s), (None, false));
        assert_eq!(servo.update(200, first, &s), (None, true));
        assert_eq!(servo.update(300, down, &s), (Some(2_000), false));
        assert_eq!(servo.update(500, down, &s), (None, true));
        let none = Settings::default();
        assert_eq!(PenServo::default().update(0, down, &none), (None, true), "no pen lift");
    }
}
