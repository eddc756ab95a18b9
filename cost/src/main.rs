//! The cost harness: runs servoplot's motion code on QEMU's Cortex-M4F model (`mps2-an386`) and
//! marks where each measured piece of work starts and ends; the runner (`count.py`) counts the
//! instructions between marks with a QEMU plugin and prints the table.
#![no_std]
#![no_main]

mod build;
mod pulse_path;
mod shared;
mod task;

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use defmt_rtt as _;
use servoplot::geom::Point;
use servoplot::motion::interp::{Curve, Interpolator, Method, Shape};
use servoplot::motion::job::{Feed, Job};

use servoplot::motion::planner::{Limits, PLANNER_SEGMENTS, Planner};
use servoplot::settings::Settings;

/// Where the runner's plugin snapshots the instruction counter: called between measured pieces.
#[unsafe(no_mangle)]
#[inline(never)]
pub extern "C" fn cost_mark() {
    // A real instruction, so the function is never folded into another.
    cortex_m::asm::nop();
}

/// Writes one result line: the runner pairs it with the last two marks, and adds up lines of
/// the same measure, case and method.
pub fn report_steps(what: &str, case: &str, method: &str, steps: u64) {
    hprintln!("result {} {} {} {}", what, case, method, steps);
}

fn method_name(method: Method) -> &'static str {
    match method {
        Method::Classic => "classic",
        Method::Diagonal => "diagonal",
    }
}

fn report(what: &str, case: &str, method: Method, steps: u64) {
    report_steps(what, case, method_name(method), steps);
}

const FEED: Feed = Feed::MmPerMin(3_000.0);

/// Steps per `fill` call when an interpolator runs alone.
const INTERP_BATCH_STEPS: usize = 16;

/// Steps per `fill` call when the planner runs alone: half the step queue, as the motion task
/// takes them.
const PLANNER_BATCH_STEPS: usize = servoplot::motion::pulse::STEP_QUEUE_LEN / 2;

