//! The words of a line and the block they make: compaction, G-code numbers, the letter values,
//! and the G and M commands sorted into GRBL's modal groups, before any check against the state.

use super::modal::{Coolant, Distance, MotionMode, Spindle, TOOL_NUMBER_MAX, Units, WorkSystem};
use super::offsets::StoredPosition;
use crate::host::GrblError;
use crate::host::framing::LINE_MAX_BYTES;

/// A line with spaces, tabs, block-delete slashes and comments removed, upper-cased.
type Compact = heapless::Vec<u8, LINE_MAX_BYTES>;

/// Compacts `text`; `(...)` are comments only when `parens_are_comments`; `;` always ends it.
pub(super) fn compact(text: &str, parens_are_comments: bool) -> Result<Compact, GrblError> {
    let mut out = Compact::new();
    let mut in_comment = false;
    for &b in text.as_bytes() {
        if in_comment {
            in_comment = b != b')';
            continue;
        }
        match b {
            b'(' if parens_are_comments => in_comment = true,
            b';' => break,
            b' ' | b'\t' | b'/' => {}
            _ => out.push(b.to_ascii_uppercase()).map_err(|_| GrblError::LineOverflow)?,
        }
    }
    Ok(out)
}

/// The words of a compacted line: a letter and its number each.
pub(super) struct WordIter<'a> {
    rest: &'a [u8],
}

impl<'a> WordIter<'a> {
    pub(super) fn new(bytes: &'a [u8]) -> Self {
        WordIter { rest: bytes }
    }
}

impl Iterator for WordIter<'_> {
    type Item = Result<(u8, f32), GrblError>;

    fn next(&mut self) -> Option<Self::Item> {
        let (&letter, tail) = self.rest.split_first()?;
        if !letter.is_ascii_uppercase() {
            self.rest = &[];
            return Some(Err(GrblError::ExpectedCommandLetter));
        }
        let n = tail.iter().take_while(|c| c.is_ascii_digit() || matches!(c, b'.' | b'+' | b'-')).count();
        let (number, rest) = tail.split_at(n);
        self.rest = rest;
        // `1e9`: G-code has no exponents (`E` would be a word of its own, and no command takes
        // one); say what is wrong with the number rather than with an `E` word.
        if let [b'E', next, ..] = rest
            && (next.is_ascii_digit() || matches!(next, b'.' | b'+' | b'-'))
            && !number.is_empty()
        {
            self.rest = &[];
            return Some(Err(GrblError::BadNumberFormat));
        }
        Some(parse_number(number).map(|v| (letter, v)))
    }
}

/// A G-code number: optional sign, digits with at most one point, at least one digit (no
/// exponent: in G-code `E` is a word letter). The whole of `text` must be the number.
pub(super) fn parse_number(text: &[u8]) -> Result<f32, GrblError> {
    let syntax = crate::decimal::Syntax { sign: true, exponent: false };
    match crate::decimal::parse_prefix(text, syntax) {
        Ok(n) if n.len_bytes == text.len() => Ok(n.value),
        _ => Err(GrblError::BadNumberFormat),
    }
}

/// Letter values of one line.
#[derive(Clone, Copy, Default)]
pub(super) struct Words {
    values: [Option<f32>; 26],
}

impl Words {
    pub(super) fn insert(&mut self, letter: u8, value: f32) -> Result<(), GrblError> {
        let slot = &mut self.values[(letter.wrapping_sub(b'A')) as usize % 26];
        if slot.is_some() {
            return Err(GrblError::RepeatedWord);
        }
        *slot = Some(value);
        Ok(())
    }

    pub(super) fn get(&self, letter: u8) -> Option<f32> {
        self.values[(letter.wrapping_sub(b'A')) as usize % 26]
    }

    pub(super) fn take(&mut self, letter: u8) -> Option<f32> {
        self.values[(letter.wrapping_sub(b'A')) as usize % 26].take()
    }

    pub(super) fn is_empty(&self) -> bool {
        self.values.iter().all(Option::is_none)
    }
}

pub(super) fn no_unused(words: &Words) -> Result<(), GrblError> {
    if words.is_empty() { Ok(()) } else { Err(GrblError::UnusedWords) }
}

