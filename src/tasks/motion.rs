//! The motion task: turns jobs into curves, curves into timed step commands through the
//! planner, and feeds them to the pulse engine through the step queue.
//!
//! It decides nothing. Each job arrives with its curve built and checked (`drawing::build`);
//! how fast each step goes is the planner's ([`crate::motion::planner::Planner`]); the run state it
//! reports, where the pen goes and when, which job waits, the alarms, when the step queue rests
//! and what to wait for next are the supervisor's ([`crate::motion::supervisor::Supervisor`]), which it
//! tells what happened and whose answers it carries out.
//!
//! Each time it runs it takes a trip, controls and jobs, then fills the step queue in one tight
//! loop — as many steps as fit, up to `STEP_QUEUE_MAX_US` of motion, so a hold acts within that
//! time even at the slowest feed — publishes what it queued, and wakes the pulse engine. Then it
//! waits for exactly one of three things: the queue half emitted, a job when the planner has
//! room for one, or a control request (or a change of override, which it hands to the planner).
//! It starts the pulses only once the servos are ready and the pen has settled. On target it
//! runs on its own interrupt executor, between the pulse engine and everything else.

use core::sync::atomic::{Ordering, fence};

use embassy_futures::select::{Either, select};
use embassy_futures::yield_now;
use embassy_time::{Duration, Timer};

use crate::geom::TICKS_PER_US;
use crate::machine::{MotionWriter, STEP_QUEUE_MAX_TICKS};
use crate::machine_io::inputs::Trip;
use crate::motion::drawing::Drawing;
use crate::motion::interp::Curve;
use crate::motion::job::{Control, Job, JobKind};
use crate::motion::overrides::Overrides;
use crate::motion::planner::{Emitted, Limits, PLANNER_SEGMENTS, Planner};
use crate::motion::pulse::{STEP_QUEUE_LEN, StepProducer};
use crate::motion::supervisor::{AtRest, FillEnd, Filled, JobOrder, Next, StartReady, Supervisor, Take, Tripped};
use crate::settings::Settings;
use crate::status::RunState;

/// The step queue holds at least this many steps, however long: the pulse engine holds two (the
/// period counting and the one preloaded after it), so a third is there for the next update
/// event while the task, woken half way through the queue, refills it. Only the slowest feeds
/// queue more than [`STEP_QUEUE_MAX_US`](crate::machine::STEP_QUEUE_MAX_US) so.
pub const STEP_QUEUE_MIN_STEPS: u32 = 3;

/// Should the planner ever have nothing to emit while it says it is moving, the task looks
/// again after this long instead of spinning; also the shortest wait for the queue to drain.
pub const MOTION_RETRY_US: u64 = 100;

/// How often the task looks whether the servos and the pen are ready before it starts the
/// pulses.
pub const SERVO_READY_POLL_MS: u64 = 1;

/// Steps computed before they are published to the pulse engine: the pulses wait at most this
/// many steps' work for a refill, however much of the queue is free (32 functions steps are
/// about 1.3 ms on the F407).
pub const PUBLISH_BATCH_STEPS: usize = 32;

/// Steps queued in one poll at most: half the queue, what the task refills when woken. From
/// an empty queue at the start of a curve, while the planner's look-ahead grows, a whole queue
/// of a function's steps is some 8 ms of the F407; half keeps the poll short.
pub const FILL_MAX_STEPS: u32 = (STEP_QUEUE_LEN / 2) as u32;

/// What the task has queued for the pulse engine: the totals it publishes. (Where the pen is,
/// and where the plan ends, the machine says.)
struct Queued {
    steps: u32,
    ticks: u32,
    /// A rest ends what was published: the pulse engine stops when it is done.
    resting: bool,
    /// The interval of the steps queued last (their mean over the last batch), ticks.
    last_interval_ticks: u32,
}

impl Queued {
    /// Nothing queued: the motion rests, after `steps` and `ticks` so far.
    fn at_rest(steps: u32, ticks: u32) -> Queued {
        Queued { steps, ticks, resting: true, last_interval_ticks: 0 }
    }
}

/// The time the motion task's work takes. On the board it is the time the work really takes,
/// and there is nothing to do ([`RealTime`]); the simulator's virtual time stands still while
/// code runs, and a model of the board's CPU spends it here.
pub trait WorkTime {
    /// `drawing` is planned: its steps come next (a model of the processor may charge them by
    /// its kind and size).
    fn planned(&mut self, _drawing: &Drawing) {}

    /// `emitted` was computed: the future ends once the processor would have done so.
    fn took(&mut self, emitted: &Emitted) -> impl Future<Output = ()>;
}

/// The board's [`WorkTime`]: the work took its time already.
pub struct RealTime;

