//! Which line of a card plot has completed, and when its resume record is due: the bookkeeping
//! between the lines the plot hands over and the steps the pulses have emitted.
//!
//! Each line answered `ok` is marked with the steps the plot had handed to the motion by then:
//! its motion has completed once the pulses have emitted as many since the plot began (the plot
//! begins at rest, and the motion emits the steps handed to it in order, every one of them while
//! nothing aborts). A line that moves nothing completes with the line before it. Of the lines
//! completed, the newest is kept in the record, at most once every [`RESUME_STORE_MIN_MS`].
//!
//! The marks wait in a queue of [`RESUME_MARKS`]; when more lines wait for their motion than
//! that, the newest mark moves on to the newer line (it completes later, never wrongly), so a
//! record may fall further behind, but never ahead of the pen.

use heapless::Deque;

use super::resume::ResumeRecord;
use crate::geom::Point;
use crate::host::gcode::{GcodeState, Modal};

/// Lines whose motion is awaited, at most (more merge into the newest).
pub const RESUME_MARKS: usize = 16;
/// The record is written at most once in this long, ms.
pub const RESUME_STORE_MIN_MS: u64 = 1_000;

/// Where the plot stands once a line's motion has completed.
#[derive(Clone, Debug, PartialEq)]
pub struct LineMark {
    /// The next line's number.
    pub next_line: u32,
    /// Where the next line starts in the file, bytes.
    pub offset: u32,
    /// The line ended in a CR.
    pub after_cr: bool,
    /// The steps handed to the motion up to this line, counted as the motion counts them.
    pub handed_steps: u32,
    /// Where the pen stands once the line has run, steps.
    pub position: Point,
    /// The parser's state after the line.
    pub modal: Modal,
}

/// The bookkeeping; see the module documentation. Its marks take about 2 KB: the boards keep
/// it in static storage, beside the card file's check.
pub struct ResumeKeeper {
    /// The record stored last, or to be stored (its place fields are changed for each store);
    /// `None` while no plot runs.
    record: Option<ResumeRecord>,
    /// The steps handed over and emitted as the plot's lines began; `None` before.
    counts_at_start: Option<(u32, u32)>,
    marks: Deque<LineMark, RESUME_MARKS>,
    /// The newest mark completed and not yet stored.
    done: Option<LineMark>,
    /// When the last record was stored, ms; `None` before the first.
    stored_at_ms: Option<u64>,
    /// Records handed out to be stored since the plot began.
    stores: u32,
}

impl Default for ResumeKeeper {
    fn default() -> Self {
        Self::new()
    }
}

impl ResumeKeeper {
    /// No plot runs.
    pub const fn new() -> Self {
        ResumeKeeper {
            record: None,
            counts_at_start: None,
            marks: Deque::new(),
            done: None,
            stored_at_ms: None,
            stores: 0,
        }
    }

    /// A plot of `record.file` begins (from its start, or resumed): `record` is where.
    pub fn start(&mut self, record: ResumeRecord) {
        self.record = Some(record);
        self.counts_at_start = None;
        self.marks.clear();
        self.done = None;
        self.stored_at_ms = None;
        self.stores = 0;
    }

    /// Records handed out to be stored since the plot began.
    pub fn stores(&self) -> u32 {
        self.stores
    }

    /// Where the plot began (a resumed one: where the record said it goes on), until the first
    /// store after its lines began: the pen's point and the parser's state there.
    pub fn record_at(&self) -> (Point, Modal) {
        self.record.as_ref().map_or((Point::ORIGIN, GcodeState::new().modal()), |r| (r.position, r.modal))
    }

    /// The plot is over: nothing more is kept.
    pub fn stop(&mut self) {
        self.record = None;
    }

    /// The plot's lines begin with the pen at rest, the counts of steps handed over and emitted
    /// as they stand.
    pub fn begin(&mut self, handed_steps: u32, emitted_steps: u32) {
        self.counts_at_start = Some((handed_steps, emitted_steps));
    }

    /// A line was answered `ok`, `emitted_steps` emitted: `mark` is where the plot stands once
    /// its motion completes.
    pub fn answered(&mut self, mark: LineMark, emitted_steps: u32) {
        self.settle(emitted_steps);
        let full = self.marks.is_full();
        if let Some(newest) = self.marks.back_mut()
            && (newest.handed_steps == mark.handed_steps || full)
        {
            // No motion since the mark before, or no room: the line completes with it, or later.
            *newest = mark;
            return;
        }
        let _room = self.marks.push_back(mark);
    }

    /// Takes the marks of the lines completed with `emitted_steps` emitted: the newest is kept
    /// for the next store.
    fn settle(&mut self, emitted_steps: u32) {
        let Some((handed_at_start, emitted_at_start)) = self.counts_at_start else { return };
        let emitted = emitted_steps.wrapping_sub(emitted_at_start);
        while let Some(mark) = self.marks.front() {
            if mark.handed_steps.wrapping_sub(handed_at_start) > emitted {
                break;
            }
            self.done = self.marks.pop_front();
        }
    }

