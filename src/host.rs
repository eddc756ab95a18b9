//! The host link's protocol: the pure, synchronous core of the serial link, in GRBL 1.1 lines.
//!
//! Data flow: bytes from the link -> [`framing`] (text lines, realtime bytes) -> [`gcode`] (one
//! line to machine [`Command`]s, with the modal state and planned position) -> [`guards`] (what
//! each command waits for, is refused on and answers) -> the machine; every answer goes back
//! through [`report`], with [`refresh`] choosing the occasional status fields and [`startup`]
//! holding the blocks run after each reset.
//!
//! Existing G-code senders (UGS, CNCjs, bCNC) and a plain terminal talk to the plotter as if it
//! were GRBL 1.1. This module owns the pure parts of that conversation:
//!
//! - [`framing`]: bytes in, text lines out ([`LineAssembler`]), and the realtime bytes that
//!   bypass lines ([`realtime`]);
//! - [`gcode`]: one line in, machine [`Command`]s out ([`GcodeState::execute`]), with GRBL's
//!   modal state, planned position and error rules, plus the plotter's own curve commands;
//! - [`report`]: every answer the plotter writes (`ok`, `error:N`, status reports, `$$`, ...);
//! - [`refresh`]: which status reports carry GRBL's occasional `WCO:` and `Ov:` fields;
//! - [`startup`]: the startup blocks (`$N0=`, `$N1=`) run after every reset;
//! - [`guards`]: what each command waits for before it acts, is refused on, and answers.
//!
//! It owns no pins, queues or clocks: the serial task feeds it bytes, hands the resulting
//! commands to the machine and writes the answers. Every line gets exactly one `ok` or
//! `error:N`, and a line answered with an error changes nothing (neither the modal state nor the
//! planned position, nor the settings).
//!
//! # Error numbers
//!
//! Every error but one is a GRBL 1.1 error number, so senders show their usual text for it; the
//! plotter's own (100 and up, numbers neither GRBL nor grblHAL use) come after a `[MSG:...]`
//! saying what they mean:
//!
//! | N  | [`GrblError`]             | when |
//! |----|---------------------------|------|
//! | 1  | `ExpectedCommandLetter`   | a word does not start with a letter; a line holds a control or non-ASCII byte |
//! | 2  | `BadNumberFormat`         | a word's number is missing or malformed (`X`, `X1.2.3`, `X--1`) |
//! | 2  | `Expression`              | the `Y=` expression of `$F` does not parse (an info line gives the column) |
//! | 3  | `InvalidStatement`        | unknown `$` command, unknown setting number, bad setting value |
//! | 4  | `NegativeValue`           | negative F, N, P, S, T, or negative size in a curve command |
//! | 5  | `SettingDisabled`         | `$H`: the plotter has no homing switches |
//! | 8  | `NotIdle`                 | `$J=` while a program runs (a move queued or drawing), held or in alarm; a setting, `$Nn=`, `$I=`, `$SLP` while held, jogging or homing (behind a running program they wait for it); `$RST=` and `$C` unless at rest |
//! | 9  | `Locked`                  | G-code or a curve command while in alarm (unlock with `$X`) or jogging; any line while asleep (`$SLP`, until a reset); a move still waiting for room in the job queue when an abort (keypad D, jog cancel, a curve stopped part way, a reset on the other host link) dropped what was planned |
//! | 11 | `LineOverflow`            | a line longer than [`LINE_MAX_BYTES`] |
//! | 14 | `LineLengthExceeded`      | a `$Nn=` startup block longer than [`startup::STARTUP_LINE_MAX_BYTES`] |
//! | 15 | `TravelExceeded`          | any point of a move or curve outside ±max travel (`$130`, `$131`) |
//! | 16 | `InvalidJog`              | a `$J=` line with a word or command jogging does not allow |
//! | 20 | `Unsupported`             | a G/M code or word letter the plotter does not support (G18, G28.2, M8, ...); G10 with an L other than 2 or 20, or L2 with R |
//! | 21 | `ModalGroupViolation`     | two commands of one modal group in a line (`G0 G1`, `G20 G21`) |
//! | 22 | `UndefinedFeedRate`       | a feed move or jog with a zero or missing feed rate |
//! | 23 | `ValueNotInteger`         | `G1.5`, `M3.1` |
//! | 24 | `AxisCommandConflict`     | G10, G28, G30 or G92 with a motion command or with another of them in one line |
//! | 25 | `RepeatedWord`            | a word letter twice in a line (`X1 X2`) |
//! | 26 | `NoAxisWords`             | G10, G92, an arc or a jog without axis words |
//! | 27 | `InvalidLineNumber`       | N above 9 999 999 |
//! | 28 | `ValueWordMissing`        | G4 without P; G10 without L or P; a curve command without a required word |
//! | 29 | `UnsupportedCoordSys`     | G10 with a P other than 0 to 6 (0: the active system, 1–6: G54–G59) |
//! | 30 | `G53InvalidMotionMode`    | G53 while G2/G3/G80 is the motion mode |
//! | 31 | `AxisWordsExist`          | axis words while G80 is the motion mode (G10's, G28's, G30's and G92's too) |
//! | 32 | `NoAxisWordsInPlane`      | G2/G3 with only a Z word |
//! | 33 | `InvalidTarget`           | arc end not on its circle, R arc to its own start, sweep above 360° |
//! | 33 | `Drawing`                 | the drawing cannot be drawn as asked: finer than the step lattice (an axis under a step, a sine of fewer than 8 steps per wave, a function changing faster than its X steps), a sine steeper than the max function jump (`$204`), a function undefined or jumping part way (an info line says which and where), a function too far from 0 for single precision; as `Drawing(Travel)`: error 15 |
//! | 33 | `FunctionUndefined`       | the `$F` function cannot be evaluated on its range (an info line gives x) |
//! | 34 | `ArcRadius`               | R arc whose radius is shorter than half the chord |
//! | 35 | `NoOffsetsInPlane`        | G2/G3 without R, I or J |
//! | 36 | `UnusedWords`             | a word no command in the line uses (`G0 X1 P2`, `I5` without an arc, `L2` without G10) |
//! | 38 | `MaxValueExceeded`        | T above 255, dwell above [`gcode::DWELL_MAX_MS`] |
//! | 100 | `ReceiveBufferFull`      | a line dropped on a link without flow control (the UART) for want of room in the receive buffer: a paste that ignored GRBL's flow control |
//!
//! GRBL's soft limits raise an alarm; the plotter answers `error:15` instead and moves nothing,
//! which is safer and tells the sender which line was refused.
//!
//! # Plotter commands
//!
//! Beyond GRBL, one `$` command per curve the machine draws; all draw from the pen, take
//! millimetres and degrees whatever G20/G21 says, and accept an F word (mm/min) that becomes the
//! modal feed rate like G1's. See [`gcode`] for their exact syntax and geometry.

