//! Every answer the plotter writes to the host, formatted as GRBL 1.1 does.
//!
//! Each function writes complete lines, each ended by CR LF as GRBL ends them, into any
//! `core::fmt::Write` (a `heapless::String`, or a writer over the UART's transmit buffer); none
//! allocates. A single line is at most [`REPORT_LINE_MAX_BYTES`] long, so a
//! `heapless::String<REPORT_LINE_MAX_BYTES>` holds any one of them; `$$` writes one line per
//! setting ([`setting`] writes one at a time). Positions are millimetres with three decimals,
//! from steps and the steps/mm settings; Z is always `0.000`, for senders that expect three axes.
//! This module only formats: it decides nothing and reads no machine state it is not given.

use core::fmt::{self, Write};

use super::GrblError;
use super::gcode::MM_PER_INCH;
use super::gcode::{Coolant, Distance, GcodeState, MotionMode, Spindle, StoredPosition, Units, WorkSystem};
use crate::decimal::Int;
use crate::geom::Axis;
use crate::host::startup::StartupLines;
use crate::machine_io::homing::HomingFail;
use crate::machine_io::inputs::Trip;
use crate::motion::drawing::DrawError;
use crate::motion::interp::CurveError;
use crate::panel::language::Language;
use crate::panel::texts::{Msg, Say};
use crate::settings::{SETTING_INFO, Settings};
use crate::status::{MotionFault, RunState, Status};
use crate::text::Text;

/// The GRBL version the plotter speaks; senders look for "Grbl 1.1".
pub const GRBL_VERSION: &str = "1.1h";

/// The build name reported by `$I`.
pub const BUILD_NAME: &str = "servoplot";

/// Longest single line written here (a status report with a work offset at ±500 mm is 81).
pub const REPORT_LINE_MAX_BYTES: usize = 128;