/// A required size word: present, not negative, not zero.
pub(super) fn positive(value: Option<f32>) -> Result<f32, GrblError> {
    match value {
        None => Err(GrblError::ValueWordMissing),
        Some(v) if v < 0.0 => Err(GrblError::NegativeValue),
        Some(0.0) => Err(GrblError::InvalidTarget),
        Some(v) => Ok(v),
    }
}

/// Modal groups, as GRBL numbers them (NIST RS274/NGC table 4).
#[derive(Clone, Copy)]
pub(super) enum Group {
    NonModal,
    Motion,
    Plane,
    Distance,
    ArcDistance,
    FeedMode,
    Units,
    CutterComp,
    ToolLength,
    CoordSystem,
    Control,
    ProgramStop,
    Spindle,
    Coolant,
}

impl Group {
    pub(super) const fn bit(self) -> u16 {
        1 << self as u16
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum NonModal {
    /// G4.
    Dwell,
    /// G53.
    MachineCoords,
    /// G10 (L2 or L20): set a work coordinate system's offset.
    SetSystem,
    /// G28, G30: go to the stored position.
    GoToStored(StoredPosition),
    /// G28.1, G30.1: store the planned position.
    Store(StoredPosition),
    /// G92.
    SetOffset,
    /// G92.1.
    ClearOffset,
}

impl NonModal {
    /// G10, G28, G30 and G92 take the line's axis words for themselves, so no motion command
    /// may share their line (GRBL's axis command conflict).
    pub(super) const fn uses_axis_words(self) -> bool {
        matches!(self, NonModal::SetSystem | NonModal::GoToStored(_) | NonModal::SetOffset)
    }
}

/// A program stop: M0 pauses, M2/M30 end the program (M1, an optional stop without a switch,
/// is no stop).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum ProgramStop {
    Pause,
    End,
}

/// One parsed line of G-code, before its checks against the state.
#[derive(Default)]
pub(super) struct Block {
    pub(super) groups: u16,
    pub(super) non_modal: Option<NonModal>,
    pub(super) motion: Option<MotionMode>,
    /// G0–G3 given explicitly: the line is a motion command even without axis words.
    pub(super) motion_word: bool,
    pub(super) units: Option<Units>,
    pub(super) distance: Option<Distance>,
    pub(super) work_system: Option<WorkSystem>,
    pub(super) spindle: Option<Spindle>,
    pub(super) coolant: Option<Coolant>,
    pub(super) stop: Option<ProgramStop>,
    pub(super) words: Words,
}

impl Block {
    fn enter(&mut self, group: Group) -> Result<(), GrblError> {
        if self.groups & group.bit() != 0 {
            return Err(GrblError::ModalGroupViolation);
        }
        self.groups |= group.bit();
        Ok(())
    }

    fn g(&mut self, value: f32) -> Result<(), GrblError> {
        let (int, tenths) = command_number(value)?;
        if tenths != 0 && !matches!((int, tenths), (28, 1) | (30, 1) | (91, 1) | (92, 1)) {
            // GRBL's other Gxx.x commands are unsupported here; anything else is no command.
            return Err(if matches!(int, 28 | 30 | 38 | 43 | 59 | 61 | 90 | 92) {
                GrblError::Unsupported
            } else {
                GrblError::ValueNotInteger
            });
        }
        let group = match (int, tenths) {
            (0..=3, 0) => {
                if self.non_modal.is_some_and(NonModal::uses_axis_words) {
                    return Err(GrblError::AxisCommandConflict);
                }
                self.motion =
                    Some([MotionMode::Rapid, MotionMode::Linear, MotionMode::ArcCw, MotionMode::ArcCcw][int as usize]);
                self.motion_word = true;
                Group::Motion
            }
            (80, 0) => {
                self.motion = Some(MotionMode::Off);
                Group::Motion
            }
            (4, 0) => self.non_modal(NonModal::Dwell),
            (53, 0) => self.non_modal(NonModal::MachineCoords),
            (10, 0) => self.axis_non_modal(NonModal::SetSystem)?,
            (28, 0) => self.axis_non_modal(NonModal::GoToStored(StoredPosition::G28))?,
            (30, 0) => self.axis_non_modal(NonModal::GoToStored(StoredPosition::G30))?,
            (28, 1) => self.non_modal(NonModal::Store(StoredPosition::G28)),
            (30, 1) => self.non_modal(NonModal::Store(StoredPosition::G30)),
            (92, 0) => self.axis_non_modal(NonModal::SetOffset)?,
            (92, 1) => self.non_modal(NonModal::ClearOffset),
            (17, 0) => Group::Plane,
            (20, 0) | (21, 0) => {
                self.units = Some(if int == 20 { Units::Inch } else { Units::Mm });
                Group::Units
            }
            (90, 0) | (91, 0) => {
                self.distance = Some(if int == 90 { Distance::Absolute } else { Distance::Incremental });
                Group::Distance
            }
            (91, 1) => Group::ArcDistance,
            (94, 0) => Group::FeedMode,
            (40, 0) => Group::CutterComp,
            (49, 0) => Group::ToolLength,
            (54..=59, 0) => {
                self.work_system = WorkSystem::from_gcode(int);
                Group::CoordSystem
            }
            (61, 0) => Group::Control,
            _ => return Err(GrblError::Unsupported),
        };
        self.enter(group)
    }