    /// The record to store now, with `emitted_steps` emitted, at `now_ms`: the newest line
    /// completed since the last store, if the last is [`RESUME_STORE_MIN_MS`] old.
    pub fn due(&mut self, emitted_steps: u32, now_ms: u64) -> Option<&mut ResumeRecord> {
        self.settle(emitted_steps);
        if self.counts_at_start.is_none() || self.stored_at_ms.is_some_and(|at| now_ms < at + RESUME_STORE_MIN_MS) {
            return None;
        }
        // Once stored, the record is of the last line stored: only a newer one is worth a store.
        let first = self.stored_at_ms.is_none();
        let record = self.record.as_mut()?;
        let mark = self.done.take().filter(|mark| mark.next_line != record.line);
        if mark.is_none() && !first {
            return None;
        }
        if let Some(mark) = mark {
            record.line = mark.next_line;
            record.offset = mark.offset;
            record.after_cr = mark.after_cr;
            record.position = mark.position;
            record.modal = mark.modal;
        }
        self.stored_at_ms = Some(now_ms);
        self.stores += 1;
        Some(record)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> ResumeRecord {
        ResumeRecord {
            seq: 0,
            file: "PLOT.NC".try_into().unwrap(),
            name: "plot.nc".try_into().unwrap(),
            file_bytes: 1000,
            offset: 0,
            line: 1,
            after_cr: false,
            position: Point::new(5, 5),
            lines: 100,
            modal: GcodeState::new().modal(),
        }
    }

    /// Line `line`, ending at byte `10 * line`, after `handed` steps, leaving the pen at
    /// (`line`, 0).
    fn mark(line: u32, handed: u32) -> LineMark {
        LineMark {
            next_line: line + 1,
            offset: 10 * line,
            after_cr: false,
            handed_steps: handed,
            position: Point::new(line as i32, 0),
            modal: GcodeState::new().modal(),
        }
    }

    #[test]
    fn the_record_holds_the_newest_line_whose_steps_were_all_emitted_at_most_once_a_second() {
        // Counts that wrap during the plot.
        let (handed0, emitted0) = (u32::MAX - 50, u32::MAX - 10);
        let mut k = ResumeKeeper::new();
        assert!(k.due(emitted0, 0).is_none(), "no plot");
        k.start(record());
        assert!(k.due(emitted0, 0).is_none(), "not before the lines begin");
        k.begin(handed0, emitted0);
        // The first store is the plot's start: line 1, nothing drawn.
        let first = k.due(emitted0, 0).unwrap();
        assert_eq!((first.line, first.offset, first.position), (1, 0, Point::new(5, 5)));
        k.answered(mark(1, handed0.wrapping_add(100)), emitted0);
        k.answered(mark(2, handed0.wrapping_add(100)), emitted0); // a line moving nothing
        k.answered(mark(3, handed0.wrapping_add(250)), emitted0);
        assert!(k.due(emitted0.wrapping_add(99), 2_000).is_none(), "line 1 has a step to go");
        let r = k.due(emitted0.wrapping_add(100), 2_000).unwrap();
        assert_eq!((r.line, r.offset, r.position), (3, 20, Point::new(2, 0)), "lines 1 and 2 done");
        assert!(k.due(emitted0.wrapping_add(250), 2_500).is_none(), "half a second after the last store");
        let r = k.due(emitted0.wrapping_add(260), 3_000).unwrap();
        assert_eq!((r.line, r.position), (4, Point::new(3, 0)));
        assert!(k.due(emitted0.wrapping_add(260), 9_000).is_none(), "nothing new completed");
    }

    #[test]
    fn more_lines_waiting_than_marks_complete_later_never_early() {
        let mut k = ResumeKeeper::new();
        k.start(record());
        k.begin(0, 0);
        for line in 1..=(RESUME_MARKS as u32 + 10) {
            k.answered(mark(line, 10 * line), 0);
        }
        let last = RESUME_MARKS as u32 + 10;
        // The marks before the last room held are exact.
        let r = k.due(10 * (RESUME_MARKS as u32 - 1), 0).unwrap();
        assert_eq!(r.line, RESUME_MARKS as u32);
        // The last mark moved on to the newest line: nothing completes before its steps.
        assert!(k.due(10 * last - 1, 5_000).is_none());
        assert_eq!(k.due(10 * last, 10_000).unwrap().line, last + 1);
    }

    #[test]
    fn marks_freed_as_their_lines_complete_keep_the_record_close_behind_the_pen() {
        // Lines of 10 steps, 40 of them in flight at any time (far more than the marks), each
        // answered as the one 40 before it completes; a store is due every 100 lines.
        let mut k = ResumeKeeper::new();
        k.start(record());
        k.begin(0, 0);
        let in_flight = 40;
        for line in 1..=1_000u32 {
            let emitted = 10 * line.saturating_sub(in_flight);
            k.answered(mark(line, 10 * line), emitted);
            if let Some(r) = k.due(emitted, u64::from(line) * 10) {
                let completed = line.saturating_sub(in_flight);
                // Never ahead of the pen, and at most the marks' reach behind it.
                assert!(r.line <= completed + 1, "line {line}: record of {} ahead of {completed}", r.line);
                if line > 200 {
                    let behind = completed + 1 - r.line;
                    assert!(behind <= in_flight, "line {line}: record {behind} lines behind the pen");
                }
            }
        }
    }
}
