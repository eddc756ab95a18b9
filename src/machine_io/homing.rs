//! The homing cycle (`$H`) as GRBL runs it: which moves it makes, what each must find, and
//! where it leaves machine zero. Pure logic: the homing task (`tasks::homing`) hands the moves to
//! the motion task one by one and checks each when the machine has stopped.
//!
//! Each axis is homed in turn, X then Y, towards the end `$23` names:
//!
//! 1. seek the switch at the seek feed (`$25`), for up to 1.5 times the whole travel;
//! 2. pull off it by `$27` at the seek feed;
//! 3. locate it again at the slow locate feed (`$24`), for up to 5 pull-offs;
//! 4. pull off again: the switch must have released.
//!
//! An approach ends when the pulse engine finds its switch (the limit switch ahead is watched
//! while homing, hard limits or not). After each move the cycle waits `$26` for the switch to
//! settle. Once both axes are done, the switch found marks the end of the travel: machine zero is
//! `$130` (`$131`) inside it, the middle of the travel, and the pen is a pull-off off the switch.

use crate::geom::Axis;
use crate::settings::Settings;

/// The seek goes at most this many whole travels (`2 × $130`) before homing fails: from any
/// point of the travel, further than the switch can be.
pub const HOMING_SEEK_TRAVELS: f32 = 1.5;

/// The locate approach goes at most this many pull-offs before homing fails.
pub const HOMING_LOCATE_PULL_OFFS: f32 = 5.0;

/// The axes homed, in order.
pub const HOMING_ORDER: [Axis; 2] = [Axis::X, Axis::Y];

/// One of the four moves of an axis' cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Phase {
    Seek,
    PullOff,
    Locate,
    Release,
}

impl Phase {
    /// The moves of an axis, in order.
    pub const ALL: [Phase; 4] = [Phase::Seek, Phase::PullOff, Phase::Locate, Phase::Release];

    /// True for the moves that must end on the switch; the others move away from it.
    pub const fn approaches(self) -> bool {
        matches!(self, Phase::Seek | Phase::Locate)
    }
}

/// Why a homing cycle failed, with GRBL's alarm for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum HomingFail {
    /// A reset or an abort stopped the cycle (`ALARM:6`).
    Aborted,
    /// The switch was still pressed after a pull-off (`ALARM:8`).
    PullOff(Axis),
    /// An approach ended without finding its switch (`ALARM:9`).
    Approach(Axis),
}

/// One homing move: `steps` along `axis` (signed) at `feed_mm_per_min`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct HomingMove {
    pub axis: Axis,
    pub phase: Phase,
    pub steps: i32,
    pub feed_mm_per_min: f32,
}

/// True when `axis` homes towards its max switch (its `$23` bit clear).
pub fn towards_max(settings: &Settings, axis: Axis) -> bool {
    settings.homing_dir_mask & (1 << axis.index()) == 0
}

/// The move of `phase` in the cycle of `axis`.
pub fn homing_move(settings: &Settings, axis: Axis, phase: Phase) -> HomingMove {
    let travel = settings.configured_travel_steps()[axis.index()];
    let pull_off = settings.mm_to_steps(axis, settings.homing_pull_off_mm).max(1);
    let (distance, feed_mm_per_min) = match phase {
        Phase::Seek => {
            (crate::math::ceil(2.0 * travel as f32 * HOMING_SEEK_TRAVELS) as i32, settings.homing_seek_mm_per_min)
        }
        Phase::Locate => {
            (crate::math::ceil(pull_off as f32 * HOMING_LOCATE_PULL_OFFS) as i32, settings.homing_locate_mm_per_min)
        }
        Phase::PullOff | Phase::Release => (pull_off, settings.homing_seek_mm_per_min),
    };
    let towards_switch = if towards_max(settings, axis) { 1 } else { -1 };
    let steps = if phase.approaches() { distance } else { -distance } * towards_switch;
    HomingMove { axis, phase, steps, feed_mm_per_min }
}

/// The machine position of `axis` once its cycle is done: a pull-off inside the end of the
/// travel its switch marks.
pub fn homed_steps(settings: &Settings, axis: Axis) -> i32 {
    let travel = settings.configured_travel_steps()[axis.index()];
    let pull_off = settings.mm_to_steps(axis, settings.homing_pull_off_mm).max(1);
    if towards_max(settings, axis) { travel - pull_off } else { pull_off - travel }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    #[test]
    fn each_axis_seeks_pulls_off_locates_slowly_and_pulls_off_towards_its_end() {
        // ±200 mm at 100 steps/mm; X homes to its max end, Y to its min end.
        let s = Settings { homing_dir_mask: 0b10, homing_pull_off_mm: 2.0, ..Settings::default() };
        let x: Vec<_> = Phase::ALL.iter().map(|&p| homing_move(&s, Axis::X, p)).collect();
        let steps: Vec<_> = x.iter().map(|m| m.steps).collect();
        assert_eq!(steps, [60_000, -200, 1_000, -200]);
        let feeds: Vec<_> = x.iter().map(|m| m.feed_mm_per_min).collect();
        assert_eq!(feeds, [1_000.0, 1_000.0, 100.0, 1_000.0]);
        let y: Vec<_> = Phase::ALL.iter().map(|&p| homing_move(&s, Axis::Y, p).steps).collect();
        assert_eq!(y, [-60_000, 200, -1_000, 200]);
        assert_eq!(homed_steps(&s, Axis::X), 19_800);
        assert_eq!(homed_steps(&s, Axis::Y), -19_800);
    }

    #[test]
    fn a_pull_off_is_at_least_one_step() {
        let s = Settings { steps_per_mm: [1.0, 1.0], homing_pull_off_mm: 0.1, ..Settings::default() };
        assert_eq!(homing_move(&s, Axis::X, Phase::PullOff).steps, 1);
        assert_eq!(homed_steps(&s, Axis::X), -199);
    }
}
