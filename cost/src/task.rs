//! The motion task's cost per step: the firmware's own `tasks::motion::run`, polled as its
//! executor would poll it, with a stand-in clock and a stand-in pulse side that takes the
//! queued steps at their intervals, as the step timer does.
//!
//! Only the polls are counted: what the motion task does per wake-up (controls, jobs, the fill
//! loop with the planner and the queue, counters, the timer it waits on). The executor's and
//! the board's time driver's own work per wake-up is not in it (it is per wake-up, and a
//! wake-up moves up to half the step queue).

use core::cell::Cell;
use core::pin::pin;
use core::task::{Context, Poll, RawWaker, RawWakerVTable, Waker};

use critical_section::Mutex;
use servoplot::motion::interp::Curve;
use servoplot::motion::job::Job;

/// Step ticks a microsecond of the clock.
const TICKS_PER_US: u64 = servoplot::geom::TICKS_PER_US as u64;
use servoplot::machine::Machine;
use servoplot::motion::planner::{Limits, PLANNER_SEGMENTS, Planner};
use servoplot::motion::pulse::StepQueue;
use servoplot::settings::Settings;
use servoplot::status::RunState;

use crate::{cost_mark, report_steps};

/// The stand-in clock: time passes only when the harness says so.
struct Clock {
    now: Mutex<Cell<u64>>,
    wake_at: Mutex<Cell<u64>>,
}

impl embassy_time_driver::Driver for Clock {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.now.borrow(cs).get())
    }

    fn schedule_wake(&self, at: u64, _waker: &Waker) {
        critical_section::with(|cs| {
            let w = self.wake_at.borrow(cs);
            w.set(w.get().min(at));
        });
    }
}

embassy_time_driver::time_driver_impl!(static CLOCK: Clock = Clock {
    now: Mutex::new(Cell::new(0)),
    wake_at: Mutex::new(Cell::new(u64::MAX)),
});

fn noop_waker() -> Waker {
    const VTABLE: RawWakerVTable =
        RawWakerVTable::new(|_| RawWaker::new(core::ptr::null(), &VTABLE), |_| {}, |_| {}, |_| {});
    // SAFETY: the vtable's functions do nothing and never touch the data pointer.
    unsafe { Waker::from_raw(RawWaker::new(core::ptr::null(), &VTABLE)) }
}

/// The planner the motion task runs with: built once and kept, since every case ends at rest
/// with the planner idle.
fn planner() -> &'static mut Planner<Curve, PLANNER_SEGMENTS> {
    static mut PLANNER: Option<Planner<Curve, PLANNER_SEGMENTS>> = None;
    // SAFETY: the harness measures one case at a time on one core, and each case's motion task
    // is dropped before the next case borrows the planner again.
    let slot = unsafe { &mut *core::ptr::addr_of_mut!(PLANNER) };
    slot.get_or_insert_with(|| Planner::new(Limits::default()))
}

/// Most polls one job may take before the harness gives up.
const MAX_POLLS: usize = 100_000;

/// Runs `job` through the motion task from rest to rest; reports each poll's instructions with
/// the steps it queued. Returns the steps emitted.
pub fn measure(case: &str, method: &str, job: Job, settings: &Settings) -> u64 {
    let machine = Machine::new(*settings);
    let Some(handles) = machine.handles() else { panic!("handles") };
    // No servo task here: the drivers hold their axes from the start.
    handles.servo.set_servos_ready(true);
    handles.servo.set_pen_settled(machine.pen_order());
    let mut queue = StepQueue::new();
    let (producer, mut consumer) = queue.split();
    let mut motion = pin!(servoplot::tasks::motion::run(
        handles.motion,
        planner(),
        producer,
        || {},
        servoplot::tasks::motion::RealTime
    ));
    let Some(from) = machine.plan_end() else { panic!("plan end") };
    if machine.try_submit(job, from).is_err() {
        panic!("job queue");
    }
    let waker = noop_waker();
    let mut cx = Context::from_waker(&waker);
    // When the pulse side emits its next pulse (step ticks), and the step it holds; when it
    // emitted the last one (the clock counts whole microseconds, the pulses step ticks).
    let mut next_pulse_at: Option<(u64, servoplot::geom::StepCmd)> = None;
    let mut last_pulse_ticks = 0u64;
    let mut emitted = 0u64;
    let mut moved = false;
    for _ in 0..MAX_POLLS {
        let queued_before = emitted + u64::from(queue_len(&machine));
        cost_mark();
        let poll = poll_once(motion.as_mut(), &mut cx);
        cost_mark();
        let queued_now = emitted + u64::from(queue_len(&machine));
        report_steps("task", case, method, queued_now - queued_before);
        if let Poll::Ready(never) = poll {
            match never {}
        }
        moved |= queued_now > 0;
        // The motion task waits: let time pass to its wake-up, the pulse side emitting what is
        // due by then (or everything, when it waits for the pulses themselves).
        let wake_at = critical_section::with(|cs| CLOCK.wake_at.borrow(cs).replace(u64::MAX));
        loop {
            if next_pulse_at.is_none() {
                match consumer.pop() {
                    Some(cmd) => {
                        let t = last_pulse_ticks.max(clock_now() * TICKS_PER_US);
                        next_pulse_at = Some((t + u64::from(cmd.interval_ticks), cmd));
                    }
                    None => break,
                }
            }
            let Some((at_ticks, cmd)) = next_pulse_at else { break };
            let at = at_ticks.div_ceil(TICKS_PER_US);
            if at > wake_at {
                break;
            }
            set_clock(at);
            last_pulse_ticks = at_ticks;
            handles.pulse.emitted(cmd);
            emitted += 1;
            next_pulse_at = None;
        }
        if next_pulse_at.is_none() && machine.pulses_idle() {
            handles.pulse.pulses_stopped();
            machine.deliver_pulse_news();
        }
        if wake_at != u64::MAX {
            set_clock(clock_now().max(wake_at));
        }
        if moved && machine.run_state() == RunState::Idle && machine.pulses_idle() {
            return emitted;
        }
    }
    panic!("the motion task did not come to rest");
}

/// One poll of the motion task, as its executor would make it.
#[inline(never)]
fn poll_once<F: core::future::Future>(f: core::pin::Pin<&mut F>, cx: &mut Context<'_>) -> Poll<F::Output> {
    f.poll(cx)
}

fn clock_now() -> u64 {
    critical_section::with(|cs| CLOCK.now.borrow(cs).get())
}

fn set_clock(t: u64) {
    critical_section::with(|cs| CLOCK.now.borrow(cs).set(t));
}

/// Steps queued and not yet emitted.
fn queue_len(machine: &Machine) -> u32 {
    machine.queued_steps()
}
