//! What the run screen knows about the drawing in progress: its name and planned path (for a
//! keypad drawing), when it started and ended, and from those its progress, elapsed time and the
//! time left.
//!
//! A run is the time the machine spends drawing (`Run` or `Hold`), from the first step to rest.
//! A keypad drawing is confirmed with a [`Plan`]: its name, the path shown before it started, its
//! steps, and its time at the speed the planner cruises at (the feed, capped by the slower
//! axis' max rate). Its progress is the share of those steps emitted; the time left starts from
//! the plan's and leans more and more on the pace measured (see [`Run::left_ms`]). A run from the host link
//! has no plan: the host alone knows how much is still to come, so the screen shows what is
//! queued instead. Times are milliseconds of a clock the caller reads; nothing here reads one.

use heapless::String;

use crate::geom::{Axis, Point};
use crate::motion::job::Feed;
use crate::motion::planner::Limits;
use crate::panel::trail::Trail;
use crate::settings::Settings;

/// Longest name of a drawing on the run screen ("Ellipse 30x15").
pub const JOB_NAME_CHARS: usize = 16;

/// A keypad drawing, as confirmed after its preview.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plan {
    pub name: String<JOB_NAME_CHARS>,
    /// The planned path, sampled along its steps.
    pub path: Trail,
    /// Steps from start to end.
    pub steps: u32,
    /// The time of the whole drawing at the planner's cruise speed and 100 % feed, ms.
    pub estimate_ms: u32,
    /// The machine's emitted-steps count when it was confirmed (the machine at rest).
    pub first_step: u32,
}

impl Plan {
    /// The plan of a drawing of `steps` steps, named `name`, drawn at `feed`: `path`, its path
    /// as the builder walked it ([`Trail::sample`] at every step), and the time that path takes
    /// at the planner's cruise speed.
    pub fn of(steps: u64, path: Trail, name: String<JOB_NAME_CHARS>, feed: Feed, settings: &Settings) -> Plan {
        let limits = Limits::from_settings(settings);
        let [vx, vy] = limits.max_speed_mm_per_s();
        let speed_mm_per_s = limits.requested_speed_mm_per_s(feed).min(vx).min(vy);
        let length_mm: f32 = path
            .points()
            .windows(2)
            .map(|w| {
                let dx = settings.steps_to_mm(Axis::X, w[1].x - w[0].x);
                let dy = settings.steps_to_mm(Axis::Y, w[1].y - w[0].y);
                crate::math::sqrt(dx * dx + dy * dy)
            })
            .sum();
        // Saturating: a plan longer than 49 days shows as that.
        let estimate_ms = (length_mm / speed_mm_per_s * 1000.0) as u32;
        Plan { name, path, steps: u32::try_from(steps).unwrap_or(u32::MAX), estimate_ms, first_step: 0 }
    }
}

/// A run: see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// `None` for a run from the host link.
    pub plan: Option<Plan>,
    /// `None` until the menu first looks at the machine after a keypad drawing was confirmed.
    pub started_ms: Option<u32>,
    /// When the machine came to rest; the run screen then shows the plot time until a key.
    pub ended_ms: Option<u32>,
}

impl Run {
    /// Time from the first step to rest (or to `now_ms` while running), ms.
    pub fn elapsed_ms(&self, now_ms: u32) -> u32 {
        self.started_ms.map_or(0, |start| self.ended_ms.unwrap_or(now_ms).wrapping_sub(start))
    }

    /// Steps emitted of the plan's, clamped to them; `None` without a plan.
    fn done_steps(&self, emitted_steps: u32) -> Option<(u32, u32)> {
        let plan = self.plan.as_ref()?;
        Some((emitted_steps.wrapping_sub(plan.first_step).min(plan.steps), plan.steps.max(1)))
    }

    /// Progress in whole percent of the plan's steps: 100 only once every step is out.
    pub fn percent(&self, emitted_steps: u32) -> Option<u8> {
        let (done, all) = self.done_steps(emitted_steps)?;
        // In f32 (no 64-bit division on the target); a step short of the end stays below 100.
        let percent = (done as f32 * 100.0 / all as f32) as u8;
        Some(if done < all { percent.min(99) } else { 100 })
    }

    /// The time left, ms; `None` without a plan. At first it is the planner's time for the
    /// steps still to go at `feed_percent` of the programmed feed; as the drawing goes on it
    /// leans, in proportion to the share drawn, on the pace measured so far (elapsed time per
    /// step done), which takes in what the plan's estimate leaves out: the slowing on tight
    /// curves, holds, override changes.
    pub fn left_ms(&self, emitted_steps: u32, feed_percent: u8, now_ms: u32) -> Option<u32> {
        let (done, all) = self.done_steps(emitted_steps)?;
        // In f32: a display's precision, and no 64-bit division on the target.
        let (done, all) = (done as f32, all as f32);
        let left = all - done;
        let estimate = self.plan.as_ref()?.estimate_ms as f32;
        let planned = estimate * left / all * 100.0 / f32::from(feed_percent.max(1));
        let paced = if done > 0.0 { self.elapsed_ms(now_ms) as f32 * left / done } else { planned };
        // Saturating: a time beyond 49 days shows as that.
        Some(((planned * left + paced * done) / all) as u32)
    }
}

