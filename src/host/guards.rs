//! The host link's guards: when a line and each command it gives may act, and what each answers.
//! Pure logic; the serial task ([`crate::tasks::serial`]) waits, calls it, and carries out what
//! it says on the machine and the link.
//!
//! It owns these rules:
//! - where a line is parsed from: where the plan ends (once an abort has stopped, if one is
//!   braking), except in check mode, where the parser plans on from the lines it checked;
//! - a line that changes what a power cycle keeps (G10, G28.1, G30.1) is kept only with the
//!   machine stopped, and parsed again from where the pen stands once it is;
//! - `$X` and `$H` are refused while a driver alarm or the e-stop is still active (they would
//!   trip again at once), with a message and `error:9`, and change nothing;
//! - what each command waits for before it acts: G4 and M0 the motion before them to end, M3/M5
//!   the pen, M2/M30 the pen raised where a pen lift is set (else the motion's end), a setting,
//!   `$RST`, `$N`, `$I=` and `$SLP` the machine at rest, `$H` (and `$X` after a trip) the machine
//!   stopped;
//! - what each answers before the line's `ok`: `[MSG:Pgm End]`, `[MSG:Sleeping]`,
//!   `[MSG:Enabled]`/`[MSG:Disabled]` (then a restart), `[MSG:Caution: Unlocked]`, a report; `$H`
//!   waits for the cycle's end and is refused with `error:9` if it failed;
//! - a setting the settings refuse: `error:15` with a message when it would strand the pen
//!   outside the travel, else `error:3`;
//! - the startup blocks run after a reset unless the machine is in an alarm.

use crate::host::{Command, GrblError, Report};
use crate::machine_io::inputs::{InputLevels, InputSetup};
use crate::machine_io::pen::{self, Pen, PenDepth};
use crate::settings::{SettingError, Settings};
use crate::status::RunState;

/// Said before `error:9` when `$X` or `$H` finds a stop still active.
pub const STOP_ACTIVE_MESSAGE: &str = "Driver alarm or e-stop still active";
/// Said before `error:15` when a setting would leave the pen outside the travel.
pub const STRANDS_PEN_MESSAGE: &str = "The pen would be outside the travel: setting refused";

/// What the machine reports that the guards depend on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reported {
    /// The levels of the machine's inputs now.
    pub input_levels: InputLevels,
    /// A trip halted the machine and `$X` has not yet let the pulses out again.
    pub halted: bool,
}

/// What a command waits for before it acts (or, for `$H`, before it is answered).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wait {
    /// Nothing: it acts at once.
    None,
    /// Nothing queued or moving: idle, or stopped in an alarm.
    AtRest,
    /// Nothing queued, planned or moving, held or not, and no homing cycle: the position is
    /// final.
    Stopped,
    /// At rest, then the pen sent here (this deep when down) and settled.
    Pen(Pen, PenDepth),
    /// At rest, then this many milliseconds more.
    Dwell { ms: u32 },
}

/// What a command answers before the line's `ok`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Answer {
    None,
    /// `[MSG:...]`.
    Message(&'static str),
    /// A report (`$`, `$$`, `$G`, `$#`, `$I`, `$N`).
    Report(Report),
}

/// Why a command was refused: the line is answered `error:N`, after `message` if there is one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refusal {
    pub error: GrblError,
    pub message: Option<&'static str>,
}

impl Refusal {
    /// Refused with `error`, nothing said before it.
    pub const fn error(error: GrblError) -> Refusal {
        Refusal { error, message: None }
    }
}

/// How a command that was not refused is carried out: wait for `before`, act, wait for
/// `after`, then [`Course::answer`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Course {
    pub before: Wait,
    /// `$H`: the homing cycle it started ends with the machine stopped.
    pub after: Wait,
    answer: Answer,
    /// In an alarm once `after` is over, the command failed (a homing cycle that failed raised
    /// it): `error:9` instead of the answer.
    alarm_fails: bool,
    /// The parser starts over once the line is answered (leaving check mode).
    pub restart_after_answer: bool,
}

impl Course {
    /// What the command answers once it acted and `after` is over, the machine then in `state`.
    pub fn answer(&self, state: RunState) -> Result<Answer, Refusal> {
        if self.alarm_fails && state == RunState::Alarm {
            return Err(Refusal::error(GrblError::Locked));
        }
        Ok(self.answer)
    }
}

