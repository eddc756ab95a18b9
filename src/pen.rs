//! The pen lift: an RC servo that holds the pen up or down, and which moves need the pen where.
//! Pure logic; the servo task drives the servo's PWM from [`Machine::pen`](crate::machine::Machine::pen)
//! and counts the settle time, the motion task changes the pen only at rest and starts no pulse
//! before the pen has settled.
//!
//! `$213` says how the pen is lifted ([`PenLift`]): not at all (no pen servo: the pen is
//! always down, as on a plotter with a fixed pen), by `M3`/`M4` (down) and `M5` (up), or by
//! itself as well: up for rapid moves (`G0`), down for every drawing move (`G1`–`G3` and the
//! curve commands).

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

/// One order to the pen: where, and which order it is (bit 0 set for down, above it a count of
/// the orders). An order the servo task settled is told apart from a later one to the same
/// place, so a pen sent away and back while the servo task looked elsewhere never counts as
/// settled early.
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

    /// The order that sends the pen to `pen`; `None` when it is sent there already.
    pub fn then(self, pen: Pen) -> Option<PenOrder> {
        let down = u32::from(pen == Pen::Down);
        (self.0 & 1 != down).then(|| PenOrder(((self.0 >> 1).wrapping_add(1) << 1) | down))
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
        let pulse = pulse_us(settings, order.pen());
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

/// The servo pulse that holds `pen`, µs.
pub fn pulse_us(settings: &Settings, pen: Pen) -> u32 {
    match pen {
        Pen::Up => settings.pen_up_us,
        Pen::Down => settings.pen_down_us,
    }
}

/// Where a move needs the pen, a rapid (`G0`) or not, with the spindle (`M3`/`M4`) on or not;
/// `None` when nothing lifts the pen.
pub fn for_move(settings: &Settings, rapid: bool, spindle_on: bool) -> Option<Pen> {
    match PenLift::of(settings) {
        PenLift::None => None,
        PenLift::Auto if rapid => Some(Pen::Up),
        PenLift::Auto => Some(Pen::Down),
        PenLift::Spindle => Some(if spindle_on { Pen::Down } else { Pen::Up }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_mode_puts_the_pen_where_a_move_needs_it() {
        let mode = |pen_lift| Settings { pen_lift, ..Settings::default() };
        assert_eq!(for_move(&mode(0), true, true), None, "no pen servo");
        assert_eq!(for_move(&mode(1), true, true), Some(Pen::Down), "M3: down, rapid or not");
        assert_eq!(for_move(&mode(1), false, false), Some(Pen::Up), "M5: up, drawing or not");
        assert_eq!(for_move(&mode(2), true, true), Some(Pen::Up), "auto: rapids travel up");
        assert_eq!(for_move(&mode(2), false, false), Some(Pen::Down), "auto: drawing moves draw");
        let s = Settings::default();
        assert_eq!((pulse_us(&s, Pen::Up), pulse_us(&s, Pen::Down)), (1_000, 2_000));
    }

    #[test]
    fn an_order_counts_and_the_servo_settles_for_the_last_one() {
        let first = PenOrder::from_bits(0);
        assert_eq!(first.then(Pen::Up), None, "up already");
        let down = first.then(Pen::Down).unwrap();
        let up_again = down.then(Pen::Up).unwrap();
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