pub mod framing;
pub mod gcode;
pub mod guards;
pub mod refresh;
pub mod report;
pub mod startup;

pub use framing::{LINE_MAX_BYTES, LineAssembler, LineEvent, Realtime, realtime};
pub use gcode::{Command, Commands, GcodeState, Report};

/// Why a line was refused; [`GrblError::code`] is the number sent as `error:N`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum GrblError {
    ExpectedCommandLetter,
    BadNumberFormat,
    InvalidStatement,
    NegativeValue,
    SettingDisabled,
    NotIdle,
    Locked,
    LineOverflow,
    LineLengthExceeded,
    TravelExceeded,
    InvalidJog,
    Unsupported,
    ModalGroupViolation,
    UndefinedFeedRate,
    ValueNotInteger,
    AxisCommandConflict,
    RepeatedWord,
    NoAxisWords,
    InvalidLineNumber,
    ValueWordMissing,
    UnsupportedCoordSys,
    G53InvalidMotionMode,
    AxisWordsExist,
    NoAxisWordsInPlane,
    InvalidTarget,
    ArcRadius,
    NoOffsetsInPlane,
    UnusedWords,
    MaxValueExceeded,
    /// A line dropped whole, unread, because the receive buffer was full when it came.
    ReceiveBufferFull,
    /// The expression of `$F` does not parse; `column` is 1-based within the line.
    Expression {
        column: u16,
        kind: crate::motion::expr::ParseErrorKind,
    },
    /// The function of `$F` cannot be evaluated at `x_mm` (a domain error or an overflow).
    FunctionUndefined {
        x_mm: f32,
        error: crate::motion::expr::EvalError,
    },
    /// The drawing builder refused the drawing.
    Drawing(crate::motion::drawing::DrawError),
}

impl From<crate::motion::drawing::DrawError> for GrblError {
    fn from(e: crate::motion::drawing::DrawError) -> Self {
        match e {
            crate::motion::drawing::DrawError::Travel => GrblError::TravelExceeded,
            e => GrblError::Drawing(e),
        }
    }
}

impl GrblError {
    /// The GRBL 1.1 error number.
    pub const fn code(self) -> u8 {
        match self {
            GrblError::ExpectedCommandLetter => 1,
            GrblError::BadNumberFormat | GrblError::Expression { .. } => 2,
            GrblError::InvalidStatement => 3,
            GrblError::NegativeValue => 4,
            GrblError::SettingDisabled => 5,
            GrblError::NotIdle => 8,
            GrblError::Locked => 9,
            GrblError::LineOverflow => 11,
            GrblError::LineLengthExceeded => 14,
            GrblError::TravelExceeded => 15,
            GrblError::InvalidJog => 16,
            GrblError::Unsupported => 20,
            GrblError::ModalGroupViolation => 21,
            GrblError::UndefinedFeedRate => 22,
            GrblError::ValueNotInteger => 23,
            GrblError::AxisCommandConflict => 24,
            GrblError::RepeatedWord => 25,
            GrblError::NoAxisWords => 26,
            GrblError::InvalidLineNumber => 27,
            GrblError::ValueWordMissing => 28,
            GrblError::UnsupportedCoordSys => 29,
            GrblError::G53InvalidMotionMode => 30,
            GrblError::AxisWordsExist => 31,
            GrblError::NoAxisWordsInPlane => 32,
            GrblError::InvalidTarget | GrblError::FunctionUndefined { .. } => 33,
            GrblError::Drawing(crate::motion::drawing::DrawError::Travel) => 15,
            GrblError::Drawing(_) => 33,
            GrblError::ArcRadius => 34,
            GrblError::NoOffsetsInPlane => 35,
            GrblError::UnusedWords => 36,
            GrblError::MaxValueExceeded => 38,
            GrblError::ReceiveBufferFull => 100,
        }
    }
}
