//! Jobs handed from the inputs (the host link, the keypad and the homing task, all in thread
//! mode) to the motion task, and the epoch rule that keeps their planned positions true: each
//! job goes with the [`PlanEpoch`] it was planned in, an abort starts a new one, and a job from
//! an earlier epoch is refused ([`Stale`]) or, if it was queued already, dropped. The jobs pass
//! through a [`JobQueue`](super::job_queue::JobQueue): written and read outside any lock.

use core::future::poll_fn;
use core::sync::atomic::Ordering;
use core::task::Poll;

use super::{Machine, PlanEpoch, Refused, Stale};
use crate::job::Job;

impl Machine {
    /// The epoch positions are planned in now: until the next abort, a job planned from the
    /// end of the jobs before it starts where the pen will be.
    pub fn plan_epoch(&self) -> PlanEpoch {
        PlanEpoch(self.aborts.load(Ordering::Acquire))
    }

    /// Hands `job`, planned in `epoch`, to the motion task, waiting for room. An abort before
    /// or while it waits refuses it: it was planned from a point the pen will not reach.
    pub async fn submit(&self, job: Job, epoch: PlanEpoch) -> Result<(), Stale> {
        let mut job = Some((epoch, job));
        poll_fn(|cx| {
            if self.plan_epoch() != epoch {
                return Poll::Ready(Err(Stale));
            }
            // An abort empties the queue and wakes this.
            self.jobs.poll_push(&mut job, cx).map(Ok)
        })
        .await?;
        // Queued just as an abort came, the motion task drops it.
        if self.plan_epoch() != epoch { Err(Stale) } else { Ok(()) }
    }

    /// Hands `job`, planned in `epoch`, to the motion task if there is room now.
    pub fn try_submit(&self, job: Job, epoch: PlanEpoch) -> Result<(), Refused> {
        if self.plan_epoch() != epoch {
            return Err(Refused::Stale);
        }
        self.jobs.push((epoch, job)).map_err(|_| Refused::Full)
    }

    /// Jobs handed over and not yet taken by the motion task.
    pub fn queued_jobs(&self) -> usize {
        self.jobs.len()
    }

    /// Waits until a job is queued (it may already be). For the motion task.
    pub async fn job_ready(&self) {
        self.jobs.ready().await
    }

    /// The next job queued in the current epoch, dropping those planned before an abort (their
    /// senders were refused, or the abort's message covers them). Only the motion task calls
    /// this.
    pub fn next_job(&self) -> Option<Job> {
        loop {
            let (epoch, job) = self.jobs.pop()?;
            if epoch == self.plan_epoch() {
                // Taken, it is planned before anything else may look: nothing has stopped.
                self.plan_empty.store(false, Ordering::Release);
                return Some(job);
            }
            warn!("job planned before an abort dropped");
        }
    }

