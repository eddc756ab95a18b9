//! G-code blocks carried out on the parser state: modal groups, non-modal commands (those on
//! the coordinate data through [`super::coordinates`]), and the straight moves and G2/G3 arcs a
//! block hands out, each checked against the travel and its interpolator.

use core::f32::consts::TAU;

use super::words::{Block, NonModal, ProgramStop};
use super::{
    ARC_ANGLE_EPSILON_RAD, ARC_RADIUS_ERROR_MAX_MM, ARC_RADIUS_ERROR_MAX_RATIO, ARC_RADIUS_SLACK_MM, Command, Commands,
    Coolant, DWELL_MAX_MS, Distance, GcodeState, LINE_NUMBER_MAX, MotionMode, Spindle, WorkSystem,
};
use crate::geom::Rotation;
use crate::host::GrblError;
use crate::machine_io::pen;
use crate::motion::drawing::{self, EllipseParams, Request};
use crate::motion::job::{Feed, JobKind};
use crate::settings::Settings;

impl GcodeState {
    /// Executes a parsed block on `self` (a copy [`GcodeState::commit`] keeps only on success),
    /// its commands into `out`.
    pub(super) fn run_block(&mut self, block: Block, settings: &Settings, out: &mut Commands) -> Result<(), GrblError> {
        let mut words = block.words;
        if let Some(n) = words.take(b'N')
            && n > LINE_NUMBER_MAX
        {
            return Err(GrblError::InvalidLineNumber);
        }
        if let Some(u) = block.units {
            self.units = u;
        }
        if let Some(d) = block.distance {
            self.distance = d;
        }
        if let Some(w) = block.work_system {
            self.work_system = w;
        }
        if let Some(s) = block.spindle {
            self.spindle = s;
        }
        if let Some(c) = block.coolant {
            self.coolant = c;
        }
        if let Some(m) = block.motion {
            self.motion = m;
        }
        let scale = self.units.mm_per_unit();
        if let Some(f) = words.take(b'F') {
            self.feed_mm_per_min = Some(f * scale);
        }
        let speed = words.take(b'S');
        if speed.is_some() {
            self.spindle_speed = speed;
        }
        if let Some(t) = words.take(b'T') {
            self.tool = t as u8; // 0..=255, checked when parsed
        }

        // M3/M4/M5, or a new S word under M3/M4 (how deep the pen goes), moves the pen, as
        // GRBL's spindle changes with them once the motion before has ended.
        let spindle_on = self.spindle != Spindle::Off;
        out.pen =
            pen::for_spindle_words(settings, spindle_on, block.spindle.is_some(), speed.is_some(), self.spindle_speed);
        if block.non_modal == Some(NonModal::Dwell) {
            let p = words.take(b'P').ok_or(GrblError::ValueWordMissing)?;
            let ms = crate::math::round(p * 1000.0);
            if !(ms <= DWELL_MAX_MS as f32) {
                return Err(GrblError::MaxValueExceeded);
            }
            out.dwell_ms = Some(ms as u32);
        }

        let axis = [words.get(b'X').map(|v| v * scale), words.get(b'Y').map(|v| v * scale)];
        let has_z = words.get(b'Z').is_some();
        let has_xy = axis[0].is_some() || axis[1].is_some();
        let has_axis = has_xy || has_z;
        let axis_command = if block.non_modal.is_some_and(NonModal::uses_axis_words) {
            AxisCommand::NonModal
        } else if block.motion_word || has_axis {
            AxisCommand::Motion
        } else {
            AxisCommand::None
        };

        match block.non_modal {
            Some(NonModal::MachineCoords) if !matches!(self.motion, MotionMode::Rapid | MotionMode::Linear) => {
                return Err(GrblError::G53InvalidMotionMode);
            }
            Some(command) => self.set_coordinates(command, &mut words, axis, has_axis)?,
            None => {}
        }

        if self.motion == MotionMode::Off {
            // Even G10, G28, G30 and G92 may not have axis words then (GRBL's rule).
            if has_axis {
                return Err(GrblError::AxisWordsExist);
            }
        } else if axis_command == AxisCommand::Motion {
            let machine = block.non_modal == Some(NonModal::MachineCoords);
            let target = self.target_mm(axis, self.distance, machine);
            match self.motion {
                MotionMode::Rapid if has_xy => self.line(target, Feed::Rapid, settings, &mut out.main)?,
                MotionMode::Linear => {
                    let feed = self.checked_feed(settings)?;
                    if has_xy {
                        self.line(target, Feed::MmPerMin(feed), settings, &mut out.main)?;
                    }
                }
                MotionMode::ArcCw | MotionMode::ArcCcw => {
                    let feed = self.checked_feed(settings)?;
                    if !has_axis {
                        return Err(GrblError::NoAxisWords);
                    }
                    if !has_xy {
                        return Err(GrblError::NoAxisWordsInPlane);
                    }
                    let form = match words.take(b'R') {
                        Some(r) => ArcForm::Radius(r * scale),
                        None => {
                            let (i, j) = (words.take(b'I'), words.take(b'J'));
                            words.take(b'K');
                            if i.is_none() && j.is_none() {
                                return Err(GrblError::NoOffsetsInPlane);
                            }
                            ArcForm::Offsets([i.unwrap_or(0.0) * scale, j.unwrap_or(0.0) * scale])
                        }
                    };
                    let rotation =
                        if self.motion == MotionMode::ArcCw { Rotation::Clockwise } else { Rotation::CounterClockwise };
                    self.arc(target, rotation, form, feed, settings, out)?;
                }
                _ => {}
            }
        }
        if let Some(NonModal::GoToStored(which)) = block.non_modal {
            self.go_to_stored(which, axis, has_axis, settings, out)?;
        }

        if axis_command != AxisCommand::None {
            words.take(b'X');
            words.take(b'Y');
            words.take(b'Z');
        }
        if !words.is_empty() {
            return Err(GrblError::UnusedWords);
        }

        if block.stop == Some(ProgramStop::End) {
            // GRBL (after LinuxCNC) resets these groups at program end; units, F, S, T and the
            // offsets stay.
            self.motion = MotionMode::Linear;
            self.distance = Distance::Absolute;
            self.work_system = WorkSystem::G54;
            self.spindle = Spindle::Off;
            self.coolant = Coolant::Off;
        }
        out.stop = block.stop;
        Ok(())
    }