/// How `command` is carried out, the machine reporting `machine` and set up by `settings`, or
/// why it is refused before it changes anything. A job is handed to the motion task, waiting
/// for room: nothing here.
pub fn course(command: &Command, machine: Reported, settings: &Settings) -> Result<Course, Refusal> {
    let stops_active = InputSetup::from_settings(settings).stops_active(machine.input_levels) != 0;
    if matches!(command, Command::Unlock | Command::Home) && stops_active {
        return Err(Refusal { error: GrblError::Locked, message: Some(STOP_ACTIVE_MESSAGE) });
    }
    let plain = Course {
        before: Wait::None,
        after: Wait::None,
        answer: Answer::None,
        alarm_fails: false,
        restart_after_answer: false,
    };
    let message = |text| Course { answer: Answer::Message(text), ..plain };
    Ok(match *command {
        Command::Job(_) => plain,
        Command::Dwell { ms } => Course { before: Wait::Dwell { ms }, ..plain },
        Command::Pen(pen, depth) => Course { before: Wait::Pen(pen, depth), ..plain },
        // M2/M30 turn the spindle off: a pen lift raises the pen.
        Command::ProgramEnd => Course {
            before: pen::at_program_end(settings).map_or(Wait::AtRest, |pen| Wait::Pen(pen, PenDepth::FULL)),
            ..message("Pgm End")
        },
        // The hold starts once the motion before it has ended.
        Command::Pause => Course { before: Wait::AtRest, ..plain },
        // A setting applies to the motion after it, never under a move: the planner takes new
        // limits at rest (see `Planner::set_limits`), so the lines before it end first. What a
        // power cycle keeps changes only at rest.
        Command::SetSetting { .. }
        | Command::RestoreSettings { .. }
        | Command::StoreStartupLine { .. }
        | Command::StoreBuildInfo(_) => Course { before: Wait::AtRest, ..plain },
        Command::Sleep => Course { before: Wait::AtRest, ..message("Sleeping") },
        Command::Report(kind) => Course { answer: Answer::Report(kind), ..plain },
        Command::CheckMode { on: true } => message("Enabled"),
        Command::CheckMode { on: false } => Course { restart_after_answer: true, ..message("Disabled") },
        Command::Home => Course { before: Wait::Stopped, after: Wait::Stopped, alarm_fails: true, ..plain },
        // The motion task drops what a trip cut short before the pulses may go on.
        Command::Unlock => {
            Course { before: if machine.halted { Wait::Stopped } else { Wait::None }, ..message("Caution: Unlocked") }
        }
    })
}

/// Why a setting the settings refused is refused on the link.
pub fn setting_refused(e: SettingError) -> Refusal {
    match e {
        SettingError::StrandsPen => Refusal { error: GrblError::TravelExceeded, message: Some(STRANDS_PEN_MESSAGE) },
        SettingError::Unknown | SettingError::OutOfRange => Refusal::error(GrblError::InvalidStatement),
    }
}

/// Where a line is parsed from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineStart<E> {
    /// Where the plan ends is not known (an abort is braking): once the machine has stopped,
    /// the line is taken again.
    AgainAfterStop,
    /// The line's jobs are planned from `end`; `from_end`: the parser's position moves there
    /// first (not in check mode, where it plans on from the lines it checked).
    Parse { end: E, from_end: bool },
}

/// Where a line is parsed from, the plan ending at `plan_end` (`None` while an abort brakes)
/// and the machine, as a line sees it, in `state`.
pub fn line_start<E>(plan_end: Option<E>, state: RunState) -> LineStart<E> {
    match plan_end {
        None => LineStart::AgainAfterStop,
        Some(end) => LineStart::Parse { end, from_end: state != RunState::Check },
    }
}

/// True when a line parsed is dropped unrun and parsed again once the machine has stopped: it
/// changes what a power cycle keeps (`changes_kept`) and the machine is not `stopped`.
pub fn kept_change_waits(changes_kept: bool, stopped: bool) -> bool {
    changes_kept && !stopped
}

