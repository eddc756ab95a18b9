//! One link's count of lines dropped for want of room in its pipe: the receiver counts them,
//! the line loop answers each `error:100` once it has taken every byte that came before them.

use core::cell::Cell;

use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::signal::Signal;

/// The receiver's count of lines dropped for want of room in the pipe.
#[derive(Default)]
pub struct Dropped {
    /// Bytes of lines are dropped, not passed on, until the line loop has answered the lines
    /// dropped so far and the receiver stands at the start of a line.
    pub active: Cell<bool>,
    /// Ends of dropped lines, not yet answered.
    pub lines: Cell<u32>,
    /// The last line byte dropped was not a line end: a dropped line is still under way.
    pub mid_line: Cell<bool>,
    /// Wakes the line loop when a dropped line's end is counted.
    pub counted: Signal<NoopRawMutex, ()>,
}

impl Dropped {
    /// Forgets every dropped line (a reset: lines before it get no answer).
    pub fn clear(&self) {
        self.active.set(false);
        self.lines.set(0);
        self.mid_line.set(false);
    }

    /// The dropped lines to answer now, if the line loop has taken every byte that came before
    /// them; passing bytes on starts again if no dropped line is under way.
    pub fn take(&self, pipe_empty: bool) -> u32 {
        if !self.active.get() || !pipe_empty {
            return 0;
        }
        let n = self.lines.replace(0);
        if !self.mid_line.get() {
            self.active.set(false);
        }
        n
    }
}
