//! The `$` commands: reports, settings, restores, unlock and `$J=` jogs; the plotter curve
//! commands are handed on to [`super::curves`].

use super::offsets::Offsets;
use super::words::{Group, NonModal, compact, parse_block, parse_number};
use super::{Command, Commands, GcodeState, Report};
use crate::host::GrblError;
use crate::host::startup::{STARTUP_LINES, ascii_line};
use crate::motion::drawing;
use crate::motion::job::{Feed, JobKind};
use crate::settings::{SettingError, Settings};
use crate::status::RunState;

/// Whether a command that acts at rest is taken in `state`: at rest, or while a program runs
/// (the host link then holds it until the program's motion has ended, so it never changes
/// anything under a move); refused (`error:8`) while held, jogging or homing, whose end is the
/// user's, not the program's.
fn waits_for_rest(state: RunState) -> bool {
    matches!(state, RunState::Idle | RunState::Run)
}

impl GcodeState {
    /// A line starting with `$`, its command into `out`; `rest` follows the `$` and is a suffix
    /// of `line`.
    pub(super) fn system(
        &mut self,
        line: &str,
        rest: &str,
        settings: &Settings,
        state: RunState,
        out: &mut Commands,
    ) -> Result<(), GrblError> {
        let c = compact(rest, true)?;
        let command = match c.as_slice() {
            b"" => Command::Report(Report::Help),
            b"$" => Command::Report(Report::Settings),
            b"G" => Command::Report(Report::ParserState),
            b"#" => Command::Report(Report::Parameters),
            b"I" => Command::Report(Report::BuildInfo),
            [b'I', b'=', body @ ..] => {
                if !waits_for_rest(state) {
                    return Err(GrblError::NotIdle);
                }
                // Compacted text is ASCII: only its length can refuse it.
                Command::StoreBuildInfo(ascii_line(body).ok_or(GrblError::LineLengthExceeded)?)
            }
            b"X" => Command::Unlock,
            b"C" => match state {
                RunState::Check => Command::CheckMode { on: false },
                RunState::Idle => Command::CheckMode { on: true },
                _ => return Err(GrblError::NotIdle),
            },
            b"H" if !settings.homing => return Err(GrblError::SettingDisabled),
            b"H" if matches!(state, RunState::Idle | RunState::Alarm) => Command::Home,
            b"H" => return Err(GrblError::NotIdle),
            b"SLP" if waits_for_rest(state) || state == RunState::Alarm => Command::Sleep,
            b"SLP" => return Err(GrblError::NotIdle),
            b"N" => Command::Report(Report::StartupLines),
            [b'N', index @ b'0'..=b'9', b'=', body @ ..] => self.startup_line(*index - b'0', body, settings, state)?,
            [b'R', b'S', b'T', b'=', what] => match self.restore(*what, settings, state)? {
                Some(command) => command,
                None => return Ok(()),
            },
            [b'J', b'=', body @ ..] => return self.jog(body, settings, state, &mut out.main),
            [b'0'..=b'9', ..] => self.set_setting(&c, settings, state)?,
            [which @ (b'E' | b'O' | b'S'), ..] => {
                if matches!(state, RunState::Alarm | RunState::Jog | RunState::Home) {
                    return Err(GrblError::Locked);
                }
                return self.plotter_curve(*which, c.get(1..).unwrap_or(&[]), settings, out);
            }
            [b'F', ..] => {
                if matches!(state, RunState::Alarm | RunState::Jog | RunState::Home) {
                    return Err(GrblError::Locked);
                }
                return self.function(line, rest, settings, out);
            }
            _ => return Err(GrblError::InvalidStatement),
        };
        out.main = Some(command);
        Ok(())
    }

    /// `$id=value`.
    fn set_setting(&mut self, c: &[u8], settings: &Settings, state: RunState) -> Result<Command, GrblError> {
        if !(waits_for_rest(state) || state == RunState::Alarm) {
            return Err(GrblError::NotIdle);
        }
        let eq = c.iter().position(|&b| b == b'=').ok_or(GrblError::InvalidStatement)?;
        let (id_text, value_text) = (&c[..eq], &c[eq + 1..]);
        if id_text.len() > 5 || !id_text.iter().all(u8::is_ascii_digit) {
            return Err(GrblError::InvalidStatement);
        }
        let id = id_text.iter().fold(0u32, |n, d| n * 10 + (d - b'0') as u32);
        let id = u16::try_from(id).map_err(|_| GrblError::InvalidStatement)?;
        let value = parse_number(value_text)?;
        let mut next = *settings;
        next.set(id, value).map_err(|e| match e {
            SettingError::OutOfRange if value < 0.0 => GrblError::NegativeValue,
            SettingError::Unknown | SettingError::OutOfRange => GrblError::InvalidStatement,
            SettingError::StrandsPen => GrblError::TravelExceeded,
        })?;
        self.rescale(&next);
        Ok(Command::SetSetting { id, value })
    }