/// True when the startup blocks run after a reset, the machine in `state`: not in an alarm.
pub fn startup_blocks_run(state: RunState) -> bool {
    state != RunState::Alarm
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::startup::StartupLine;
    use crate::machine_io::inputs::{DRIVER_ALARM_X, ESTOP};

    /// Inputs at rest, no trip.
    const CALM: Reported = Reported { input_levels: 0, halted: false };

    fn watching_inputs() -> Settings {
        Settings { estop_input: true, driver_alarm_input: true, ..Settings::default() }
    }

    fn pen_lift() -> Settings {
        Settings { pen_lift: 1, ..Settings::default() }
    }

    fn carried(command: Command, machine: Reported, settings: &Settings) -> Course {
        course(&command, machine, settings).expect("not refused")
    }

    /// What `command` waits for first and answers, on a calm machine with default settings.
    fn before_and_answer(command: Command) -> (Wait, Answer) {
        let c = carried(command, CALM, &Settings::default());
        (c.before, c.answer(RunState::Idle).expect("answered"))
    }

    #[test]
    fn unlock_or_home_with_the_estop_still_pressed_is_refused_with_a_message_and_error_9() {
        let pressed = Reported { input_levels: ESTOP, halted: true };
        for command in [Command::Unlock, Command::Home] {
            let refusal = course(&command, pressed, &watching_inputs()).expect_err("refused");
            assert_eq!(refusal.error.code(), 9);
            assert_eq!(refusal.message, Some(STOP_ACTIVE_MESSAGE));
        }
        let driver = Reported { input_levels: DRIVER_ALARM_X, halted: true };
        assert!(course(&Command::Unlock, driver, &watching_inputs()).is_err(), "a driver alarm too");
    }

    #[test]
    fn an_estop_that_is_not_watched_or_released_does_not_hold_back_unlock() {
        let pressed = Reported { input_levels: ESTOP, halted: false };
        assert!(course(&Command::Unlock, pressed, &Settings::default()).is_ok(), "$208=0: not wired");
        assert!(course(&Command::Unlock, CALM, &watching_inputs()).is_ok(), "released");
    }

    #[test]
    fn other_lines_pass_while_the_estop_is_pressed() {
        let pressed = Reported { input_levels: ESTOP, halted: true };
        let report = course(&Command::Report(Report::Settings), pressed, &watching_inputs());
        assert!(report.is_ok(), "`$$` is answered in an alarm");
    }

    #[test]
    fn unlock_after_a_trip_waits_for_the_machine_to_stop_then_says_caution() {
        let tripped = carried(Command::Unlock, Reported { halted: true, ..CALM }, &Settings::default());
        assert_eq!(tripped.before, Wait::Stopped);
        assert_eq!(tripped.answer(RunState::Idle), Ok(Answer::Message("Caution: Unlocked")));
        let (before, _) = before_and_answer(Command::Unlock);
        assert_eq!(before, Wait::None, "no trip: unlocks at once");
    }

    #[test]
    fn home_waits_for_a_stop_then_for_the_cycle_and_answers_error_9_if_it_failed() {
        let home = carried(Command::Home, CALM, &Settings::default());
        assert_eq!((home.before, home.after), (Wait::Stopped, Wait::Stopped));
        assert_eq!(home.answer(RunState::Idle), Ok(Answer::None), "homed: just `ok`");
        assert_eq!(home.answer(RunState::Alarm).map_err(|r| r.error.code()), Err(9), "the cycle failed");
    }

    #[test]
    fn only_home_fails_on_an_alarm_after_it_acted() {
        let unlock = carried(Command::Unlock, CALM, &Settings::default());
        assert!(unlock.answer(RunState::Alarm).is_ok());
        let report = carried(Command::Report(Report::ParserState), CALM, &Settings::default());
        assert_eq!(report.answer(RunState::Alarm), Ok(Answer::Report(Report::ParserState)));
    }

    #[test]
    fn program_end_with_a_pen_lift_raises_the_pen_before_pgm_end() {
        let end = carried(Command::ProgramEnd, CALM, &pen_lift());
        assert_eq!(end.before, Wait::Pen(Pen::Up, PenDepth::FULL));
        assert_eq!(end.answer(RunState::Idle), Ok(Answer::Message("Pgm End")));
        let (before, answer) = before_and_answer(Command::ProgramEnd);
        assert_eq!((before, answer), (Wait::AtRest, Answer::Message("Pgm End")), "no pen lift: the pen stays");
    }

    #[test]
    fn a_setting_and_what_a_power_cycle_keeps_wait_for_the_machine_to_rest_and_answer_only_ok() {
        let line = StartupLine::try_from("G21").expect("fits");
        for command in [
            Command::SetSetting { id: 110, value: 3000.0 },
            Command::RestoreSettings { startup_lines: true },
            Command::StoreStartupLine { index: 0, line: line.clone() },
            Command::StoreBuildInfo(line),
        ] {
            assert_eq!(before_and_answer(command.clone()), (Wait::AtRest, Answer::None), "{command:?}");
        }
    }

    #[test]
    fn sleep_waits_for_rest_then_says_sleeping() {
        assert_eq!(before_and_answer(Command::Sleep), (Wait::AtRest, Answer::Message("Sleeping")));
    }

    #[test]
    fn dwell_pen_and_pause_wait_for_the_motion_before_them_and_answer_only_ok() {
        assert_eq!(before_and_answer(Command::Dwell { ms: 250 }), (Wait::Dwell { ms: 250 }, Answer::None));
        let down = Command::Pen(Pen::Down, PenDepth::FULL);
        assert_eq!(before_and_answer(down), (Wait::Pen(Pen::Down, PenDepth::FULL), Answer::None));
        assert_eq!(before_and_answer(Command::Pause), (Wait::AtRest, Answer::None));
    }

    #[test]
    fn reports_answer_at_once_without_a_wait() {
        for kind in [
            Report::Help,
            Report::Settings,
            Report::ParserState,
            Report::Parameters,
            Report::BuildInfo,
            Report::StartupLines,
        ] {
            assert_eq!(before_and_answer(Command::Report(kind)), (Wait::None, Answer::Report(kind)));
        }
    }

    #[test]
    fn check_mode_says_enabled_and_leaving_it_says_disabled_then_restarts() {
        let on = carried(Command::CheckMode { on: true }, CALM, &Settings::default());
        assert_eq!((on.answer(RunState::Idle), on.restart_after_answer), (Ok(Answer::Message("Enabled")), false));
        let off = carried(Command::CheckMode { on: false }, CALM, &Settings::default());
        assert_eq!((off.answer(RunState::Check), off.restart_after_answer), (Ok(Answer::Message("Disabled")), true));
    }

    #[test]
    fn a_setting_that_strands_the_pen_is_error_15_with_a_message_and_a_bad_one_error_3() {
        let strands = setting_refused(SettingError::StrandsPen);
        assert_eq!((strands.error.code(), strands.message), (15, Some(STRANDS_PEN_MESSAGE)));
        for e in [SettingError::Unknown, SettingError::OutOfRange] {
            assert_eq!(setting_refused(e), Refusal::error(GrblError::InvalidStatement), "{e:?}");
        }
    }

    #[test]
    fn a_line_starts_where_the_plan_ends_once_known_and_check_mode_plans_on_from_its_lines() {
        assert_eq!(line_start::<u8>(None, RunState::Run), LineStart::AgainAfterStop, "an abort brakes");
        assert_eq!(line_start(Some(7), RunState::Run), LineStart::Parse { end: 7, from_end: true });
        assert_eq!(line_start(Some(7), RunState::Idle), LineStart::Parse { end: 7, from_end: true });
        assert_eq!(line_start(Some(7), RunState::Check), LineStart::Parse { end: 7, from_end: false });
    }

    #[test]
    fn a_line_changing_what_a_power_cycle_keeps_waits_for_the_machine_to_stop() {
        assert!(kept_change_waits(true, false), "G10 behind a moving program");
        assert!(!kept_change_waits(true, true), "stopped: kept now");
        assert!(!kept_change_waits(false, false), "a move follows the moves before it");
    }

    #[test]
    fn the_startup_blocks_run_after_a_reset_unless_in_an_alarm() {
        assert!(startup_blocks_run(RunState::Idle));
        assert!(!startup_blocks_run(RunState::Alarm));
    }
}
