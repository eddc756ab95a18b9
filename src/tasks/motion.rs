//! The motion task: turns jobs into curves, curves into timed step commands through the
//! planner, and feeds them to the pulse task through the bounded step queue.
//!
//! It only moves values: which curve a job is, and how fast each step goes, are decided by the
//! core (`interp::Curve::for_job`, `planner::Planner`). Back-pressure from the step queue paces it.

use embassy_futures::select::{Either3, select3};

use crate::geom::Point;
use crate::interp::Curve;
use crate::job::{Control, JobKind};
use crate::machine::{Machine, MotionFault};
use crate::planner::{Limits, PLANNER_SEGMENTS, Planner};
use crate::status::RunState;

/// Runs the motion forever.
pub async fn run(machine: &Machine) -> ! {
    let mut planner: Planner<Curve, PLANNER_SEGMENTS> = Planner::new(Limits::from_settings(&machine.settings()));
    // Where the pen will be once everything planned so far has been emitted.
    let mut planned_end: Point = machine.position();
    // What runs is reported as a jog while the last job taken was one (jogs start only at rest
    // or behind other jogs).
    let mut moving = RunState::Run;
    loop {
        if let Some(control) = machine.control.try_take() {
            apply(machine, &mut planner, control);
        }
        while !planner.is_full() {
            let Ok(job) = machine.jobs.try_receive() else { break };
            let settings = machine.settings();
            if planner.is_idle() {
                planner.set_limits(Limits::from_settings(&settings));
            }
            match Curve::for_job(&job, planned_end, &settings) {
                Ok(curve) => {
                    planned_end = curve.end();
                    moving = match job.kind {
                        JobKind::Draw => RunState::Run,
                        JobKind::Jog => RunState::Jog,
                    };
                    info!("job planned to ({}, {}) steps", planned_end.x, planned_end.y);
                    machine.set_fault(None);
                    if planner.push(curve, job.feed, settings.method).is_err() {
                        // is_full() was false just now; nothing else pushes.
                        error!("planner refused a segment it had room for");
                    }
                }
                Err(e) => {
                    warn!("job refused: {:?}", e);
                    machine.set_fault(Some(MotionFault::Setup(e)));
                }
            }
        }
        match planner.next_cmd() {
            Some(Ok(cmd)) => {
                machine.set_run_state(moving);
                machine.steps.send(cmd).await;
            }
            Some(Err(e)) => {
                // The curve left its domain part way: stop there and drop what was planned after
                // it, since it was planned from a point the pen never reached.
                warn!("curve ended early: {:?}", e);
                machine.set_fault(Some(MotionFault::Curve(e)));
                planner.abort();
                while machine.jobs.try_receive().is_ok() {}
            }
            None => {
                if planner.is_idle() {
                    // Everything planned is queued: wait until it is emitted, then rest there.
                    while !machine.pulses_idle() {
                        machine.pulses_done.wait().await;
                    }
                    planned_end = machine.position();
                    if machine.run_state() != RunState::Idle {
                        info!("at rest at ({}, {}) steps", planned_end.x, planned_end.y);
                    }
                    machine.set_run_state(RunState::Idle);
                } else {
                    machine.set_run_state(RunState::Hold);
                }
                match select3(machine.jobs.ready_to_receive(), machine.control.wait(), machine.pulses_done.wait()).await
                {
                    Either3::Second(control) => apply(machine, &mut planner, control),
                    Either3::First(()) | Either3::Third(()) => {}
                }
            }
        }
    }
}

fn apply<const N: usize>(machine: &Machine, planner: &mut Planner<Curve, N>, control: Control) {
    info!("control: {:?}", control);
    match control {
        Control::Hold => planner.hold(),
        Control::Resume => planner.resume(),
        Control::Abort => {
            planner.abort();
            while machine.jobs.try_receive().is_ok() {}
        }
    }
}
