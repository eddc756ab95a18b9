//! The G-code and `$` command parser with the machine's state: any bytes as a host's stream,
//! framed into lines as the serial task frames them, each line executed against the parser's
//! modal state and the settings, and what it hands out carried out as the serial task would
//! (settings applied, startup blocks stored, check mode, sleep, unlock; a soft reset, 0x18, runs
//! the startup blocks). Every move is taken as done at once. The first byte picks the state the
//! machine is in while lines arrive (at rest, drawing, held, jogging, homing). The lattice starts
//! coarse (`START_STEPS_PER_MM`), so that curves are cheap to build and many lines get tried.
//!
//! Checks, besides that nothing panics:
//! - a refused line leaves the parser's state as it was (modes, offsets, planned position);
//! - a line built a slice at a time (`parse`, `Pending::advance`, `commit`, as the serial task
//!   builds curves) gives what the same line executed at once gives;
//! - every drawing starts where the one before it ended (the planned position) and ends inside
//!   the travel; outside check mode the planned position is the last drawing's end;
//! - a setting handed out is one `Settings::set` takes;
//! - a startup block refused at a reset changes nothing, and none moves the planned position;
//! - the `$G`, `$#` and `$$` reports write (when a line asks, and at the end of the stream), each
//!   line within `REPORT_LINE_MAX_BYTES`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use servoplot::geom::Point;
use servoplot::host::GrblError;
use servoplot::host::framing::{LineAssembler, LineEvent, Realtime, realtime};
use servoplot::host::gcode::{Command, GcodeState, Pending, Report};
use servoplot::host::report::{REPORT_LINE_MAX_BYTES, Reply};
use servoplot::host::startup::StartupLines;
use servoplot::settings::Settings;
use servoplot::status::RunState;

/// Steps per millimetre on both axes at the start ($100, $101): a coarse lattice, so that a curve
/// costs a few hundred steps to build and the fuzzer tries many lines; a `$100=` line changes it.
const START_STEPS_PER_MM: f32 = 10.0;

/// The states a machine may be in while a line arrives and no mode of the parser's own (check
/// mode, sleep, alarm) holds.
const LINE_STATES: [RunState; 5] = [RunState::Idle, RunState::Run, RunState::Hold, RunState::Jog, RunState::Home];

/// The machine around the parser: what the serial task keeps.
struct Machine {
    gcode: GcodeState,
    settings: Settings,
    startup: StartupLines,
    /// Check mode, sleep or alarm; `None`: `moving` applies.
    mode: Option<RunState>,
    moving: RunState,
    /// Where the pen is: the planned position, but for check mode, which moves nothing.
    pen: Point,
    /// Steps a curve is built by per slice in the sliced build.
    slice_steps: u32,
}

impl Machine {
    fn state(&self) -> RunState {
        self.mode.unwrap_or(self.moving)
    }

    /// One line, as the serial task carries it out.
    fn line(&mut self, line: &str) {
        let before = self.gcode;
        let state = self.state();
        let sliced = self.sliced(line, state);
        let result = self.gcode.execute(line, &self.settings, state).map(Iterator::collect::<Vec<_>>);
        match (&result, &sliced) {
            (Ok(commands), Ok((gcode, sliced))) => {
                assert!(same(commands, sliced), "{line:?}: built at once {commands:?}, by slices {sliced:?}");
                assert!(same(&self.gcode, gcode), "{line:?}: the state differs when built by slices");
            }
            (Err(a), Err(b)) => assert_eq!(a, b, "{line:?}: at once and by slices"),
            _ => panic!("{line:?}: at once {result:?}, by slices {:?}", sliced.as_ref().map(|(_, c)| c)),
        }
        let commands = match result {
            Ok(commands) => commands,
            Err(e) => {
                assert!(same(&self.gcode, &before), "{line:?} refused ({e:?}) changed the state");
                return;
            }
        };
        let mut at = before.planned_position();
        let mut drew = false;
        for command in commands {
            match command {
                Command::Job(job) => {
                    let (start, end) = (job.drawing.start(), job.drawing.end());
                    assert_eq!(start, at, "{line:?}: a drawing starts off the planned position");
                    assert!(!self.settings.strands(end), "{line:?}: a drawing ends outside the travel at {end:?}");
                    at = end;
                    drew = true;
                }
                Command::SetSetting { id, value } => {
                    let mut plain = self.settings;
                    assert_eq!(plain.set(id, value), Ok(()), "{line:?}: ${id}={value} handed out");
                    // At rest, and refused (error 15) if it would strand the pen.
                    let _ = self.settings.set_all_around(&[(id, value)], self.pen);
                }
                Command::RestoreSettings { startup_lines } => {
                    self.settings = Settings::default();
                    if startup_lines {
                        self.startup.clear();
                    }
                }
                Command::StoreStartupLine { index, line } => self.startup.set(usize::from(index), line),
                Command::StoreBuildInfo(line) => self.startup.build_info = line,
                Command::Sleep => self.mode = Some(RunState::Sleep),
                Command::CheckMode { on: true } => self.mode = Some(RunState::Check),
                Command::CheckMode { on: false } => self.reset(),
                Command::Unlock | Command::Home => self.mode = None,
                Command::Report(kind) => self.report(kind, line),
                Command::Dwell { .. } | Command::Pause | Command::ProgramEnd | Command::Pen(..) => {}
            }
        }
        if self.mode != Some(RunState::Check) {
            if drew {
                assert_eq!(self.gcode.planned_position(), at, "{line:?}: planned elsewhere than drawn");
            }
            self.pen = self.gcode.planned_position();
        }
    }

