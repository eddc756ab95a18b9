//! The homing task: runs the homing cycle ([`crate::machine_io::homing`]) when `$H` or the keypad asks for
//! one. It hands each move to the motion task as a job, waits until the machine has stopped,
//! and checks what the move had to do: an approach stops at its switch, a pull-off leaves it
//! released. The cycle ends at rest with machine zero set, or in an alarm that says what failed.

use embassy_time::{Duration, Timer};

use crate::geom::{Axis, Point};
use crate::machine::{HomingWriter, MotionFault, PlanEnd};
use crate::machine_io::homing::{HOMING_ORDER, HomingFail, Phase, homed_steps, homing_move, towards_max};
use crate::machine_io::inputs::{InputSetup, Trip};
use crate::motion::job::Job;
use crate::status::RunState;
use crate::tasks::servo::SERVO_ENABLE_POLL_MS;

/// How often the task looks whether a homing move has ended.
pub const HOMING_POLL_MS: u64 = 5;

/// Runs a homing cycle at each request, forever.
pub async fn run(machine: HomingWriter<'_>) -> ! {
    loop {
        machine.homing_requested().await;
        // Whatever was queued before the request goes first.
        until_stopped(machine).await;
        if InputSetup::from_settings(&machine.settings()).stops_active(machine.input_levels()) != 0 {
            // A driver alarm or the e-stop would trip again at once: the alarm stays.
            warn!("homing refused: driver alarm or e-stop active");
        } else {
            // Homing is a way out of an alarm too: it starts from rest, unlocked.
            machine.unlock();
            match cycle(machine).await {
                Ok(()) => info!("homed at ({}, {}) steps", machine.position().x, machine.position().y),
                // A trip stopped the cycle and raised its own alarm.
                Err(None) => {}
                Err(Some(fail)) => {
                    warn!("homing failed: {:?}", fail);
                    machine.fail(MotionFault::Homing(fail));
                }
            }
        }
        machine.end_homing();
    }
}

/// The cycle may go on: no trip raised an alarm (`Err(None)`: it said why), and the plan ends
/// at `left`, where the cycle's last move left it: no abort came, nothing else was handed over.
fn still_homing(machine: HomingWriter<'_>, left: PlanEnd) -> Result<(), Option<HomingFail>> {
    if machine.run_state() == RunState::Alarm || machine.halted() {
        return Err(None);
    }
    if machine.plan_end() != Some(left) {
        return Err(Some(HomingFail::Aborted));
    }
    Ok(())
}

/// Waits until nothing is queued, planned or moving.
async fn until_stopped(machine: HomingWriter<'_>) {
    while !machine.stopped() {
        Timer::after(Duration::from_millis(HOMING_POLL_MS)).await;
    }
}

/// Every move of every axis, then machine zero; see [`crate::machine_io::homing`]. `Err(None)` when a trip
/// raised an alarm of its own.
async fn cycle(machine: HomingWriter<'_>) -> Result<(), Option<HomingFail>> {
    let settings = machine.settings();
    // A healthy cycle never aborts: any abort from here on, even between moves, is a reset or a
    // keypad D that stops it. Each move is planned from where the one before it left the plan.
    let mut plan = machine.plan_end().ok_or(HomingFail::Aborted)?;
    for axis in HOMING_ORDER {
        let switch = Trip::Limit { axis, max: towards_max(&settings, axis) };
        for phase in Phase::ALL {
            let step = homing_move(&settings, axis, phase);
            let from = plan.at();
            let to = match axis {
                Axis::X => Point::new(from.x + step.steps, from.y),
                Axis::Y => Point::new(from.x, from.y + step.steps),
            };
            let job = Job::homing_move(from, to, step.feed_mm_per_min, &settings).ok_or(HomingFail::Approach(axis))?;
            let ends = machine.submit(job, plan).await.map_err(|_| HomingFail::Aborted)?;
            until_stopped(machine).await;
            let found = machine.take_switch_found();
            // Stopped at its switch, the move left the plan where the pen stands.
            plan = if found.is_some() { ends.then(machine.position()) } else { ends };
            still_homing(machine, plan)?;
            if phase.approaches() && found != Some(switch) {
                return Err(Some(HomingFail::Approach(axis)));
            }
            // The switch settles, and the inputs are read again.
            let settle_ms = u64::from(settings.homing_debounce_ms) + SERVO_ENABLE_POLL_MS;
            Timer::after(Duration::from_millis(settle_ms)).await;
            still_homing(machine, plan)?;
            if !phase.approaches() && InputSetup::from_settings(&settings).pressed(machine.input_levels(), switch) {
                return Err(Some(HomingFail::PullOff(axis)));
            }
        }
    }
    machine.set_origin(Point::new(homed_steps(&settings, Axis::X), homed_steps(&settings, Axis::Y)));
    Ok(())
}