impl WorkTime for RealTime {
    fn took(&mut self, _emitted: &Emitted) -> impl Future<Output = ()> {
        core::future::ready(())
    }
}

/// Runs the motion forever with `planner` (idle; the board keeps it in static storage, built in
/// place: it is 50 KB). `steps` is the producer end of the step queue; `kick` wakes the pulse
/// engine after steps were published; `work` lets the time of the work pass (see [`WorkTime`]).
pub async fn run(
    machine: MotionWriter<'_>,
    planner: &mut Planner<Curve, PLANNER_SEGMENTS>,
    mut steps: StepProducer<'_>,
    mut kick: impl FnMut(),
    mut work: impl WorkTime,
) -> ! {
    planner.set_limits(Limits::from_settings(&machine.settings()));
    let mut queued = Queued::at_rest(0, 0);
    let mut supervisor = Supervisor::new();
    // The overrides the planner has.
    let mut overrides = Overrides::NONE;
    // A job that needs the pen elsewhere, held back until the motion before it comes to rest.
    let mut held: Option<Job> = None;
    loop {
        if let Some(trip) = machine.take_trip() {
            held = None;
            halted(machine, planner, &mut steps, &mut queued, &supervisor, trip).await;
        }
        if let Some(control) = machine.take_control() {
            apply(machine, planner, control, &mut held);
        }
        overrides = hand_over_overrides(machine, planner, overrides);
        take_jobs(machine, planner, &mut supervisor, &mut held, &mut work);
        if machine.pulses_idle() && !planner.is_idle() && !ready_to_start(machine) {
            // Starting from rest: servos off for standing still (`$1`) take their enable delay,
            // a pen just sent elsewhere its settle time. A control meanwhile is taken first.
            select(until_ready_to_start(machine), machine.control_requested()).await;
            continue;
        }
        let steps_before = queued.steps;
        let end = fill(machine, planner, &mut steps, &mut queued, &mut work).await;
        let queued_more = queued.steps != steps_before;
        let filled = supervisor.filled(end, queued_more);
        carry_out(machine, planner, filled, queued_more, &mut held);
        let then = supervisor.then(end, planner.state(), planner.is_idle(), held.is_some(), queued.resting);
        if then.rest {
            steps.rest();
            queued.resting = true;
        }
        machine.set_queued(queued.steps, queued.ticks);
        machine.set_plan_free_segments(planner.free_segments());
        if queued_more {
            kick();
        }
        if let Some(empty) = then.plan_empty {
            machine.set_plan_empty(empty);
        }
        match then.next {
            Next::Yield => yield_now().await,
            Next::UntilEmitted => until_half_emitted(machine, &queued).await,
            Next::Rest => rest(machine, planner, &mut supervisor, held.is_some()).await,
            Next::Held => stand_held(machine, planner).await,
            Next::Retry => Timer::after(Duration::from_micros(MOTION_RETRY_US)).await,
        }
    }
}

/// The overrides in force, handed to the planner when they differ from `had`, what it has.
fn hand_over_overrides(
    machine: MotionWriter<'_>,
    planner: &mut Planner<Curve, PLANNER_SEGMENTS>,
    had: Overrides,
) -> Overrides {
    let now = machine.overrides();
    if now != had {
        // Acts on what is planned from the next run of steps on.
        planner.set_overrides(now);
    }
    now
}

/// Takes jobs while the planner has room, the one held back first, and plans each as the
/// supervisor says: moving the pen first, or holding the job back until the motion rests.
fn take_jobs(
    machine: MotionWriter<'_>,
    planner: &mut Planner<Curve, PLANNER_SEGMENTS>,
    supervisor: &mut Supervisor,
    held: &mut Option<Job>,
    work: &mut impl WorkTime,
) {
    while !planner.is_full() {
        let Some(job) = held.take().or_else(|| machine.next_job()) else { break };
        // Planned from now on, moving or not yet (the pen or the servos may make it wait).
        machine.set_plan_empty(false);
        let at_rest = planner.is_idle() && machine.pulses_idle();
        match supervisor.take(JobOrder::of(&job), machine.pen(), at_rest) {
            Take::Hold => {
                *held = Some(job);
                break;
            }
            Take::Plan { pen } => {
                if let Some(pen) = pen {
                    machine.set_pen(pen);
                }
                let settings = machine.settings();
                if planner.is_idle() {
                    planner.set_limits(Limits::from_settings(&settings));
                }
                work.planned(&job.drawing);
                plan(machine, planner, job, &settings);
            }
        }
    }
}