    /// The line built a slice at a time from a copy of the parser: the state it leads to and
    /// what it hands out.
    fn sliced(&self, line: &str, state: RunState) -> Result<(GcodeState, Vec<Command>), GrblError> {
        let mut gcode = self.gcode;
        let mut pending = Pending::new();
        gcode.parse(line, &self.settings, state, &mut pending)?;
        while !pending.advance(self.slice_steps).done {}
        let commands = gcode.commit(&mut pending, &self.settings)?;
        Ok((gcode, commands.collect()))
    }

    /// A soft reset: the parser at the pen, the startup blocks run.
    fn reset(&mut self) {
        self.mode = match self.mode {
            Some(RunState::Sleep | RunState::Alarm) => Some(RunState::Alarm),
            _ => None,
        };
        self.gcode.reset(self.pen, &self.settings);
        if self.mode.is_some() {
            // In an alarm the startup blocks wait for an unlock.
            return;
        }
        for index in 0..self.startup.all().count() {
            let block = self.startup.line(index).to_owned();
            let before = self.gcode;
            match self.gcode.run_startup_block(&block, &self.settings) {
                Ok(()) => assert_eq!(self.gcode.planned_position(), before.planned_position(), "{block:?} moved"),
                Err(e) => {
                    assert!(same(&self.gcode, &before), "startup block {block:?} refused ({e:?}) changed the state")
                }
            }
        }
    }

    /// Writes a report the parser's state or the settings feed, as `$G`, `$#` or `$$` asks after
    /// `line`: it may not fail or write a line too long.
    fn report(&self, kind: Report, line: &str) {
        let reply = match kind {
            Report::ParserState => Reply::ParserState(&self.gcode, &self.settings),
            Report::Parameters => Reply::Parameters(&self.gcode, &self.settings),
            Report::Settings => Reply::Settings(&self.settings),
            Report::Help | Report::BuildInfo | Report::StartupLines => return,
        };
        let mut text = String::new();
        reply.write(&mut text).expect("a report writes");
        for report_line in text.split_terminator("\r\n") {
            assert!(report_line.len() <= REPORT_LINE_MAX_BYTES, "after {line:?}: {report_line:?}");
        }
    }
}

/// Equal, a NaN equal to a NaN: compared as printed.
fn same<T: PartialEq + std::fmt::Debug>(a: &T, b: &T) -> bool {
    a == b || format!("{a:?}") == format!("{b:?}")
}

fuzz_target!(|data: &[u8]| {
    let Some((&first, stream)) = data.split_first() else { return };
    let mut settings = Settings::default();
    settings.set_all(&[(100, START_STEPS_PER_MM), (101, START_STEPS_PER_MM)]).expect("a coarse lattice");
    let mut machine = Machine {
        gcode: GcodeState::new(),
        settings,
        startup: StartupLines::new(),
        mode: None,
        moving: LINE_STATES[usize::from(first) % LINE_STATES.len()],
        pen: Point::ORIGIN,
        slice_steps: 1 + u32::from(first / 8) * 97,
    };
    let mut assembler = LineAssembler::new();
    for &byte in stream {
        if realtime(byte) == Some(Realtime::Reset) {
            machine.reset();
        }
        if let Some(LineEvent::Line(line)) = assembler.push(byte) {
            let line = line.to_owned();
            machine.line(&line);
        }
    }
    // Whatever the stream left, the reports of it.
    for kind in [Report::ParserState, Report::Parameters, Report::Settings] {
        machine.report(kind, "the end of the stream");
    }
});
