//! Jobs handed from the inputs (the host link, the keypad and the homing task, all in thread
//! mode) to the motion task, and the one answer to where the plan ends: the end of the last job
//! handed over, or, after an abort, where the pen stops. Every input plans from that
//! [`PlanEnd`] and hands its job over with it; a job planned from anything but the plan's end
//! as it stands (another input handed one over, or an abort came, in between) is refused
//! ([`Stale`]) and changes nothing, or, if it was queued already, dropped when taken. The jobs
//! pass through a [`JobQueue`](super::job_queue::JobQueue), written and read outside any lock;
//! the plan's end is a [`PlanState`] of 28 bytes, read and changed under a critical section
//! (its rules are in [`plan_end`](super::plan_end)).

use core::cell::Cell;
use core::future::poll_fn;
use core::task::Poll;

use super::motion_writer::MotionWriter;
use super::plan_end::{PlanEnd, PlanState, Stale};
use super::{Machine, Refused};
use crate::motion::job::Job;

impl Machine {
    fn plan<R>(&self, f: impl FnOnce(&mut PlanState) -> R) -> R {
        self.plan.lock(|p: &Cell<PlanState>| {
            let mut state = p.get();
            let r = f(&mut state);
            p.set(state);
            r
        })
    }

    /// Where the plan ends: where the pen will be once every job handed over so far has run.
    /// `None` after an abort until the machine has stopped; then where the pen stopped.
    pub fn plan_end(&self) -> Option<PlanEnd> {
        let (stopped, pen) = (self.stopped(), self.position());
        self.plan(|p| p.end(stopped, pen))
    }

    /// Hands `job`, planned from `from`, to the motion task, waiting for room; the plan then
    /// ends where it does. Refused if `from` is not where the plan ends, or stops being so
    /// (an abort) before or while it waits: it was planned from a point the pen will not reach.
    ///
    /// The inputs run in thread mode, one poll at a time: between an input's look at the plan's
    /// end and its job's queueing, only the motion task may come, to take a job (the plan's end
    /// stays) or to abort (the job is refused here, and dropped if it was queued).
    pub async fn submit(&self, job: Job, from: PlanEnd) -> Result<PlanEnd, Stale> {
        let mut entry = Some((from, job));
        poll_fn(|cx| {
            let Some((_, job)) = entry.as_ref() else { return Poll::Ready(Err(Stale)) };
            let ends = self.plan(|p| p.hand_over(from, job.drawing.start(), job.drawing.end()))?;
            // An abort empties the queue and wakes this.
            let queued = self.jobs.poll_push(&mut entry, cx);
            if queued.is_pending() {
                // Not handed over yet: the plan ends where it did.
                self.plan(|p| p.take_back(from, ends));
            }
            queued.map(|()| Ok(ends))
        })
        .await
        .and_then(|ends| self.still_planned(ends))
    }

    /// Hands `job`, planned from `from`, to the motion task if there is room now; the plan then
    /// ends where it does.
    pub fn try_submit(&self, job: Job, from: PlanEnd) -> Result<PlanEnd, Refused> {
        let ends =
            self.plan(|p| p.hand_over(from, job.drawing.start(), job.drawing.end())).map_err(|Stale| Refused::Stale)?;
        if self.jobs.push((from, job)).is_err() {
            self.plan(|p| p.take_back(from, ends));
            return Err(Refused::Full);
        }
        self.still_planned(ends).map_err(|Stale| Refused::Stale)
    }

    /// `ends`, where the plan ended as a job was queued, is still where it ends: no abort came
    /// in between (the motion task drops the job then).
    fn still_planned(&self, ends: PlanEnd) -> Result<PlanEnd, Stale> {
        if self.plan(|p| p.ends_at(ends)) { Ok(ends) } else { Err(Stale) }
    }

    /// Jobs handed over and not yet taken by the motion task.
    pub fn queued_jobs(&self) -> usize {
        self.jobs.len()
    }

    /// The pen stands elsewhere than the plan said, with nothing queued (a homing approach
    /// stopped at its switch, or machine zero moved): the plan ends where it stands.
    pub(super) fn plan_from_pen(&self) {
        let pen = self.position();
        self.plan(|p| p.restart_at(pen));
    }
}

