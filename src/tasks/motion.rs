//! The motion task: turns jobs into curves, curves into timed step commands through the
//! planner, and feeds them to the pulse task through the step queue.
//!
//! It only moves values: which curve a job is, and how fast each step goes, are decided by the
//! core (`interp::Curve::for_job`, `planner::Planner`). It waits for exactly one of three things:
//! room in the step queue (bounded in count, and in time by `STEP_QUEUE_MAX_US`, so a hold acts
//! within that time even at the slowest feed), a job when the planner has room for one, or a
//! control request. On target it runs on its own interrupt executor, between the pulse task and
//! everything else.

use embassy_futures::select::{Either, select};
use embassy_time::{Duration, Timer};

use crate::geom::Point;
use crate::interp::Curve;
use crate::job::{Control, Job, JobKind};
use crate::machine::{Machine, MotionFault, STEP_QUEUE_MAX_TICKS};
use crate::planner::{Limits, PLANNER_SEGMENTS, Planner, PlannerState};
use crate::settings::Settings;
use crate::status::RunState;

/// Should the planner ever have nothing to emit while it says it is moving, the task looks
/// again after this long instead of spinning.
pub const MOTION_RETRY_US: u64 = 100;

/// Runs the motion forever.
pub async fn run(machine: &Machine) -> ! {
    let mut planner: Planner<Curve, PLANNER_SEGMENTS> = Planner::new(Limits::from_settings(&machine.settings()));
    // Where the steps handed to the pulse task so far take the pen.
    let mut sent_end: Point = machine.position();
    // Where the pen will be once everything planned so far has been emitted.
    let mut planned_end = sent_end;
    // Reported while moving: a jog while the last job taken was one (jogs start only at rest
    // or behind other jogs).
    let mut moving = RunState::Run;
    loop {
        if let Some(control) = machine.take_control() {
            apply(machine, &mut planner, control);
        }
        if planner.is_idle() {
            // Nothing planned (after an abort, a curve error, or at rest): the next job starts
            // where the pen stops, not where an abandoned plan would have ended.
            planned_end = sent_end;
        }
        while !planner.is_full() {
            let Ok(job) = machine.jobs.try_receive() else { break };
            if job.aborts_before != machine.aborts() {
                // Planned before an abort, from where the dropped plan would have ended; its
                // sender was told (`error:9`) or the abort's message covers it.
                warn!("job planned before an abort dropped");
                continue;
            }
            let settings = machine.settings();
            if planner.is_idle() {
                planner.set_limits(Limits::from_settings(&settings));
            }
            if let Some(kind) = plan(machine, &mut planner, &mut planned_end, &job, &settings) {
                moving = kind;
            }
        }
        let queued = machine.queued_ticks();
        if queued >= STEP_QUEUE_MAX_TICKS {
            // Enough motion queued: wait until half of it is emitted, or for a control.
            let wait = Duration::from_ticks(u64::from(queued - STEP_QUEUE_MAX_TICKS / 2));
            select(Timer::after(wait), machine.control_requested()).await;
            continue;
        }
        match planner.next_cmd() {
            Some(Ok(cmd)) => {
                machine.set_plan_empty(false);
                machine.set_run_state(moving);
                sent_end = sent_end.stepped(cmd.step);
                machine.queue_step(cmd).await;
            }
            Some(Err(e)) => {
                // The curve left its domain or the travel area part way: stop there and drop
                // what was planned after it, since it was planned from a point the pen never
                // reached. The host is told (see the serial task).
                warn!("curve ended early: {:?}", e);
                machine.set_fault(Some(MotionFault::Curve(e)));
                abort(machine, &mut planner);
            }
            None => {
                machine.set_plan_empty(planner.is_idle());
                match planner.state() {
                    PlannerState::Idle => {
                        // Everything planned is queued: rest once it has been emitted.
                        while !machine.pulses_idle() {
                            machine.pulses_done.wait().await;
                        }
                        if machine.run_state() != RunState::Idle {
                            info!("at rest at ({}, {}) steps", sent_end.x, sent_end.y);
                        }
                        machine.set_run_state(RunState::Idle);
                        wait_for_work(machine, &planner).await;
                    }
                    PlannerState::Held => {
                        machine.set_run_state(RunState::Hold);
                        wait_for_work(machine, &planner).await;
                    }
                    PlannerState::Running | PlannerState::Holding | PlannerState::Aborting => {
                        Timer::after(Duration::from_micros(MOTION_RETRY_US)).await;
                    }
                }
            }
        }
    }
}

/// Turns `job` into a curve from `planned_end` and queues it in the planner; the kind of
/// motion it is when it was planned.
fn plan(
    machine: &Machine,
    planner: &mut Planner<Curve, PLANNER_SEGMENTS>,
    planned_end: &mut Point,
    job: &Job,
    settings: &Settings,
) -> Option<RunState> {
    match Curve::for_job(job, *planned_end, settings) {
        Ok(curve) => {
            *planned_end = curve.end();
            info!("job planned to ({}, {}) steps", planned_end.x, planned_end.y);
            machine.set_fault(None);
            if planner.push(curve, job.feed, settings.method).is_err() {
                // is_full() was false just now and nothing else pushes.
                error!("planner refused a segment it had room for");
            }
            Some(match job.kind {
                JobKind::Draw => RunState::Run,
                JobKind::Jog => RunState::Jog,
            })
        }
        Err(e) => {
            warn!("job refused: {:?}", e);
            machine.set_fault(Some(MotionFault::Setup(e)));
            None
        }
    }
}

/// Waits for a control, or for a job while the planner has room to take it.
async fn wait_for_work(machine: &Machine, planner: &Planner<Curve, PLANNER_SEGMENTS>) {
    if planner.is_full() {
        machine.control_requested().await;
    } else {
        match select(machine.jobs.ready_to_receive(), machine.control_requested()).await {
            Either::First(()) | Either::Second(()) => {}
        }
    }
}

fn apply(machine: &Machine, planner: &mut Planner<Curve, PLANNER_SEGMENTS>, control: Control) {
    info!("control: {:?}", control);
    match control {
        Control::Hold => planner.hold(),
        Control::Resume => planner.resume(),
        Control::Abort => abort(machine, planner),
    }
}

/// Decelerates to a stop and drops everything planned and queued, telling the inputs that
/// positions planned so far are stale.
fn abort(machine: &Machine, planner: &mut Planner<Curve, PLANNER_SEGMENTS>) {
    planner.abort();
    while machine.jobs.try_receive().is_ok() {}
    machine.note_abort();
}
