//! Where the plan ends, as pure bookkeeping: the [`PlanEnd`] every input plans from, and the
//! rules that move it ([`PlanState`]): a job handed over moves it to the job's end, an abort
//! makes every earlier end stale and leaves it unknown until the machine stops, and the motion
//! task takes only jobs planned from the end the jobs before them left. The machine keeps one
//! `PlanState` under a critical section (see [`jobs`](super::jobs)).

use crate::geom::Point;

/// A job planned from a [`PlanEnd`] that is not where the plan ends (another input handed a job
/// over, or an abort came, since): it is not queued.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Stale;

/// A point on the plan: where the pen will be once the jobs handed over so far have run, and
/// how many changes of the plan (jobs handed over, aborts, an approach stopped at its switch)
/// led there. Two ends are equal only if no change came between them, even one that left the
/// pen at the same point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct PlanEnd {
    at: Point,
    changes: u32,
}

impl PlanEnd {
    /// Where the pen will be, machine steps.
    pub const fn at(self) -> Point {
        self.at
    }

    /// The plan's end after one more change that leaves the pen at `at`.
    pub const fn then(self, at: Point) -> PlanEnd {
        PlanEnd { at, changes: self.changes.wrapping_add(1) }
    }
}

/// The plan's bookkeeping, shared by the inputs and the motion task.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlanState {
    /// Where the last job handed over ends: what the next one must be planned from.
    end: PlanEnd,
    /// Where the last job the motion task took ends: what the next one it takes must have been
    /// planned from (a job queued as an abort came is not).
    taken: PlanEnd,
    /// An abort came and the machine has not stopped since: the plan ends where the pen stops,
    /// not known yet.
    settling: bool,
}

impl PlanState {
    /// At power-on: nothing planned, the pen at `at`.
    pub(super) const fn at(at: Point) -> PlanState {
        let end = PlanEnd { at, changes: 0 };
        PlanState { end, taken: end, settling: false }
    }

    /// The plan's end, once the machine has stopped after an abort (`stopped`, the pen at `pen`).
    pub(super) fn end(&mut self, stopped: bool, pen: Point) -> Option<PlanEnd> {
        if self.settling {
            if !stopped {
                return None;
            }
            self.end.at = pen;
            self.taken = self.end;
            self.settling = false;
        }
        Some(self.end)
    }

    /// A job from `from` to `to` is handed over: the plan ends at `to`. `Err` if `from` is not
    /// where the plan ends now.
    pub(super) fn hand_over(&mut self, from: PlanEnd, start: Point, to: Point) -> Result<PlanEnd, Stale> {
        if self.settling || self.end != from || start != from.at {
            return Err(Stale);
        }
        self.end = from.then(to);
        Ok(self.end)
    }

    /// A job handed over as `ends` found no room: the plan ends where it did before, unless an
    /// abort came meanwhile.
    pub(super) fn take_back(&mut self, from: PlanEnd, ends: PlanEnd) {
        if self.end == ends {
            self.end = from;
        }
    }

    /// The motion task takes a job planned from `from`, ending at `to`: false if it was planned
    /// before an abort (it is dropped).
    pub(super) fn take(&mut self, from: PlanEnd, to: Point) -> bool {
        if self.settling || self.taken != from {
            return false;
        }
        self.taken = from.then(to);
        true
    }

    /// True if the plan ends at `end`.
    pub(super) fn ends_at(&self, end: PlanEnd) -> bool {
        !self.settling && self.end == end
    }

    /// An abort: every end planned so far is stale, and the plan ends where the pen stops.
    pub(super) fn abort(&mut self) {
        self.end = self.end.then(self.end.at);
        self.taken = self.end;
        self.settling = true;
    }

    /// The pen stands at `pen`, with nothing queued after it, other than the plan said (a
    /// homing approach stopped at its switch, or machine zero moved): the plan ends there.
    pub(super) fn restart_at(&mut self, pen: Point) {
        if !self.settling {
            self.end = self.end.then(pen);
            self.taken = self.end;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plan_ends_where_the_last_job_handed_over_ends_and_after_an_abort_where_the_pen_stops() {
        let (origin, ten, pen) = (Point::ORIGIN, Point::new(10, 0), Point::new(4, 0));
        let mut plan = PlanState::at(origin);
        let start = plan.end(true, origin).unwrap();
        let first = plan.hand_over(start, origin, ten).unwrap();
        assert_eq!(first.at(), ten);
        assert_eq!(plan.hand_over(start, origin, Point::new(-10, 0)), Err(Stale), "planned before the first");
        assert_eq!(plan.hand_over(first, origin, Point::new(20, 0)), Err(Stale), "not starting at the end");
        assert!(plan.take(start, ten));
        plan.abort();
        assert_eq!(plan.end(false, pen), None, "unknown while the pen moves");
        assert_eq!(plan.hand_over(first, ten, Point::new(20, 0)), Err(Stale));
        let stopped = plan.end(true, pen).unwrap();
        assert_eq!(stopped.at(), pen, "where the pen stopped");
        assert!(!plan.take(first, Point::new(20, 0)), "planned before the abort: dropped");
        let next = plan.hand_over(stopped, pen, origin).unwrap();
        assert!(plan.ends_at(next));
        plan.take_back(stopped, next);
        assert!(plan.ends_at(stopped), "a job given back leaves the plan as it was");
        plan.restart_at(ten);
        assert_eq!(plan.end(true, ten).map(PlanEnd::at), Some(ten));
        assert!(!plan.ends_at(stopped));
    }
}