    /// G10, G28, G30, G92: a non-modal command using axis words, which no motion command and no
    /// other such command may share a line with (checked before the modal group, as GRBL does).
    fn axis_non_modal(&mut self, command: NonModal) -> Result<Group, GrblError> {
        if self.motion_word || self.non_modal.is_some_and(NonModal::uses_axis_words) {
            return Err(GrblError::AxisCommandConflict);
        }
        Ok(self.non_modal(command))
    }

    fn non_modal(&mut self, command: NonModal) -> Group {
        // A second group-0 command fails in `enter`, so keeping the first one here is harmless.
        if self.non_modal.is_none() {
            self.non_modal = Some(command);
        }
        Group::NonModal
    }

    fn m(&mut self, value: f32) -> Result<(), GrblError> {
        let (int, tenths) = command_number(value)?;
        if tenths != 0 {
            return Err(GrblError::ValueNotInteger);
        }
        let group = match int {
            0 | 1 | 2 | 30 => {
                self.stop = match int {
                    0 => Some(ProgramStop::Pause),
                    1 => None,
                    _ => Some(ProgramStop::End),
                };
                Group::ProgramStop
            }
            3..=5 => {
                self.spindle = Some([Spindle::Cw, Spindle::Ccw, Spindle::Off][int as usize - 3]);
                Group::Spindle
            }
            8 | 9 => {
                self.coolant = Some(if int == 8 { Coolant::Flood } else { Coolant::Off });
                Group::Coolant
            }
            _ => return Err(GrblError::Unsupported),
        };
        self.enter(group)
    }
}

/// A G or M number as (integer part, tenths): `92.1` is (92, 1); hundredths are refused.
fn command_number(value: f32) -> Result<(u16, u8), GrblError> {
    if !(0.0..1000.0).contains(&value) {
        return Err(GrblError::Unsupported);
    }
    let hundredths = crate::math::round(value * 100.0) as u32;
    if !hundredths.is_multiple_of(10) {
        return Err(GrblError::ValueNotInteger);
    }
    Ok(((hundredths / 100) as u16, ((hundredths % 100) / 10) as u8))
}

/// Parses one line of G-code words (compacted).
pub(super) fn parse_block(bytes: &[u8]) -> Result<Block, GrblError> {
    let mut block = Block::default();
    for word in WordIter::new(bytes) {
        let (letter, value) = word?;
        match letter {
            b'G' => block.g(value)?,
            b'M' => block.m(value)?,
            b'F' | b'N' | b'P' | b'S' | b'T' => {
                block.words.insert(letter, value)?;
                if value < 0.0 {
                    return Err(GrblError::NegativeValue);
                }
                if letter == b'T' && value > TOOL_NUMBER_MAX {
                    return Err(GrblError::MaxValueExceeded);
                }
            }
            b'I' | b'J' | b'K' | b'L' | b'R' | b'X' | b'Y' | b'Z' => block.words.insert(letter, value)?,
            _ => return Err(GrblError::Unsupported),
        }
    }
    Ok(block)
}