    /// An abort: starts a new epoch, so that jobs planned before it are refused, and drops
    /// every queued job, which wakes the inputs waiting to hand one over (to be refused). Only
    /// the motion task calls this, once its planner has dropped its plan.
    pub fn abort_plan(&self) {
        self.aborts.fetch_add(1, Ordering::AcqRel);
        // A job handed over in the old epoch after this is dropped by `next_job`.
        self.jobs.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drawing::{self, Request};
    use crate::geom::Point;
    use crate::job::Feed;
    use crate::machine::JOB_QUEUE_LEN;
    use crate::settings::Settings;
    use core::pin::pin;
    use core::task::{Context, Waker};

    /// A line from the origin to `x_mm` on X.
    fn line(x_mm: f32) -> Job {
        let settings = Settings::default();
        let to = drawing::line_target([x_mm, 0.0], &settings).unwrap();
        let drawing = drawing::build(&Request::Straight { to }, Point::ORIGIN, &settings).unwrap().unwrap();
        Job::draw(drawing, Feed::MmPerMin(1_000.0))
    }

    fn end_x(job: &Job) -> i32 {
        job.drawing.end().x
    }

    #[test]
    fn jobs_reach_the_motion_task_in_order_until_the_queue_is_full() {
        let machine = Machine::new(Settings::default());
        let epoch = machine.plan_epoch();
        for n in 1..=JOB_QUEUE_LEN {
            assert_eq!(machine.try_submit(line(n as f32), epoch), Ok(()));
        }
        assert_eq!(machine.try_submit(line(99.0), epoch), Err(Refused::Full));
        assert_eq!(machine.queued_jobs(), JOB_QUEUE_LEN);
        let ends: std::vec::Vec<i32> = core::iter::from_fn(|| machine.next_job()).map(|j| end_x(&j)).collect();
        let expected: std::vec::Vec<i32> = (1..=JOB_QUEUE_LEN).map(|n| end_x(&line(n as f32))).collect();
        assert_eq!(ends, expected);
        assert_eq!(machine.queued_jobs(), 0);
    }

    #[test]
    fn an_abort_drops_the_queued_jobs_and_refuses_those_planned_before_it() {
        let machine = Machine::new(Settings::default());
        let before = machine.plan_epoch();
        machine.try_submit(line(1.0), before).unwrap();
        machine.try_submit(line(2.0), before).unwrap();
        machine.abort_plan();
        assert_eq!(machine.queued_jobs(), 0);
        assert!(machine.next_job().is_none());
        assert_eq!(machine.try_submit(line(3.0), before), Err(Refused::Stale));
        let after = machine.plan_epoch();
        assert_ne!(after, before);
        machine.try_submit(line(4.0), after).unwrap();
        assert_eq!(machine.next_job().map(|j| end_x(&j)), Some(end_x(&line(4.0))));
    }

    #[test]
    fn a_job_handed_over_in_the_old_epoch_as_an_abort_came_is_dropped_when_taken() {
        let machine = Machine::new(Settings::default());
        let before = machine.plan_epoch();
        // The input checked the epoch, then the abort came before its job was in.
        machine.abort_plan();
        machine.jobs.push((before, line(1.0))).unwrap();
        machine.try_submit(line(2.0), machine.plan_epoch()).unwrap();
        assert_eq!(machine.next_job().map(|j| end_x(&j)), Some(end_x(&line(2.0))), "the stale one skipped");
        assert!(machine.next_job().is_none());
    }

    #[test]
    fn submit_waits_for_room_and_is_refused_by_an_abort_while_it_waits() {
        let machine = Machine::new(Settings::default());
        let epoch = machine.plan_epoch();
        for n in 1..=JOB_QUEUE_LEN {
            machine.try_submit(line(n as f32), epoch).unwrap();
        }
        let mut cx = Context::from_waker(Waker::noop());
        let mut waiting = pin!(machine.submit(line(50.0), epoch));
        assert!(waiting.as_mut().poll(&mut cx).is_pending(), "the queue is full");
        machine.next_job().unwrap();
        assert_eq!(waiting.as_mut().poll(&mut cx), Poll::Ready(Ok(())), "room made");
        assert_eq!(machine.queued_jobs(), JOB_QUEUE_LEN);

        let mut refused = pin!(machine.submit(line(60.0), epoch));
        assert!(refused.as_mut().poll(&mut cx).is_pending());
        machine.abort_plan();
        assert_eq!(refused.as_mut().poll(&mut cx), Poll::Ready(Err(Stale)));
        assert_eq!(machine.queued_jobs(), 0, "nothing queued after the abort");
    }

    #[test]
    fn the_motion_task_waits_for_a_job_and_is_woken_by_its_handing_over() {
        let machine = Machine::new(Settings::default());
        let mut cx = Context::from_waker(Waker::noop());
        let mut ready = pin!(machine.job_ready());
        assert!(ready.as_mut().poll(&mut cx).is_pending());
        machine.try_submit(line(1.0), machine.plan_epoch()).unwrap();
        assert!(ready.as_mut().poll(&mut cx).is_ready());
    }
}