/// Carries out what the supervisor says of a fill that `queued_more` steps or not: the run
/// state to publish, and an alarm, which aborts everything (the host is told, see the serial
/// task).
fn carry_out(
    machine: MotionWriter<'_>,
    planner: &mut Planner<Curve, PLANNER_SEGMENTS>,
    filled: Filled,
    queued_more: bool,
    held: &mut Option<Job>,
) {
    if queued_more {
        machine.set_plan_empty(false);
    }
    if let Some(state) = filled.publish {
        machine.set_run_state(state);
    }
    if let Some(fault) = filled.alarm {
        error!("curve stopped part way: {:?}", fault);
        machine.raise_alarm(fault);
        abort(machine, planner, held);
    }
}

/// Waits until half of what the pulse engine has not taken yet is emitted (it holds two steps:
/// the one it emits and the one after), or for a control.
async fn until_half_emitted(machine: MotionWriter<'_>, queued: &Queued) {
    let ahead = machine.queued_ticks().saturating_sub(2 * queued.last_interval_ticks);
    let wait_us = u64::from(ahead / 2 / TICKS_PER_US).max(MOTION_RETRY_US);
    select(Timer::after(Duration::from_micros(wait_us)), machine.control_requested()).await;
}

/// Everything planned is queued: waits until it has been emitted, then does what the
/// supervisor says of the rest: takes the job `held` back, or moves the pen, publishes the run
/// state and waits for work.
async fn rest(
    machine: MotionWriter<'_>,
    planner: &Planner<Curve, PLANNER_SEGMENTS>,
    supervisor: &mut Supervisor,
    held: bool,
) {
    while !machine.pulses_idle() && !machine.halted() {
        machine.until_pulses_stopped().await;
    }
    if machine.run_state() != RunState::Idle {
        let at = machine.position();
        info!("at rest at ({}, {}) steps", at.x, at.y);
    }
    let settings = machine.settings();
    match supervisor.at_rest(held, machine.queued_jobs(), &settings) {
        // The held job moves the pen and goes on.
        AtRest::TakeHeld => {}
        AtRest::Wait { pen, publish } => {
            if let Some(pen) = pen {
                machine.set_pen(pen);
            }
            machine.set_run_state(publish);
            wait_for_work(machine, planner).await;
        }
    }
}

/// A hold stands: reports it, and waits for a control or a job.
async fn stand_held(machine: MotionWriter<'_>, planner: &Planner<Curve, PLANNER_SEGMENTS>) {
    machine.set_run_state(RunState::Hold);
    wait_for_work(machine, planner).await;
}

/// An input tripped the machine (see [`crate::machine_io::inputs`]): once the pulse engine has halted,
/// drops everything planned and queued without braking (the pulses already stopped), takes the
/// position from the pulses emitted, and does what the supervisor says: raises the alarm
/// (motion is refused until `$X`), or hands a limit switch a homing approach ran into to the
/// homing task.
async fn halted(
    machine: MotionWriter<'_>,
    planner: &mut Planner<Curve, PLANNER_SEGMENTS>,
    steps: &mut StepProducer<'_>,
    queued: &mut Queued,
    supervisor: &Supervisor,
    trip: Trip,
) {
    while machine.pulsing() {
        machine.until_pulses_stopped().await;
    }
    error!("tripped: {:?}", trip);
    planner.drop_all();
    steps.retract();
    let (emitted_steps, emitted_ticks) = machine.emitted_totals();
    *queued = Queued::at_rest(emitted_steps, emitted_ticks);
    machine.set_queued(emitted_steps, emitted_ticks);
    machine.set_plan_empty(true);
    machine.set_plan_free_segments(planner.free_segments());
    match supervisor.tripped(trip, machine.is_homing_switch(trip)) {
        Tripped::FoundSwitch => {
            info!("homing found {:?}", trip);
            machine.found_switch(trip);
        }
        Tripped::Alarm(fault) => {
            // The pulses stopped at once: the motion rests, under the alarm.
            machine.set_run_state(RunState::Idle);
            machine.raise_alarm(fault);
            machine.abort_plan();
        }
    }
}

