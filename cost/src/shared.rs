//! The shared state's critical sections: what the tasks do to the state they share, each a few
//! times, so that `count.py --masked` (the `masked` plugin) finds the longest stretch with
//! interrupts masked among them. Nothing here is timed by marks: the plugin watches every
//! change of PRIMASK in the run.
//!
//! The operations are the tasks' own: a key press through the menu and the run screen following
//! the machine (keypad task), a redraw's reads (LCD task), a job submitted and taken (the inputs
//! and the motion task), settings read and changed (host link, keypad, motion task and pulse
//! engine), the status read (reports, LCD) and a control request taken. Where a task would
//! wait, the harness polls the future once, so that the operation that ends the wait finds a
//! waker to wake (one that does nothing: the executor's own work in a wake is not in it).

use core::pin::pin;
use core::task::{Context, Poll};

use servoplot::geom::Point;
use servoplot::machine::{Machine, PlanEnd};
use servoplot::motion::interp::Shape;
use servoplot::motion::job::{Control, Feed, Job};
use servoplot::panel::keypad::{Key, KeyEvent};
use servoplot::panel::screen::{self, Live};
use servoplot::settings::Settings;
use servoplot::tasks::panel::Panel;

/// Times each operation runs: enough to reach every branch the state can take (an empty and a
/// full job queue, a menu on several screens).
const ROUNDS: usize = 8;

/// The keys pressed, in turn: through the mode list into a form and back out.
const KEYS: [Key; 6] = [Key::Digit(8), Key::Digit(2), Key::Hash, Key::Digit(5), Key::Star, Key::C];

/// Runs every operation [`ROUNDS`] times.
pub fn run() {
    let settings = Settings::default();
    let machine = Machine::new(settings);
    let Some(handles) = machine.handles() else { panic!("handles") };
    let (motion, host) = (handles.motion, handles.host);
    let panel = Panel::new();
    // A line out and the line back: each starts where the other ends.
    let line = |from: Point, to: Point| match servoplot::motion::drawing::from_shape(
        Shape::Straight { to },
        from,
        &settings,
    ) {
        Ok(drawing) => Job::draw(drawing, Feed::MmPerMin(1_000.0)),
        Err(_) => panic!("drawing refused"),
    };
    let there = Point::new(400, 300);
    let (out, back) = (line(Point::ORIGIN, there), line(there, Point::ORIGIN));
    let next = |end: PlanEnd| if end.at() == Point::ORIGIN { out.clone() } else { back.clone() };
    for round in 0..ROUNDS {
        // Keypad task: a key through the menu, then the run screen follows the machine.
        for key in KEYS {
            for event in [KeyEvent::Press(key), KeyEvent::Release(key)] {
                let status = machine.status();
                let settings = machine.settings();
                core::hint::black_box(panel.update(|menu| menu.handle(event, &status, &settings)));
            }
            let status = machine.status();
            panel.update_if(|menu| menu.observe(&status, round as u32));
        }
        // LCD task: what a redraw reads.
        let status = machine.status();
        let settings = machine.settings();
        let live = Live {
            now_ms: round as u32,
            speed_mm_per_min: machine.speed_mm_per_min(),
            work_offset_mm: machine.work_offset_mm(),
            drawn: None,
            picture: None,
        };
        core::hint::black_box(panel.read(|menu| screen::view(menu, &status, &settings, &live)));
        // Inputs and motion task: jobs handed over until the queue is full, one more waiting for
        // room, then all taken; the motion task waits for the first.
        let Some(mut end) = machine.plan_end() else { panic!("plan end") };
        waits(motion.job_ready());
        while let Ok(ends) = machine.try_submit(next(end), end) {
            end = ends;
        }
        let mut waiting = pin!(machine.submit(next(end), end));
        let mut queued = poll(waiting.as_mut()).is_ready();
        while let Some(taken) = motion.next_job() {
            core::hint::black_box(taken);
            if !queued {
                queued = poll(waiting.as_mut()).is_ready();
            }
        }
        // Host link and keypad change a setting, the LCD and the serial task waiting for it; the
        // motion task and the pulse engine read them.
        waits(machine.changed());
        waits(host.settings_changed());
        let _ = machine.update_settings(|s| s.set(110, 2_000.0 + round as f32));
        core::hint::black_box(machine.settings());
        // Reports: the status, and a control requested and taken.
        core::hint::black_box(machine.status());
        machine.request(Control::Hold);
        core::hint::black_box(motion.take_control());
    }
}

/// Polls `f` once with a waker that does nothing, leaving that waker wherever `f` waits.
fn waits(f: impl Future) {
    let _ = poll(pin!(f));
}

fn poll<F: Future>(f: core::pin::Pin<&mut F>) -> Poll<F::Output> {
    f.poll(&mut Context::from_waker(core::task::Waker::noop()))
}