/// The jobs' taker: the motion task.
impl MotionWriter<'_> {
    /// Waits until a job is queued (it may already be).
    pub async fn job_ready(self) {
        self.machine().jobs.ready().await
    }

    /// The next job planned from where the jobs taken before it end, dropping those planned
    /// before an abort (their senders were refused, or the abort's message covers them).
    pub fn next_job(self) -> Option<Job> {
        loop {
            let (from, job) = self.machine().jobs.pop()?;
            if self.machine().plan(|p| p.take(from, job.drawing.end())) {
                // Taken, it is planned before anything else may look: nothing has stopped.
                self.set_plan_empty(false);
                return Some(job);
            }
            warn!("job planned before an abort dropped");
        }
    }

    /// An abort: every end planned so far is stale, so that jobs planned from one are refused,
    /// and the plan ends where the pen stops; drops every queued job, which wakes the inputs
    /// waiting to hand one over (to be refused). Once the planner has dropped its plan.
    pub fn abort_plan(self) {
        self.machine().plan(PlanState::abort);
        // A job handed over before this and queued after it is dropped by `next_job`.
        self.machine().jobs.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Point, Step, StepCmd};
    use crate::machine::JOB_QUEUE_LEN;
    use crate::machine::PulseWriter;
    use crate::motion::drawing::{self, Request};
    use crate::motion::job::Feed;

    /// The motion task's handle, for the motion task's part.
    fn motion(machine: &Machine) -> MotionWriter<'_> {
        MotionWriter::new(machine)
    }
    use crate::settings::Settings;
    use core::pin::pin;
    use core::task::{Context, Waker};

    /// A line from `from` to `x_mm` on X.
    fn line_from(from: Point, x_mm: f32) -> Job {
        let settings = Settings::default();
        let to = drawing::line_target([x_mm, 0.0], &settings).unwrap();
        let drawing = drawing::build(&Request::Straight { to }, from, &settings).unwrap().unwrap();
        Job::draw(drawing, Feed::MmPerMin(1_000.0))
    }

    /// A line from where `end` is to `x_mm` on X.
    fn line(end: PlanEnd, x_mm: f32) -> Job {
        line_from(end.at(), x_mm)
    }

    fn x(mm: f32) -> i32 {
        line_from(Point::ORIGIN, mm).drawing.end().x
    }

    fn end_x(job: &Job) -> i32 {
        job.drawing.end().x
    }

    /// The pulse engine's part: `dx` steps along X emitted, and nothing more queued.
    fn emit(machine: &Machine, dx: i32) {
        let step = Step::new(dx.signum() as i8, 0);
        for _ in 0..dx.abs() {
            PulseWriter::new(machine).emitted(StepCmd::new(step, 1));
        }
        let (steps, ticks) = machine.emitted_totals();
        motion(machine).set_queued(steps, ticks);
    }

    /// The motion task's part: takes every job queued, and runs them: the pen ends where the
    /// last one does. The X each ends at.
    fn run_all(machine: &Machine) -> std::vec::Vec<i32> {
        let taken: std::vec::Vec<Job> = core::iter::from_fn(|| motion(machine).next_job()).collect();
        if let Some(last) = taken.last() {
            emit(machine, last.drawing.end().x - machine.position().x);
        }
        motion(machine).set_plan_empty(true);
        taken.iter().map(end_x).collect()
    }

    #[test]
    fn each_job_hands_the_plan_on_to_its_end_and_the_jobs_reach_the_motion_task_in_order() {
        let machine = Machine::new(Settings::default());
        let mut end = machine.plan_end().unwrap();
        assert_eq!(end.at(), Point::ORIGIN);
        for n in 1..=JOB_QUEUE_LEN {
            end = machine.try_submit(line(end, n as f32), end).unwrap();
            assert_eq!(end.at(), Point::new(x(n as f32), 0));
            assert_eq!(machine.plan_end(), Some(end), "the plan ends where the last job does");
        }
        let before = machine.plan_end();
        assert_eq!(machine.try_submit(line(end, 99.0), end), Err(Refused::Full));
        assert_eq!(machine.plan_end(), before, "a job without room changes nothing");
        assert_eq!(machine.queued_jobs(), JOB_QUEUE_LEN);
        let expected: std::vec::Vec<i32> = (1..=JOB_QUEUE_LEN).map(|n| x(n as f32)).collect();
        assert_eq!(run_all(&machine), expected);
        assert_eq!(machine.queued_jobs(), 0);
        assert_eq!(machine.plan_end(), Some(end), "taking the jobs leaves the plan's end");
    }

    #[test]
    fn a_job_planned_before_another_was_handed_over_is_refused_and_changes_nothing() {
        let machine = Machine::new(Settings::default());
        let start = machine.plan_end().unwrap();
        // Two inputs plan from the same end; the keypad's goes first.
        let keypad = machine.try_submit(line(start, 5.0), start).unwrap();
        assert_eq!(machine.try_submit(line(start, -5.0), start), Err(Refused::Stale));
        assert_eq!(machine.plan_end(), Some(keypad));
        assert_eq!(run_all(&machine), [x(5.0)], "only the keypad's is drawn");
        // Even a job from the same point is stale once another was handed over in between.
        let there = machine.plan_end().unwrap();
        let back = machine.try_submit(line(there, 0.0), there).unwrap();
        let round = machine.try_submit(line(back, 5.0), back).unwrap();
        assert_eq!(round.at(), there.at());
        assert_eq!(machine.try_submit(line(there, 7.0), there), Err(Refused::Stale));
        // And a job that does not start where its end says is refused too.
        assert_eq!(machine.try_submit(line_from(Point::ORIGIN, 7.0), round), Err(Refused::Stale));
        assert_eq!(machine.plan_end(), Some(round));
    }

    #[test]
    fn after_an_abort_the_plan_ends_where_the_pen_stops_and_earlier_plans_are_refused() {
        let machine = Machine::new(Settings::default());
        let start = machine.plan_end().unwrap();
        let first = machine.try_submit(line(start, 10.0), start).unwrap();
        let second = machine.try_submit(line(first, 20.0), first).unwrap();
        // The motion task takes the first and stops 3 steps along it.
        assert_eq!(motion(&machine).next_job().map(|j| end_x(&j)), Some(x(10.0)));
        emit(&machine, 3);
        motion(&machine).abort_plan();
        assert_eq!(machine.queued_jobs(), 0, "the second was dropped");
        assert_eq!(machine.plan_end(), None, "unknown until the machine stops");
        assert_eq!(machine.try_submit(line(second, 30.0), second), Err(Refused::Stale));
        motion(&machine).set_plan_empty(true);
        let stopped = machine.plan_end().unwrap();
        assert_eq!(stopped.at(), Point::new(3, 0), "where the pen stopped");
        assert_eq!(machine.try_submit(line(second, 30.0), second), Err(Refused::Stale));
        assert_eq!(machine.try_submit(line(start, 30.0), start), Err(Refused::Stale));
        machine.try_submit(line(stopped, 4.0), stopped).unwrap();
        assert_eq!(run_all(&machine), [x(4.0)]);
    }

    #[test]
    fn an_abort_at_rest_still_refuses_what_was_planned_before_it() {
        let machine = Machine::new(Settings::default());
        let before = machine.plan_end().unwrap();
        motion(&machine).abort_plan();
        let after = machine.plan_end().unwrap();
        assert_eq!(after.at(), before.at(), "the pen did not move");
        assert_ne!(after, before);
        assert_eq!(machine.try_submit(line(before, 1.0), before), Err(Refused::Stale));
        machine.try_submit(line(after, 1.0), after).unwrap();
    }

    #[test]
    fn a_job_queued_just_as_an_abort_came_is_dropped_when_taken() {
        let machine = Machine::new(Settings::default());
        let before = machine.plan_end().unwrap();
        // The input's job was handed over, then the abort came before it was in the queue.
        machine.plan(|p| p.hand_over(before, Point::ORIGIN, Point::new(x(1.0), 0))).unwrap();
        motion(&machine).abort_plan();
        machine.jobs.push((before, line(before, 1.0))).unwrap();
        assert_eq!(machine.plan_end(), None, "the machine has not stopped: a job is queued");
        assert!(motion(&machine).next_job().is_none(), "the motion task drops it");
        let after = machine.plan_end().unwrap();
        machine.try_submit(line(after, 2.0), after).unwrap();
        assert_eq!(run_all(&machine), [x(2.0)]);
    }

    #[test]
    fn a_stop_short_of_the_plan_with_nothing_after_it_restarts_the_plan_at_the_pen() {
        let machine = Machine::new(Settings::default());
        let start = machine.plan_end().unwrap();
        let ends = machine.try_submit(line(start, 10.0), start).unwrap();
        motion(&machine).next_job().unwrap();
        emit(&machine, 7);
        machine.plan_from_pen();
        assert_eq!(machine.plan_end(), Some(ends.then(Point::new(7, 0))));
        assert_eq!(machine.try_submit(line(ends, 1.0), ends), Err(Refused::Stale));
        let here = machine.plan_end().unwrap();
        machine.try_submit(line(here, 1.0), here).unwrap();
        assert_eq!(run_all(&machine), [x(1.0)]);
    }

    #[test]
    fn submit_waits_for_room_and_is_refused_by_an_abort_while_it_waits() {
        let machine = Machine::new(Settings::default());
        let mut end = machine.plan_end().unwrap();
        for n in 1..=JOB_QUEUE_LEN {
            end = machine.try_submit(line(end, n as f32), end).unwrap();
        }
        let mut cx = Context::from_waker(Waker::noop());
        let mut waiting = pin!(machine.submit(line(end, 50.0), end));
        assert!(waiting.as_mut().poll(&mut cx).is_pending(), "the queue is full");
        assert_eq!(machine.plan_end(), Some(end), "not handed over while it waits");
        motion(&machine).next_job().unwrap();
        let Poll::Ready(Ok(after)) = waiting.as_mut().poll(&mut cx) else { panic!("room made") };
        assert_eq!(after.at(), Point::new(x(50.0), 0));
        assert_eq!(machine.queued_jobs(), JOB_QUEUE_LEN);

        let mut refused = pin!(machine.submit(line(after, 60.0), after));
        assert!(refused.as_mut().poll(&mut cx).is_pending());
        motion(&machine).abort_plan();
        assert_eq!(refused.as_mut().poll(&mut cx), Poll::Ready(Err(Stale)));
        assert_eq!(machine.queued_jobs(), 0, "nothing queued after the abort");
    }

    #[test]
    fn the_motion_task_waits_for_a_job_and_is_woken_by_its_handing_over() {
        let machine = Machine::new(Settings::default());
        let mut cx = Context::from_waker(Waker::noop());
        let mut ready = pin!(motion(&machine).job_ready());
        assert!(ready.as_mut().poll(&mut cx).is_pending());
        let end = machine.plan_end().unwrap();
        machine.try_submit(line(end, 1.0), end).unwrap();
        assert!(ready.as_mut().poll(&mut cx).is_ready());
    }
}