    /// `$Nn=line`: `line` (compacted) is checked as a line run at rest, and stored if it parses
    /// and moves nothing: a startup block runs after every reset, when no one may expect the pen
    /// to move. An empty line clears the block.
    fn startup_line(&self, index: u8, body: &[u8], settings: &Settings, state: RunState) -> Result<Command, GrblError> {
        if !waits_for_rest(state) {
            return Err(GrblError::NotIdle);
        }
        if usize::from(index) >= STARTUP_LINES {
            return Err(GrblError::InvalidStatement);
        }
        // Compacted text is ASCII: only its length can refuse it.
        let line = ascii_line(body).ok_or(GrblError::LineLengthExceeded)?;
        let text = line.as_str();
        if !text.is_empty() {
            if text.starts_with('$') {
                return Err(GrblError::InvalidStatement);
            }
            let mut trial = *self;
            trial.run_startup_block(text, settings)?;
        }
        Ok(Command::StoreStartupLine { index, line })
    }

    /// `$RST=$`, `$RST=#`, `$RST=*`; `None` when only the coordinate data is cleared.
    fn restore(&mut self, what: u8, settings: &Settings, state: RunState) -> Result<Option<Command>, GrblError> {
        if !matches!(what, b'$' | b'#' | b'*') {
            return Err(GrblError::InvalidStatement);
        }
        // Coordinate data is cleared as the line is parsed: never behind a running program.
        if !matches!(state, RunState::Idle | RunState::Alarm) {
            return Err(GrblError::NotIdle);
        }
        if what != b'$' {
            // G54–G59, G28, G30 and G92; the active system stays selected.
            self.offsets = Offsets::new();
        }
        if what == b'#' {
            return Ok(None);
        }
        let defaults = Settings::default();
        if defaults.steps_per_mm != settings.steps_per_mm {
            self.rescale(&defaults);
        }
        Ok(Some(Command::RestoreSettings { startup_lines: what == b'*' }))
    }

    /// Keeps the planned position on the same step when steps/mm change.
    fn rescale(&mut self, next: &Settings) {
        let position = self.position;
        self.sync_position(position, next);
    }

    /// `$J=` followed by `body` (compacted): the jog into `slot`.
    fn jog(
        &mut self,
        body: &[u8],
        settings: &Settings,
        state: RunState,
        slot: &mut Option<Command>,
    ) -> Result<(), GrblError> {
        if !matches!(state, RunState::Idle | RunState::Jog) {
            return Err(GrblError::NotIdle);
        }
        let block = parse_block(body)?;
        let mut words = block.words;
        let units = block.units.unwrap_or(self.units);
        let distance = block.distance.unwrap_or(self.distance);
        let f = words.take(b'F').ok_or(GrblError::UndefinedFeedRate)?;
        let feed = f * units.mm_per_unit();
        if !(feed > 0.0) {
            return Err(GrblError::UndefinedFeedRate);
        }
        let allowed = Group::Distance.bit() | Group::Units.bit() | Group::NonModal.bit();
        if block.groups & !allowed != 0 || !matches!(block.non_modal, None | Some(NonModal::MachineCoords)) {
            return Err(GrblError::InvalidJog);
        }
        words.take(b'N');
        let axis = [words.take(b'X'), words.take(b'Y')];
        let has_z = words.take(b'Z').is_some();
        if !words.is_empty() {
            return Err(GrblError::InvalidJog);
        }
        if axis == [None, None] {
            // A Z-only jog (a sender's Z buttons) moves nothing.
            return if has_z { Ok(()) } else { Err(GrblError::NoAxisWords) };
        }
        let machine = block.non_modal == Some(NonModal::MachineCoords);
        let target = self.target_mm(axis.map(|v| v.map(|v| v * units.mm_per_unit())), distance, machine);
        let to = drawing::line_target(target, settings).ok_or(GrblError::TravelExceeded)?;
        self.straight(to, target, Feed::MmPerMin(feed), JobKind::Jog, settings, slot)
    }
}