/// One answer to a host, named by what it says: [`Reply::write`] writes it. The serial task
/// sends every answer as one of these, so one function builds them all and the wait to send
/// one is the same code for every answer.
#[derive(Clone, Copy)]
pub enum Reply<'a> {
    Ok,
    Error(GrblError),
    /// `[MSG:text]`.
    Message(&'a str),
    /// The banner, with the hint how to leave an alarm.
    Welcome(RunState),
    Status(&'a Status, &'a Settings, &'a StatusFields),
    Alarm(MotionFault),
    /// `>line:ok` or `>line:error:N`.
    StartupResult(&'a str, Result<(), GrblError>),
    Help,
    Settings(&'a Settings),
    ParserState(&'a GcodeState, &'a Settings),
    Parameters(&'a GcodeState, &'a Settings),
    BuildInfo {
        info: &'a str,
        planner_blocks: usize,
        rx_buffer_bytes: usize,
    },
    StartupLines(&'a StartupLines),
}

impl Reply<'_> {
    /// Writes the answer.
    pub fn write(&self, out: &mut impl Write) -> fmt::Result {
        match *self {
            Reply::Ok => ok(out),
            Reply::Error(e) => error(out, e),
            Reply::Message(text) => message(out, text),
            Reply::Welcome(state) => welcome(out, state),
            Reply::Status(s, settings, fields) => status(out, s, settings, fields),
            Reply::Alarm(fault) => alarm(out, fault),
            Reply::StartupResult(line, result) => startup_result(out, line, result),
            Reply::Help => help(out),
            Reply::Settings(s) => settings(out, s),
            Reply::ParserState(gcode, s) => parser_state(out, gcode, s),
            Reply::Parameters(gcode, s) => parameters(out, gcode, s),
            Reply::BuildInfo { info, planner_blocks, rx_buffer_bytes } => {
                build_info(out, info, planner_blocks, rx_buffer_bytes)
            }
            Reply::StartupLines(lines) => startup_lines(out, lines),
        }
    }
}

/// `ok`: the line was executed.
pub fn ok(out: &mut impl Write) -> fmt::Result {
    out.write_str("ok\r\n")
}

/// `error:N`, preceded by an info line where the number alone would not say what is wrong
/// (the column of an expression error, the x where a function is undefined).
pub fn error(out: &mut impl Write, error: GrblError) -> fmt::Result {
    match error {
        GrblError::Expression { column, kind } => {
            let why = Say(Msg::from(kind), Language::English);
            write!(out, "[MSG:Expression error at column {}: {why}]\r\n", Int::from(column))?;
        }
        GrblError::FunctionUndefined { x_mm, error } => {
            out.write_str("[MSG:Function undefined at x=")?;
            ReportUnits::Mm.length(out, x_mm)?;
            write!(out, ": {}]\r\n", Text(error.message()))?;
        }
        GrblError::Drawing(e) => drawing_refused(out, e)?,
        _ => {}
    }
    write!(out, "error:{}\r\n", Int::from(error.code()))
}

/// Why the drawing builder refused a drawing, as an info line.
fn drawing_refused(out: &mut impl Write, e: DrawError) -> fmt::Result {
    out.write_str("[MSG:")?;
    match e {
        DrawError::BadParameter => out.write_str("Curve parameter out of range")?,
        DrawError::Travel => out.write_str("Curve leaves the travel")?,
        DrawError::Setup(_) => out.write_str("Curve cannot start at the pen")?,
        DrawError::TooSteep => out.write_str("Sine steeper than the max function jump ($204)")?,
        DrawError::TooFine => out.write_str("Curve finer than the step lattice can draw")?,
        DrawError::Imprecise => out.write_str("Function too far from 0 for single precision")?,
        DrawError::Fails { x_mm, error } => {
            let why = Text(match error {
                CurveError::Jump => "jumps more than $204",
                CurveError::Travel => "leaves the travel",
                _ => "is undefined",
            });
            write!(out, "Function {why} after x=")?;
            ReportUnits::Mm.length(out, x_mm)?;
        }
    }
    out.write_str("]\r\n")
}

/// The banner after power-up and every soft reset; in an alarm, GRBL's hint how to leave it.
pub fn welcome(out: &mut impl Write, state: RunState) -> fmt::Result {
    write!(out, "\r\nGrbl {} ['$' for help]\r\n", Text(GRBL_VERSION))?;
    if state == RunState::Alarm {
        message(out, "'$H'|'$X' to unlock")?;
    }
    Ok(())
}

/// GRBL's alarm code for a hard limit: a limit switch stopped the machine.
pub const ALARM_HARD_LIMIT: u8 = 1;
/// GRBL's alarm code for the soft limit: a motion would leave the travel.
pub const ALARM_SOFT_LIMIT: u8 = 2;
/// GRBL's alarm code for a homing cycle stopped by a reset or an abort.
pub const ALARM_HOMING_ABORTED: u8 = 6;
/// GRBL's alarm code for a homing pull-off that left the switch pressed.
pub const ALARM_HOMING_PULL_OFF: u8 = 8;
/// GRBL's alarm code for a homing approach that found no switch.
pub const ALARM_HOMING_APPROACH: u8 = 9;
/// grblHAL's alarm code for the emergency stop.
pub const ALARM_ESTOP: u8 = 10;
/// grblHAL's alarm code for a motor fault: a driver raised its alarm output.
pub const ALARM_DRIVER: u8 = 17;
/// The alarm code for a curve that stopped part way for another reason (not a GRBL code).
pub const ALARM_CURVE_STOPPED: u8 = 20;
/// The alarm code for the step timer's interrupt coming a whole period late (not a GRBL code).
pub const ALARM_MISSED_UPDATE: u8 = 21;
/// The alarm code for the card lost while a file of it was plotted (not a GRBL code).
pub const ALARM_CARD_LOST: u8 = 22;

/// The alarm pushed when `fault` stops the machine: `ALARM:N`, then what happened and what
/// clears it.
pub fn alarm(out: &mut impl Write, fault: MotionFault) -> fmt::Result {
    let (code, says) = match fault {
        MotionFault::Curve(e) => curve_stopped(e),
        MotionFault::Tripped(trip) => tripped(trip),
        MotionFault::Homing(fail) => homing_failed(fail),
        MotionFault::CardLost => {
            (ALARM_CARD_LOST, ["Card lost mid-plot: stopped on the path, pen up", "", "", "; '$X' to unlock"])
        }
    };
    let [a, b, c, d] = says.map(Text);
    write!(out, "ALARM:{}\r\n[MSG:{a}{b}{c}{d}]\r\n", Int::from(code))
}

/// What an alarm says, in pieces, after its code.
type AlarmText = (u8, [&'static str; 4]);

/// The alarm of a curve stopped part way.
fn curve_stopped(e: CurveError) -> AlarmText {
    let code = if e == CurveError::Travel { ALARM_SOFT_LIMIT } else { ALARM_CURVE_STOPPED };
    let why = match e {
        CurveError::Domain => "function undefined",
        CurveError::DivisionByZero => "division by zero",
        CurveError::Overflow => "value too large",
        CurveError::Jump => "jump over $204",
        CurveError::Aliased => "finer than the steps",
        CurveError::Travel => "travel limit",
    };
    (code, ["Curve stopped: ", why, "; queued lines dropped. '$X' to unlock", ""])
}

/// The alarm of a failed homing cycle: what failed.
fn homing_failed(fail: HomingFail) -> AlarmText {
    let (code, axis, why) = match fail {
        HomingFail::Aborted => (ALARM_HOMING_ABORTED, "", "reset or abort during the cycle"),
        HomingFail::PullOff(axis) => (ALARM_HOMING_PULL_OFF, axis.name(), " switch still pressed after the pull-off"),
        HomingFail::Approach(axis) => (ALARM_HOMING_APPROACH, axis.name(), " switch not found"),
    };
    (code, ["Homing failed: ", axis, why, ". '$H' or '$X'"])
}

/// The alarm of a trip: what tripped (the axis, for a limit its side), and what clears it.
fn tripped(trip: Trip) -> AlarmText {
    match trip {
        Trip::Limit { axis, max } => (
            ALARM_HARD_LIMIT,
            [
                "Hard limit ",
                axis.name(),
                if max { "+" } else { "-" },
                ": position lost; move off the switch after '$X'",
            ],
        ),
        Trip::DriverAlarm(axis) => {
            (ALARM_DRIVER, ["Driver alarm ", axis.name(), "", ": servos off; clear the driver's fault, then '$X'"])
        }
        Trip::EStop => (ALARM_ESTOP, ["Emergency stop", "", "", ": release it, then '$X'"]),
        Trip::MissedUpdate => {
            (ALARM_MISSED_UPDATE, ["Pulse timer late: stopped without braking; '$X' to unlock", "", "", ""])
        }
    }
}

/// A feedback message, `[MSG:text]` (`Caution: Unlocked`, `Pgm End`, `Reset to continue`...).
#[inline(never)]
pub fn message(out: &mut impl Write, text: &str) -> fmt::Result {
    write!(out, "[MSG:{}]\r\n", Text(text))
}

/// What a status report shows beyond the machine's own [`Status`].
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct StatusFields {
    /// How fast the pen moves now, mm/min (0 at rest).
    pub speed_mm_per_min: f32,
    /// Machine position minus work position, mm: for `WPos:` and `WCO:`.
    pub work_offset_mm: [f32; 2],
    /// Include `|WCO:` (when, see [`crate::host::refresh`]).
    pub wco: bool,
    /// Include `|Ov:` with the feed, rapid and spindle overrides, percent.
    pub overrides: Option<[u8; 3]>,
    /// Planner segments free and receive-window bytes free, for `|Bf:` (shown when `$10` has
    /// bit 1 set).
    pub buffer: (u8, u16),
    /// The line of the card file being plotted, for `|Ln:` (`None`: no card plot runs).
    pub card_line: Option<u32>,
}

/// The status report for `?`, as GRBL 1.1 writes it:
/// `<Idle|MPos:10.000,5.000,0.000|FS:0,0>`. `$10` chooses `MPos:` (bit 0 set) or `WPos:` and
/// adds `|Bf:` (bit 1); `|WCO:` and `|Ov:` follow when `fields` asks for them. Once the pulses
/// have had to wait for the motion task, `|Un:N` counts those step-queue underruns, and once the
/// step timer's interrupt has come a period late, `|Mu:N` counts those missed updates (neither
/// a GRBL field; senders skip fields they do not know).
pub fn status(out: &mut impl Write, status: &Status, settings: &Settings, fields: &StatusFields) -> fmt::Result {
    let state = match status.state {
        RunState::Idle => "Idle",
        RunState::Run => "Run",
        RunState::Hold if status.door => "Door:0",
        RunState::Hold => "Hold:0",
        RunState::Jog => "Jog",
        RunState::Alarm => "Alarm",
        RunState::Check => "Check",
        RunState::Sleep => "Sleep",
        RunState::Home => "Home",
    };
    let machine = settings.status_report_mask & 1 != 0;
    let units = ReportUnits::of(settings);
    write!(out, "<{}|{}:", Text(state), Text(if machine { "MPos" } else { "WPos" }))?;
    let [ox, oy] = if machine { [0.0; 2] } else { fields.work_offset_mm };
    let x = settings.steps_to_mm(Axis::X, status.position.x) - ox;
    let y = settings.steps_to_mm(Axis::Y, status.position.y) - oy;
    units.xyz(out, [x, y])?;
    if settings.status_report_mask & 2 != 0 {
        write!(out, "|Bf:{},{}", Int::from(fields.buffer.0), Int::from(fields.buffer.1))?;
    }
    if let Some(line) = fields.card_line {
        // GRBL's line number field: here the card file's line being carried out.
        write!(out, "|Ln:{}", Int::from(line))?;
    }
    out.write_str("|FS:")?;
    units.rate(out, fields.speed_mm_per_min)?;
    out.write_str(",0")?;
    if fields.wco {
        out.write_str("|WCO:")?;
        units.xyz(out, fields.work_offset_mm)?;
    }
    if let Some([feed, rapid, spindle]) = fields.overrides {
        write!(out, "|Ov:{},{},{}", Int::from(feed), Int::from(rapid), Int::from(spindle))?;
    }
    if status.underruns > 0 {
        write!(out, "|Un:{}", Int::from(status.underruns))?;
    }
    if status.missed_updates > 0 {
        write!(out, "|Mu:{}", Int::from(status.missed_updates))?;
    }
    out.write_str(">\r\n")
}

/// `$$`: every setting, `$N=value` per line, in `SETTING_INFO` order.
pub fn settings(out: &mut impl Write, settings: &Settings) -> fmt::Result {
    for info in SETTING_INFO {
        setting(out, info.id, settings)?;
    }
    Ok(())
}

/// One `$N=value` line, whole numbers (a count, a bit mask, a choice) without decimals;
/// nothing for an unknown id.
pub fn setting(out: &mut impl Write, id: u16, settings: &Settings) -> fmt::Result {
    let Ok(value) = settings.get(id) else { return Ok(()) };
    write!(out, "${}=", Int::from(id))?;
    if settings.is_whole(id) {
        write!(out, "{}", Int(value as i64))?;
    } else {
        decimal(out, value)?;
    }
    out.write_str("\r\n")
}

/// `$G`: `[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F3000 S0]`, F the feed rate G1 would use now,
/// G54 the active work coordinate system.
pub fn parser_state(out: &mut impl Write, gcode: &GcodeState, settings: &Settings) -> fmt::Result {
    let motion = match gcode.motion_mode() {
        MotionMode::Rapid => "G0",
        MotionMode::Linear => "G1",
        MotionMode::ArcCw => "G2",
        MotionMode::ArcCcw => "G3",
        MotionMode::Off => "G80",
    };
    let units = match gcode.units() {
        Units::Mm => "G21",
        Units::Inch => "G20",
    };
    let distance = match gcode.distance() {
        Distance::Absolute => "G90",
        Distance::Incremental => "G91",
    };
    let spindle = match gcode.spindle() {
        Spindle::Cw => "M3",
        Spindle::Ccw => "M4",
        Spindle::Off => "M5",
    };
    let feed = crate::math::round(gcode.feed_mm_per_min(settings)) as u32;
    let speed = crate::math::round(gcode.spindle_speed().unwrap_or(0.0)) as u32;
    let coolant = match gcode.coolant() {
        Coolant::Flood => "M8",
        Coolant::Off => "M9",
    };
    let system = gcode.work_system().gcode();
    let tool = gcode.tool();
    let (system, tool, feed, speed) = (Int::from(system), Int::from(tool), Int::from(feed), Int::from(speed));
    let (motion, units, distance, spindle, coolant) =
        (Text(motion), Text(units), Text(distance), Text(spindle), Text(coolant));
    write!(out, "[GC:{motion} G{system} G17 {units} {distance} G94 {spindle} {coolant} T{tool} F{feed} S{speed}]\r\n")
}

/// `$#`: GRBL's coordinate data, in GRBL's order and format, in the report units (`$13`): the
/// offsets of G54 to G59, the G28 and G30 positions (machine coordinates), the G92 offset, then
/// the tool length offset and the last probe, always zero on the plotter (no tool, no probe).
/// G54–G59, G28 and G30 outlive a power cycle (the flash store keeps them); G92 does not.
pub fn parameters(out: &mut impl Write, gcode: &GcodeState, settings: &Settings) -> fmt::Result {
    let units = ReportUnits::of(settings);
    let offsets = gcode.offsets();
    let stored = [
        (28, offsets.stored_mm(StoredPosition::G28)),
        (30, offsets.stored_mm(StoredPosition::G30)),
        (92, offsets.g92_mm()),
    ];
    for (g, xy) in WorkSystem::all().map(|system| (system.gcode(), offsets.system_mm(system))).chain(stored) {
        write!(out, "[G{}:", Int::from(g))?;
        units.xyz(out, xy)?;
        out.write_str("]\r\n")?;
    }
    out.write_str("[TLO:")?;
    units.length(out, 0.0)?;
    out.write_str("]\r\n[PRB:")?;
    units.xyz(out, [0.0; 2])?;
    out.write_str(":0]\r\n")
}

/// `$I`: version and GRBL's `[OPT:codes,blocks,rx]` line. Senders size their character-counting
/// window from `rx_buffer_bytes`, so it must be the serial task's real receive buffer.
pub fn build_info(out: &mut impl Write, info: &str, planner_blocks: usize, rx_buffer_bytes: usize) -> fmt::Result {
    let (blocks, rx) = (Int::from(planner_blocks), Int::from(rx_buffer_bytes));
    write!(out, "[VER:{}.{}:{}]\r\n[OPT:,{blocks},{rx}]\r\n", Text(GRBL_VERSION), Text(BUILD_NAME), Text(info))?;
    // On the chip: the stack's peak and size, bytes, and the longest task poll, µs: its own
    // work, and with the motion task's polls that preempted it.
    if let Some(h) = crate::machine_io::health::read() {
        let (peak, size) = (Int::from(h.stack_peak_bytes), Int::from(h.stack_size_bytes));
        let (own, with_preemption) = (Int::from(h.longest_poll_us), Int::from(h.longest_poll_with_preemption_us));
        write!(out, "[STACK:{peak},{size}]\r\n[POLL:{own},{with_preemption}]\r\n")?;
    }
    Ok(())
}

/// `$`: the commands the plotter understands.
pub fn help(out: &mut impl Write) -> fmt::Result {
    out.write_str("[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $RST=$ $SLP $C $X $H $E $O $S $F ~ ! ? ctrl-x]\r\n")
}

/// `$N`: every startup block, `$Nn=line` per line, empty ones included.
pub fn startup_lines(out: &mut impl Write, lines: &StartupLines) -> fmt::Result {
    for (n, line) in lines.all().enumerate() {
        write!(out, "$N{}={}\r\n", Int::from(n), Text(line))?;
    }
    Ok(())
}

/// What running a startup block after a reset gave: `>line:ok` or `>line:error:N`.
pub fn startup_result(out: &mut impl Write, line: &str, result: Result<(), GrblError>) -> fmt::Result {
    write!(out, ">{}:", Text(line))?;
    match result {
        Ok(()) => ok(out),
        Err(e) => write!(out, "error:{}\r\n", Int::from(e.code())),
    }
}

/// `x,y,0.000` in millimetres.
/// The units positions and speeds are reported in (`$13`), with GRBL's decimals for each.
#[derive(Clone, Copy, PartialEq, Eq)]
enum ReportUnits {
    /// Millimetres with three decimals, mm/min whole.
    Mm,
    /// Inches with four decimals, inches/min with one.
    Inch,
}

impl ReportUnits {
    fn of(settings: &Settings) -> ReportUnits {
        if settings.report_inches { ReportUnits::Inch } else { ReportUnits::Mm }
    }

    /// `value_mm` in these units, with their decimals; never `-0.000`.
    fn length(self, out: &mut impl Write, value_mm: f32) -> fmt::Result {
        let value_mm = if value_mm.is_finite() { value_mm } else { 0.0 };
        match self {
            ReportUnits::Mm => crate::decimal::write_fixed(out, value_mm, 3),
            ReportUnits::Inch => crate::decimal::write_fixed(out, value_mm / MM_PER_INCH, 4),
        }
    }

    /// `x,y,z` (z always zero: no Z axis).
    fn xyz(self, out: &mut impl Write, [x, y]: [f32; 2]) -> fmt::Result {
        self.length(out, x)?;
        out.write_char(',')?;
        self.length(out, y)?;
        out.write_char(',')?;
        self.length(out, 0.0)
    }

    /// A speed, given in mm/min, as GRBL writes a rate: whole mm/min, or inches/min with one
    /// decimal.
    fn rate(self, out: &mut impl Write, mm_per_min: f32) -> fmt::Result {
        let speed = if mm_per_min.is_finite() { mm_per_min.abs() } else { 0.0 };
        match self {
            ReportUnits::Mm => write!(out, "{}", Int::from(crate::math::round(speed) as u32)),
            ReportUnits::Inch => crate::decimal::write_fixed(out, speed / MM_PER_INCH, 1),
        }
    }
}

/// A setting's value: at least three decimals like GRBL, more (up to six) when it has them.
fn decimal(out: &mut impl Write, value: f32) -> fmt::Result {
    crate::decimal::write_trimmed(out, value, 3, 6)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::geom::Point;
    use crate::host::GrblError;
    use crate::settings::Settings;
    use std::string::String;

    fn text(f: impl FnOnce(&mut String) -> fmt::Result) -> String {
        let mut s = String::new();
        f(&mut s).unwrap();
        s
    }

    fn st(state: RunState, x: i32, y: i32) -> Status {
        Status { state, position: Point::new(x, y), ..Status::default() }
    }

    /// The fields of a report with speed `speed` and nothing occasional.
    fn at(speed: f32) -> StatusFields {
        StatusFields { speed_mm_per_min: speed, ..StatusFields::default() }
    }

    #[test]
    fn status_reports_match_grbl_exactly() {
        let s = Settings::default(); // 100 steps/mm, $10=1
        assert_eq!(
            text(|o| status(o, &st(RunState::Idle, 1000, 500), &s, &at(0.0))),
            "<Idle|MPos:10.000,5.000,0.000|FS:0,0>\r\n"
        );
        assert_eq!(
            text(|o| status(o, &st(RunState::Run, -1, -123_456), &s, &at(1499.6))),
            "<Run|MPos:-0.010,-1234.560,0.000|FS:1500,0>\r\n"
        );
        let wco = StatusFields { work_offset_mm: [-2.5, 0.0], wco: true, ..at(0.0) };
        assert_eq!(
            text(|o| status(o, &st(RunState::Hold, 0, 0), &s, &wco)),
            "<Hold:0|MPos:0.000,0.000,0.000|FS:0,0|WCO:-2.500,0.000,0.000>\r\n"
        );
        let ov = StatusFields { overrides: Some([100, 100, 100]), ..at(600.0) };
        assert_eq!(
            text(|o| status(o, &st(RunState::Jog, 0, 0), &s, &ov)),
            "<Jog|MPos:0.000,0.000,0.000|FS:600,0|Ov:100,100,100>\r\n"
        );
        assert!(text(|o| status(o, &st(RunState::Alarm, 0, 0), &s, &at(0.0))).starts_with("<Alarm|"));
        // Once the pulses have had to wait for the motion task, the count follows.
        let late = Status { underruns: 3, ..st(RunState::Run, 0, 0) };
        assert_eq!(text(|o| status(o, &late, &s, &at(6000.0))), "<Run|MPos:0.000,0.000,0.000|FS:6000,0|Un:3>\r\n");
        // And once the step timer's interrupt has come a period late, that count.
        let missed = Status { missed_updates: 1, ..st(RunState::Alarm, 0, 0) };
        assert_eq!(text(|o| status(o, &missed, &s, &at(0.0))), "<Alarm|MPos:0.000,0.000,0.000|FS:0,0|Mu:1>\r\n");
    }

    #[test]
    fn the_report_mask_chooses_work_or_machine_position_and_the_buffer_state() {
        let mut s = Settings::default();
        let fields = StatusFields { work_offset_mm: [2.5, -1.0], buffer: (15, 128), ..at(0.0) };
        let idle = st(RunState::Idle, 1000, 500);
        s.set(10, 0.0).unwrap();
        assert_eq!(text(|o| status(o, &idle, &s, &fields)), "<Idle|WPos:7.500,6.000,0.000|FS:0,0>\r\n");
        s.set(10, 3.0).unwrap();
        assert_eq!(text(|o| status(o, &idle, &s, &fields)), "<Idle|MPos:10.000,5.000,0.000|Bf:15,128|FS:0,0>\r\n");
        s.set(10, 2.0).unwrap();
        assert_eq!(text(|o| status(o, &idle, &s, &fields)), "<Idle|WPos:7.500,6.000,0.000|Bf:15,128|FS:0,0>\r\n");
    }

    #[test]
    fn a_card_plot_reports_its_line() {
        let fields = StatusFields { card_line: Some(300), ..at(0.0) };
        let report = text(|o| status(o, &st(RunState::Run, 0, 0), &Settings::default(), &fields));
        assert_eq!(report, "<Run|MPos:0.000,0.000,0.000|Ln:300|FS:0,0>\r\n");
    }

    #[test]
    fn positions_use_each_axis_steps_per_mm_and_never_show_minus_zero() {
        let mut s = Settings::default();
        s.set(100, 80.0).unwrap();
        s.set(101, 200.0).unwrap();
        assert_eq!(
            text(|o| status(o, &st(RunState::Idle, -1, -1), &s, &at(0.0))),
            "<Idle|MPos:-0.013,-0.005,0.000|FS:0,0>\r\n"
        );
        // -0.0004 mm rounds to zero and shows as zero.
        assert_eq!(text(|o| ReportUnits::Mm.length(o, -0.0004)), "0.000");
        assert_eq!(text(|o| ReportUnits::Mm.length(o, 499.9996)), "500.000");
    }

    #[test]
    fn the_longest_status_line_fits_the_stated_maximum() {
        let mut s = Settings::default();
        s.set(10, 2.0).unwrap();
        let longest = StatusFields {
            speed_mm_per_min: 60_000.0,
            work_offset_mm: [-500.0, -500.0],
            wco: true,
            overrides: Some([200, 100, 200]),
            buffer: (255, 65_535),
            card_line: Some(u32::MAX),
        };
        let late = Status { underruns: u32::MAX, ..st(RunState::Hold, -50_000, -50_000) };
        let line = text(|o| status(o, &late, &s, &longest));
        assert!(line.len() <= REPORT_LINE_MAX_BYTES, "{} bytes", line.len());
        let mut fixed: heapless::String<REPORT_LINE_MAX_BYTES> = heapless::String::new();
        status(&mut fixed, &late, &s, &longest).unwrap();
        assert_eq!(fixed.as_str(), line);
    }

    #[test]
    fn short_answers() {
        assert_eq!(text(ok), "ok\r\n");
        assert_eq!(text(|o| error(o, GrblError::TravelExceeded)), "error:15\r\n");
        assert_eq!(text(|o| error(o, GrblError::ModalGroupViolation)), "error:21\r\n");
        assert_eq!(text(|o| welcome(o, RunState::Idle)), "\r\nGrbl 1.1h ['$' for help]\r\n");
        assert_eq!(
            text(|o| welcome(o, RunState::Alarm)),
            "\r\nGrbl 1.1h ['$' for help]\r\n[MSG:'$H'|'$X' to unlock]\r\n"
        );
        assert_eq!(text(|o| message(o, "Pgm End")), "[MSG:Pgm End]\r\n");
        assert_eq!(text(|o| build_info(o, "", 16, 128)), "[VER:1.1h.servoplot:]\r\n[OPT:,16,128]\r\n");
        assert!(text(help).starts_with("[HLP:$$ $# $G $I"));
        // Every `$` command a user can send is listed, sleep and homing too.
        for command in ["$SLP", "$H", "$C", "$X", "$J=line", "$RST=$", "$F"] {
            assert!(text(help).contains(&std::format!(" {command} ")), "{command} missing from the help");
        }
    }

    #[test]
    fn an_alarm_is_pushed_with_its_code_and_why() {
        let travel = text(|o| alarm(o, MotionFault::Curve(CurveError::Travel)));
        assert_eq!(travel, "ALARM:2\r\n[MSG:Curve stopped: travel limit; queued lines dropped. '$X' to unlock]\r\n");
        let jump = text(|o| alarm(o, MotionFault::Curve(CurveError::Jump)));
        assert!(jump.starts_with("ALARM:20\r\n[MSG:Curve stopped: jump over $204;"), "{jump}");
        for line in travel.lines().chain(jump.lines()) {
            assert!(line.len() <= REPORT_LINE_MAX_BYTES);
        }
    }

    #[test]
    fn expression_errors_say_where() {
        let e = GrblError::Expression { column: 19, kind: crate::motion::expr::ParseErrorKind::UnknownName };
        assert_eq!(text(|o| error(o, e)), "[MSG:Expression error at column 19: unknown name]\r\nerror:2\r\n");
        let e = GrblError::FunctionUndefined { x_mm: -1.5, error: crate::motion::expr::EvalError::SqrtOfNegative };
        assert_eq!(
            text(|o| error(o, e)),
            "[MSG:Function undefined at x=-1.500: sqrt of a negative number]\r\nerror:33\r\n"
        );
    }

    #[test]
    fn settings_list_like_grbl() {
        let mut s = Settings::default();
        s.set(11, 0.0005).unwrap();
        let list = text(|o| settings(o, &s));
        let lines: std::vec::Vec<&str> = list.split("\r\n").filter(|l| !l.is_empty()).collect();
        assert_eq!(lines.len(), SETTING_INFO.len());
        assert_eq!(lines[0], "$0=5.000");
        assert!(lines.contains(&"$3=0"));
        assert!(lines.contains(&"$11=0.0005"));
        assert!(lines.contains(&"$100=100.000"));
        assert!(lines.contains(&"$202=1"));
        assert!(lines.contains(&"$205=20000.000"));
        assert_eq!(text(|o| setting(o, 999, &s)), "");
    }

    #[test]
    fn parser_state_and_offsets() {
        let s = Settings::default();
        let mut g = GcodeState::new();
        assert_eq!(text(|o| parser_state(o, &g, &s)), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F3000 S0]\r\n");
        g.execute("G91 G20 G1 F10 M3 S1000 T2", &s, RunState::Idle).unwrap();
        assert_eq!(text(|o| parser_state(o, &g, &s)), "[GC:G1 G54 G17 G20 G91 G94 M3 M9 T2 F254 S1000]\r\n");
        // M8 is kept as GRBL keeps it; M9 or a program end turns it off.
        g.execute("M8", &s, RunState::Idle).unwrap();
        assert!(text(|o| parser_state(o, &g, &s)).contains(" M3 M8 T2 "));
        assert_eq!(g.execute("M8 M9", &s, RunState::Idle), Err(GrblError::ModalGroupViolation));
        g.execute("M2", &s, RunState::Idle).unwrap();
        assert!(text(|o| parser_state(o, &g, &s)).contains(" M5 M9 T2 "));
        g.execute("G91 G20 G1 F10 M3", &s, RunState::Idle).unwrap();
        g.execute("G90 G21 G0 X10 Y-5", &s, RunState::Idle).unwrap();
        g.execute("G92 X0 Y0", &s, RunState::Idle).unwrap();
        let p = text(|o| parameters(o, &g, &Settings::default()));
        assert!(p.starts_with("[G54:0.000,0.000,0.000]\r\n"));
        assert!(p.contains("[G92:10.000,-5.000,0.000]\r\n"));
        assert!(p.ends_with("[TLO:0.000]\r\n[PRB:0.000,0.000,0.000:0]\r\n"));
    }
}