pub fn cases() -> [(&'static str, Shape); 10] {
    let f = |src: &str| match servoplot::motion::expr::parse(src) {
        Ok(e) => e,
        Err(_) => panic!("expression"),
    };
    [
        ("line0", Shape::Straight { to: Point::new(5_000, 0) }),
        ("line30", Shape::Straight { to: Point::new(4_330, 2_500) }),
        ("line45", Shape::Straight { to: Point::new(3_536, 3_536) }),
        (
            "circle",
            Shape::Arc {
                center: Point::new(-2_000, 0),
                to: Point::ORIGIN,
                rotation: servoplot::geom::Rotation::CounterClockwise,
            },
        ),
        (
            "arc",
            Shape::Arc {
                center: Point::new(-2_000, 0),
                to: Point::new(-3_000, -1_732),
                rotation: servoplot::geom::Rotation::Clockwise,
            },
        ),
        (
            "ellipse",
            Shape::Ellipse {
                center: Point::new(-3_000, 0),
                a_steps: 3_000,
                b_steps: 1_500,
                to: Point::ORIGIN,
                rotation: servoplot::geom::Rotation::CounterClockwise,
            },
        ),
        (
            "sine",
            Shape::Sine { amplitude_steps: 1_000.0, omega_rad_per_step: 0.003, phase_rad: 0.0, length_steps: 6_000 },
        ),
        ("gauss", Shape::Function { expr: f("20*exp(-x^2/200)"), x0_mm: -30.0, x1_mm: 30.0 }),
        ("cubic", Shape::Function { expr: f("x^3/400"), x0_mm: -30.0, x1_mm: 30.0 }),
        ("sinx", Shape::Function { expr: f("sin(x)*x/10"), x0_mm: -30.0, x1_mm: 30.0 }),
    ]
}

fn curve(shape: &Shape, settings: &Settings) -> Curve {
    match Curve::new(shape, Point::ORIGIN, settings) {
        Ok(c) => c,
        Err(_) => panic!("curve setup"),
    }
}

/// Steps a curve to its end in batches, as the planner takes them.
#[inline(never)]
fn interp_only(mut c: Curve) -> u64 {
    let mut buf = [servoplot::geom::Step::NONE; INTERP_BATCH_STEPS];
    let mut n = 0;
    loop {
        let filled = c.fill(&mut buf);
        n += filled.steps as u64;
        match filled.end {
            None => {}
            Some(Ok(())) => return n,
            Some(Err(_)) => panic!("curve failed"),
        }
    }
}

#[inline(never)]
fn with_planner(c: Curve, method: Method, limits: Limits) -> u64 {
    let mut p: Planner<Curve, PLANNER_SEGMENTS> = Planner::new(limits);
    if p.push(c, FEED, method).is_err() {
        panic!("push");
    }
    // In batches, as the motion task fills the step queue.
    let mut buf = [servoplot::geom::StepCmd::NONE; PLANNER_BATCH_STEPS];
    let mut n = 0;
    loop {
        let emitted = p.fill(&mut buf, u32::MAX);
        n += emitted.steps as u64;
        match emitted.end {
            None => {}
            Some(Ok(())) => return n,
            Some(Err(_)) => panic!("curve failed in the planner"),
        }
    }
}

/// The harness's command line (QEMU's `-semihosting-config arg=`): only cases whose name
/// contains it run; `*` runs them all.
fn filter(buf: &mut [u8; 64]) -> &str {
    let args = [buf.as_mut_ptr() as usize, buf.len()];
    // SAFETY: GET_CMDLINE writes at most `buf.len()` bytes, NUL-terminated, into `buf`.
    let failed = unsafe { cortex_m_semihosting::syscall(cortex_m_semihosting::nr::GET_CMDLINE, &args) } != 0;
    let len = if failed { 0 } else { buf.iter().position(|&b| b == 0).unwrap_or(buf.len()) };
    match core::str::from_utf8(&buf[..len]) {
        Ok("*") | Err(_) => "",
        Ok(text) => text,
    }
}

#[entry]
fn main() -> ! {
    let mut buf = [0u8; 64];
    let only = filter(&mut buf);
    cost_mark();
    cost_mark();
    for (name, shape) in cases() {
        if !name.contains(only) {
            continue;
        }
        for method in [Method::Classic, Method::Diagonal] {
            let settings = Settings { method, ..Settings::default() };
            let limits = Limits::from_settings(&settings);
            cost_mark();
            let c = curve(&shape, &settings);
            cost_mark();
            report("setup", name, method, 1);
            cost_mark();
            let n = interp_only(c);
            cost_mark();
            report("interp", name, method, n);
            let c = curve(&shape, &settings);
            cost_mark();
            let n = with_planner(c, method, limits);
            cost_mark();
            report("planner", name, method, n);
            let drawing = match servoplot::motion::drawing::from_shape(shape.clone(), Point::ORIGIN, &settings) {
                Ok(d) => d,
                Err(_) => panic!("drawing refused"),
            };
            let emitted = task::measure(name, method_name(method), Job::draw(drawing, FEED), &settings);
            if emitted != n {
                panic!("the motion task emitted another number of steps");
            }
        }
    }
    if "pulse".contains(only) || only.is_empty() {
        pulse_path_runs();
    }
    if "shared".contains(only) || only.is_empty() {
        shared::run();
    }
    build::runs(only);
    debug::exit(debug::EXIT_SUCCESS);
    halt()
}

/// Semihosting has ended the run; should it ever return, stop here.
fn halt() -> ! {
    loop {
        cortex_m::asm::wfi();
    }
}

/// Steps of the pulse path's two runs: the difference of their costs is the cost of the steps
/// between them.
const PULSE_RUN_STEPS: [usize; 2] = [50, 250];

/// The pulse path on a circle's steps (both axes, every direction), 100 µs apart, watching every
/// input.
fn pulse_path_runs() {
    let settings = Settings {
        method: Method::Diagonal,
        hard_limits: true,
        driver_alarm_input: true,
        estop_input: true,
        ..Settings::default()
    };
    let circle = cases()[3].1.clone();
    let mut c = curve(&circle, &settings);
    let mut buf = [servoplot::geom::Step::NONE; PULSE_RUN_STEPS[1]];
    let filled = c.fill(&mut buf);
    if filled.steps < PULSE_RUN_STEPS[1] {
        panic!("circle too short");
    }
    let cmds = buf.map(|step| servoplot::geom::StepCmd::new(step, PULSE_INTERVAL_TICKS));
    let machine = pulse_path::machine(settings);
    for n in PULSE_RUN_STEPS {
        pulse_path::measure(&cmds[..n], if n == PULSE_RUN_STEPS[0] { "short" } else { "long" }, machine);
    }
}

/// Interval between pulses in the pulse path's runs, 100 µs: long enough that no interrupt of
/// the model comes late.
const PULSE_INTERVAL_TICKS: u32 = 100 * servoplot::geom::TICKS_PER_US;

/// The device's interrupt vectors (cortex-m-rt's `device` feature, enabled through the
/// firmware's HAL, expects them): the model's timer 0 runs the pulse engine.
#[unsafe(link_section = ".vector_table.interrupts")]
#[unsafe(no_mangle)]
pub static __INTERRUPTS: [unsafe extern "C" fn(); 32] = {
    let mut table: [unsafe extern "C" fn(); 32] = [default_irq; 32];
    table[pulse_path::TIMER0_IRQ as usize] = pulse_path::timer0_interrupt;
    table
};

unsafe extern "C" fn default_irq() {
    hprintln!("unexpected interrupt");
    debug::exit(debug::EXIT_FAILURE);
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    halt()
}

#[defmt::panic_handler]
fn defmt_panic() -> ! {
    hprintln!("defmt panic");
    debug::exit(debug::EXIT_FAILURE);
    halt()
}