/// Moves step commands from the planner into the step queue: as many as fit, up to
/// [`STEP_QUEUE_MAX_TICKS`] of motion queued but never fewer than [`STEP_QUEUE_MIN_STEPS`]
/// steps, and at most [`FILL_MAX_STEPS`], published [`PUBLISH_BATCH_STEPS`] at a time.
async fn fill(
    machine: MotionWriter<'_>,
    planner: &mut Planner<Curve, PLANNER_SEGMENTS>,
    steps: &mut StepProducer<'_>,
    queued: &mut Queued,
    work: &mut impl WorkTime,
) -> FillEnd {
    let mut ticks_room = STEP_QUEUE_MAX_TICKS.saturating_sub(machine.queued_ticks());
    let mut steps_short = STEP_QUEUE_MIN_STEPS.saturating_sub(machine.queued_steps());
    let mut steps_left = FILL_MAX_STEPS;
    loop {
        // Steps short of the least: a step at a time whatever their length.
        let room = ticks_room.max(u32::from(steps_short > 0));
        let slots = steps.free_slots();
        if steps_left == 0 {
            return FillEnd::PollDone;
        }
        let batch = slots.len().min(PUBLISH_BATCH_STEPS).min(steps_left as usize);
        let Some(slots) = slots.get_mut(..batch).filter(|s| !s.is_empty() && room > 0) else {
            return FillEnd::QueueFull;
        };
        let emitted = planner.fill(slots, room);
        steps_short = steps_short.saturating_sub(emitted.steps as u32);
        steps_left -= emitted.steps as u32;
        work.took(&emitted).await;
        if emitted.steps > 0 {
            // Before the pulse engine may take them.
            if emitted.step_mm_from > 0 {
                machine.set_path_step_mm(queued.steps, emitted.step_mm_before);
            }
            let from = queued.steps.wrapping_add(emitted.step_mm_from as u32);
            machine.set_path_step_mm(from, emitted.step_mm);
        }
        steps.publish(emitted.steps);
        if emitted.steps > 0 {
            queued.resting = false;
            queued.last_interval_ticks = emitted.ticks / emitted.steps as u32;
        }
        queued.steps = queued.steps.wrapping_add(emitted.steps as u32);
        queued.ticks = queued.ticks.wrapping_add(emitted.ticks);
        ticks_room = ticks_room.saturating_sub(emitted.ticks);
        match emitted.end {
            None => {}
            Some(Ok(())) => return FillEnd::PlanEmpty,
            Some(Err(e)) => return FillEnd::CurveFailed(e),
        }
    }
}

/// Queues the curve of `job` in the planner.
fn plan(machine: MotionWriter<'_>, planner: &mut Planner<Curve, PLANNER_SEGMENTS>, job: Job, settings: &Settings) {
    let end = job.drawing.end();
    info!("job planned to ({}, {}) steps", end.x, end.y);
    machine.set_drawing(job.drawing.kind());
    machine.forget_fault();
    let curve = match job.kind {
        // Built without the travel check: see `Job::homing_move`.
        JobKind::Home => job.drawing.into_curve(),
        JobKind::Draw | JobKind::Jog => job.drawing.into_curve().keep_within(settings.travel_steps()),
    };
    let pushed = match job.kind {
        JobKind::Draw | JobKind::Home => planner.push(curve, job.feed, settings.method),
        JobKind::Jog => planner.push_jog(curve, job.feed, settings.method),
    };
    if pushed.is_err() {
        // is_full() was false just now and nothing else pushes.
        error!("planner refused a segment it had room for");
    }
}

/// True when pulses may start from rest, as [`StartReady::ready`] says.
fn ready_to_start(machine: MotionWriter<'_>) -> bool {
    // What this task planned is visible before it looks: see the servo task's going-off check.
    fence(Ordering::SeqCst);
    StartReady { halted: machine.halted(), servos_ready: machine.servos_ready(), pen_settled: machine.pen_settled() }
        .ready()
}

/// Waits until [`ready_to_start`].
async fn until_ready_to_start(machine: MotionWriter<'_>) {
    while !ready_to_start(machine) {
        Timer::after(Duration::from_millis(SERVO_READY_POLL_MS)).await;
    }
}

/// Waits for a control, or for a job while the planner has room to take it.
async fn wait_for_work(machine: MotionWriter<'_>, planner: &Planner<Curve, PLANNER_SEGMENTS>) {
    if planner.is_full() {
        machine.control_requested().await;
    } else {
        match select(machine.job_ready(), machine.control_requested()).await {
            Either::First(()) | Either::Second(()) => {}
        }
    }
}

fn apply(
    machine: MotionWriter<'_>,
    planner: &mut Planner<Curve, PLANNER_SEGMENTS>,
    control: Control,
    held: &mut Option<Job>,
) {
    info!("control: {:?}", control);
    match control {
        Control::Hold => planner.hold(),
        Control::Resume => planner.resume(),
        Control::Abort => abort(machine, planner, held),
    }
}

/// Decelerates to a stop and drops everything planned, queued and `held` back, telling the
/// inputs that positions planned so far are stale.
fn abort(machine: MotionWriter<'_>, planner: &mut Planner<Curve, PLANNER_SEGMENTS>, held: &mut Option<Job>) {
    *held = None;
    planner.abort();
    machine.abort_plan();
}