    /// The feed rate for a feed move; zero (an explicit F0) is GRBL's undefined feed rate.
    pub(super) fn checked_feed(&self, settings: &Settings) -> Result<f32, GrblError> {
        let feed = self.feed_mm_per_min(settings);
        if feed > 0.0 { Ok(feed) } else { Err(GrblError::UndefinedFeedRate) }
    }

    /// A straight move to `target_mm` into `slot`; nothing when it ends on the step it starts
    /// from.
    pub(super) fn line(
        &mut self,
        target_mm: [f32; 2],
        feed: Feed,
        settings: &Settings,
        slot: &mut Option<Command>,
    ) -> Result<(), GrblError> {
        let to = drawing::line_target(target_mm, settings).ok_or(GrblError::TravelExceeded)?;
        self.straight(to, target_mm, feed, JobKind::Draw, settings, slot)
    }

    /// G2/G3 from the planned position to `end` (mm): the line's curve, into `out`.
    fn arc(
        &self,
        end: [f32; 2],
        rotation: Rotation,
        form: ArcForm,
        feed_mm_per_min: f32,
        settings: &Settings,
        out: &mut Commands,
    ) -> Result<(), GrblError> {
        let start = self.position_mm;
        let (dx, dy) = (end[0] - start[0], end[1] - start[1]);
        let (center, radius) = match form {
            ArcForm::Radius(r) => {
                if dx == 0.0 && dy == 0.0 {
                    return Err(GrblError::InvalidTarget);
                }
                let h2 = 4.0 * r * r - dx * dx - dy * dy;
                if !(h2 >= 0.0) {
                    return Err(GrblError::ArcRadius);
                }
                // Centre on the perpendicular bisector of the chord; the side follows the
                // rotation, and a negative R takes the other side (the long arc).
                let mut k = -crate::math::sqrt(h2) / crate::math::hypot(dx, dy);
                if rotation == Rotation::CounterClockwise {
                    k = -k;
                }
                if r < 0.0 {
                    k = -k;
                }
                ([start[0] + 0.5 * (dx - dy * k), start[1] + 0.5 * (dy + dx * k)], r.abs())
            }
            ArcForm::Offsets([i, j]) => {
                let center = [start[0] + i, start[1] + j];
                let radius = crate::math::hypot(i, j);
                let delta = (crate::math::hypot(end[0] - center[0], end[1] - center[1]) - radius).abs();
                if delta > ARC_RADIUS_SLACK_MM
                    && (delta > ARC_RADIUS_ERROR_MAX_MM || delta > ARC_RADIUS_ERROR_MAX_RATIO * radius)
                {
                    return Err(GrblError::InvalidTarget);
                }
                (center, radius)
            }
        };
        let (sx, sy) = (start[0] - center[0], start[1] - center[1]);
        let (ex, ey) = (end[0] - center[0], end[1] - center[1]);
        let mut sweep = crate::math::atan2(sx * ey - sy * ex, sx * ex + sy * ey);
        match rotation {
            Rotation::Clockwise if sweep >= -ARC_ANGLE_EPSILON_RAD => sweep -= TAU,
            Rotation::CounterClockwise if sweep <= ARC_ANGLE_EPSILON_RAD => sweep += TAU,
            _ => {}
        }
        let circle = EllipseParams::circle(radius, crate::math::atan2(sy, sx).to_degrees(), sweep.to_degrees());
        self.curve(Request::Ellipse(circle), Feed::MmPerMin(feed_mm_per_min), Some(end), settings, out);
        Ok(())
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum AxisCommand {
    None,
    NonModal,
    Motion,
}

enum ArcForm {
    Radius(f32),
    Offsets([f32; 2]),
}
