//! A snapshot of the parser state a later line depends on, but for the planned position: the
//! modal groups, the feed rate, S and T, and every offset (G54–G59, G28, G30, G92). A card plot
//! keeps one with each line it completes, so that after a power cut the parser can be rebuilt
//! as it was there ([`GcodeState::resumed`]) and parse the rest of the file as it would have.

use super::GcodeState;
use super::modal::{Coolant, Distance, MotionMode, Spindle, Units, WorkSystem};
use super::offsets::{KEPT_OFFSETS, Offsets};
use crate::geom::Point;
use crate::settings::Settings;

/// The parser's modal state and offsets; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Modal {
    pub motion: MotionMode,
    pub units: Units,
    pub distance: Distance,
    pub work_system: WorkSystem,
    pub spindle: Spindle,
    pub coolant: Coolant,
    /// The last F word, `None` before one (the default feed rate applies).
    pub feed_mm_per_min: Option<f32>,
    /// The last S word, `None` before one.
    pub spindle_speed: Option<f32>,
    pub tool: u8,
    /// G54 to G59, then G28 and G30, machine millimetres ([`Offsets::kept_mm`]).
    pub kept_mm: [[f32; 2]; KEPT_OFFSETS],
    /// The G92 offset, millimetres.
    pub g92_mm: [f32; 2],
}

impl GcodeState {
    /// The state's snapshot: everything but the planned position.
    pub fn modal(&self) -> Modal {
        Modal {
            motion: self.motion,
            units: self.units,
            distance: self.distance,
            work_system: self.work_system,
            spindle: self.spindle,
            coolant: self.coolant,
            feed_mm_per_min: self.feed_mm_per_min,
            spindle_speed: self.spindle_speed,
            tool: self.tool,
            kept_mm: self.offsets.kept_mm(),
            g92_mm: self.offsets.g92_mm(),
        }
    }

    /// The state `modal` was taken of, with the pen planned at `position` (steps; its
    /// millimetres are the step's own, as after a reset).
    pub fn resumed(modal: &Modal, position: Point, settings: &Settings) -> GcodeState {
        let mut offsets = Offsets::from_kept_mm(modal.kept_mm);
        offsets.set_g92_mm(modal.g92_mm);
        let mut state = GcodeState {
            motion: modal.motion,
            units: modal.units,
            distance: modal.distance,
            work_system: modal.work_system,
            spindle: modal.spindle,
            coolant: modal.coolant,
            feed_mm_per_min: modal.feed_mm_per_min,
            spindle_speed: modal.spindle_speed,
            tool: modal.tool,
            offsets,
            ..GcodeState::new()
        };
        state.sync_position(position, settings);
        state
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use std::vec::Vec;

    use super::*;
    use crate::host::gcode::Command;
    use crate::status::RunState;

    /// The commands each of `lines` hands out, and the state after them.
    fn run_all(mut state: GcodeState, lines: &[&str], settings: &Settings) -> (Vec<Vec<Command>>, GcodeState) {
        let out = lines
            .iter()
            .map(|l| state.execute(l, settings, RunState::Idle).map(|c| c.collect()).unwrap_or_default())
            .collect();
        (out, state)
    }

    /// Runs `before`, rebuilds a state from its snapshot and planned position, and checks that
    /// `after` gives the same commands and ends in the same state from both.
    fn resumes_alike(before: &[&str], after: &[&str]) {
        let settings = Settings::default();
        let (_, original) = run_all(GcodeState::new(), before, &settings);
        let rebuilt = GcodeState::resumed(&original.modal(), original.planned_position(), &settings);
        assert_eq!(rebuilt, original, "rebuilt after {before:?}");
        let (expected, end) = run_all(original, after, &settings);
        let (got, rebuilt_end) = run_all(rebuilt, after, &settings);
        assert!(expected.iter().any(|c| !c.is_empty()), "the lines after {before:?} move");
        assert_eq!(got, expected);
        assert_eq!(rebuilt_end, end);
    }

    #[test]
    fn a_rebuilt_state_parses_the_next_lines_as_the_original() {
        resumes_alike(&["G1 X10 Y5 F1200"], &["X20", "G91 Y-2", "G2 X4 Y0 I2 J0", "G90 G0 X0 Y0"]);
        resumes_alike(&["G20 G91 F40", "G1 X0.5", "M3 S500 T7"], &["X0.25 Y0.25", "G90 X1", "G0 Y0"]);
        resumes_alike(
            &["G10 L2 P2 X5 Y6", "G55", "G92 X1 Y1", "G28.1", "G0 X3 Y2", "G30.1", "G3 X5 Y4 R2 F900"],
            &["G1 X0 Y0", "G28", "G54 G0 X1", "G30 X2", "G92.1 X0"],
        );
        resumes_alike(&["G80", "M8"], &["G0 X2", "G1 Y3 F100"]);
    }

    #[test]
    fn the_snapshot_is_the_state_but_its_position() {
        let settings = Settings::default();
        let (_, state) = run_all(GcodeState::new(), &["G91 G1 X3 F500", "G56 M4 S20"], &settings);
        let modal = state.modal();
        assert_eq!(modal.motion, MotionMode::Linear);
        assert_eq!(modal.distance, Distance::Incremental);
        assert_eq!(modal.work_system.gcode(), 56);
        assert_eq!(modal.feed_mm_per_min, Some(500.0));
        assert_eq!(modal.spindle, Spindle::Ccw);
        let elsewhere = GcodeState::resumed(&modal, Point::new(-250, 40), &settings);
        assert_eq!(elsewhere.modal(), modal);
        assert_eq!(elsewhere.planned_position(), Point::new(-250, 40));
    }
}
