//! A curve that stops part way in the motion task (a defect upstream: the builder refuses such
//! curves) puts the machine into an alarm, as GRBL does: the pen stops where the curve stopped,
//! what was queued behind it is dropped and refused, and motion stays locked until `$X`.
//!
//! The motion task runs here on its own, polled on the simulator's virtual clock, with a pulse
//! side that emits the queued steps at their intervals, as the step timer does.

use core::pin::pin;
use core::task::{Context, Poll, Waker};

use servoplot::geom::{Point, TICKS_PER_US};
use servoplot::machine::{Machine, MotionFault, Refused};
use servoplot::motion::drawing::{self, Request};
use servoplot::motion::interp::Curve;
use servoplot::motion::job::{Feed, Job};
use servoplot::motion::planner::{Limits, PLANNER_SEGMENTS, Planner};
use servoplot::motion::pulse::StepQueue;
use servoplot::settings::Settings;
use servoplot::sim::clock;
use servoplot::status::RunState;

/// A straight line to `x_mm` on the X axis, built (and checked) with `settings`.
fn line_to(x_mm: f32, from: Point, settings: &Settings) -> Job {
    let to = drawing::line_target([x_mm, 0.0], settings).unwrap();
    let drawing = drawing::build(&Request::Straight { to }, from, settings).unwrap().unwrap();
    Job::draw(drawing, Feed::MmPerMin(3_000.0))
}

#[test]
fn a_curve_stopped_by_the_travel_guard_raises_an_alarm_and_drops_the_queue() {
    clock::reset();
    // The jobs are built for a ±200 mm travel; the machine's is ±50 mm, as if its settings had
    // changed behind the builder's back.
    let loose = Settings::default();
    let tight = Settings { max_travel_mm: [50.0, 50.0], ..Settings::default() };
    let machine = Machine::new(tight);
    let handles = machine.handles().unwrap();
    // No servo task here: the drivers hold their axes from the start.
    handles.servo.set_servos_ready(true);
    handles.servo.set_pen_settled(machine.pen_order());
    let start = machine.plan_end().unwrap();
    let first = line_to(150.0, Point::ORIGIN, &loose);
    let end = first.drawing.end();
    let second = line_to(10.0, end, &loose);
    let planned = machine.try_submit(first, start).unwrap();
    let planned = machine.try_submit(second, planned).unwrap();

    let mut queue = StepQueue::new();
    let (producer, mut consumer) = queue.split();
    let mut planner: Box<Planner<Curve, PLANNER_SEGMENTS>> = Box::new(Planner::new(Limits::from_settings(&loose)));
    let mut motion = pin!(servoplot::tasks::motion::run(
        handles.motion,
        &mut planner,
        producer,
        || {},
        servoplot::tasks::motion::RealTime
    ));
    let mut cx = Context::from_waker(Waker::noop());
    let mut path = vec![Point::ORIGIN];
    for _ in 0..1_000_000 {
        if let Poll::Ready(never) = motion.as_mut().poll(&mut cx) {
            match never {}
        }
        // The pulse side emits everything queued, each step after its interval.
        while let Some(cmd) = consumer.pop() {
            clock::jump_to(clock::now_ticks() + u64::from(cmd.interval_ticks.div_ceil(TICKS_PER_US)));
            handles.pulse.emitted(cmd);
            path.push(machine.position());
        }
        if machine.pulses_idle() {
            handles.pulse.pulses_stopped();
            machine.deliver_pulse_news();
        }
        if machine.stopped() && machine.run_state() == RunState::Alarm {
            break;
        }
        if !clock::jump_to_next_deadline() && machine.stopped() {
            break;
        }
    }
    let edge = (50.0 * loose.steps_per_mm[0]) as i32;
    assert_eq!(machine.run_state(), RunState::Alarm);
    assert_eq!(machine.fault(), Some(MotionFault::Curve(servoplot::motion::interp::CurveError::Travel)));
    assert_eq!(machine.position(), Point::new(edge, 0), "stopped at the edge");
    assert!(path.iter().all(|p| p.x <= edge), "a step outside the travel");
    assert_eq!(machine.queued_jobs(), 0, "the job queued behind it was dropped");
    // A job planned before the alarm is refused: it would start where the pen never got.
    let late = line_to(-10.0, planned.at(), &loose);
    assert_eq!(machine.try_submit(late, planned), Err(Refused::Stale));
    // The plan ends where the pen stopped.
    assert_eq!(machine.plan_end().map(|e| e.at()), Some(Point::new(edge, 0)));
}