/// The path drawn in the run the menu shows: cleared when another run starts, sampled from the
/// run's start, and once more when it has ended (the pen's last point).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunPath {
    /// The start of the run `path` belongs to (`None`: no run).
    run_started_ms: Option<Option<u32>>,
    pub path: Trail,
}

impl RunPath {
    /// Follows `run` with the pen at `at`, `drawn` when it draws there. Returns true while the
    /// run is under way: the pen should be looked at again soon.
    pub fn follow(&mut self, run: Option<&Run>, at: Point, drawn: bool) -> bool {
        let started_ms = run.map(|r| r.started_ms);
        if started_ms != self.run_started_ms {
            self.run_started_ms = started_ms;
            self.path.clear();
        }
        if run.is_some_and(|r| r.started_ms.is_some()) {
            self.path.sample(at, drawn);
        }
        run.is_some_and(|r| r.ended_ms.is_none())
    }
}

/// The pages of the run screen, in the order `#` steps through them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum RunPage {
    /// The numbers, with the preview beside them.
    #[default]
    Numbers,
    /// The preview over the whole screen.
    Preview,
    /// Machine coordinates and the keys.
    Machine,
}

impl RunPage {
    pub const fn next(self) -> RunPage {
        match self {
            RunPage::Numbers => RunPage::Preview,
            RunPage::Preview => RunPage::Machine,
            RunPage::Machine => RunPage::Numbers,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keypad_run(steps: u32, estimate_ms: u32) -> Run {
        let plan = Plan { steps, estimate_ms, first_step: u32::MAX - 10, ..Plan::default() };
        Run { plan: Some(plan), started_ms: Some(u32::MAX - 500), ended_ms: None }
    }

    #[test]
    fn progress_follows_the_steps_emitted() {
        let run = keypad_run(1000, 20_000);
        // The counters wrap: the plan started 10 steps before the wrap.
        let at = |done: u32| (u32::MAX - 10).wrapping_add(done);
        assert_eq!(run.percent(at(0)), Some(0));
        assert_eq!(run.percent(at(250)), Some(25));
        assert_eq!(run.percent(at(999)), Some(99), "100 % only at the last step");
        assert_eq!(run.percent(at(1000)), Some(100));
        assert_eq!(run.percent(at(5000)), Some(100), "never beyond the plan");
        assert_eq!(run.elapsed_ms(499), 1000, "the clock wraps too");
    }

    #[test]
    fn time_left_starts_from_the_plan_and_follows_the_pace() {
        let run = keypad_run(1000, 20_000);
        let at = |done: u32| (u32::MAX - 10).wrapping_add(done);
        let ms = |elapsed: u32| (u32::MAX - 500).wrapping_add(elapsed);
        assert_eq!(run.left_ms(at(0), 100, ms(0)), Some(20_000));
        assert_eq!(run.left_ms(at(0), 50, ms(0)), Some(40_000), "at half the feed, twice the time");
        // On plan: a quarter done in a quarter of the time.
        assert_eq!(run.left_ms(at(250), 100, ms(5_000)), Some(15_000));
        // Twice as slow as planned: the pace counts for the share done.
        assert_eq!(run.left_ms(at(250), 100, ms(10_000)), Some(15_000 * 3 / 4 + 30_000 / 4));
        assert_eq!(run.left_ms(at(900), 100, ms(36_000)), Some(2_000 / 10 + 4_000 * 9 / 10));
        assert_eq!(run.left_ms(at(1000), 100, ms(40_000)), Some(0));
    }

    #[test]
    fn a_host_run_has_no_progress_but_its_time() {
        let run = Run { plan: None, started_ms: Some(100), ended_ms: Some(3100) };
        assert_eq!((run.percent(7), run.left_ms(7, 100, 0)), (None, None));
        assert_eq!(run.elapsed_ms(99_999), 3000, "once ended, the plot time stays");
    }

    #[test]
    fn the_path_follows_one_run_and_starts_afresh_with_the_next() {
        let mut follow = RunPath::default();
        let at = |x| Point::new(x, 0);
        assert!(!follow.follow(None, at(5), true), "no run: nothing to follow");
        assert!(follow.path.points().is_empty());
        let mut run = Run { plan: None, started_ms: None, ended_ms: None };
        assert!(follow.follow(Some(&run), at(0), true), "confirmed, not started: under way");
        assert!(follow.path.points().is_empty(), "the clock has not started");
        run.started_ms = Some(10);
        follow.follow(Some(&run), at(0), true);
        follow.follow(Some(&run), at(7), true);
        run.ended_ms = Some(20);
        assert!(!follow.follow(Some(&run), at(9), true), "ended");
        assert_eq!(follow.path.points(), [at(0), at(7), at(9)], "the last point once ended too");
        let next = Run { plan: None, started_ms: Some(30), ended_ms: None };
        follow.follow(Some(&next), at(9), true);
        assert_eq!(follow.path.points(), [at(9)], "a new run starts a new path");
    }

    #[test]
    fn pages_cycle() {
        let p = RunPage::default();
        assert_eq!(p.next().next().next(), p);
        assert_ne!(p.next(), p);
    }
}
