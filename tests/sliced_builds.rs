//! Long builds, a slice at a time, on the simulated board with the STM32F407's processor modelled
//! (`--cpu f407`): a drawing whose walk takes seconds of the board's time is built while the
//! watchdog is fed, status reports are answered and keys are read, and a reset abandons it.

use servoplot::geom::Point;
use servoplot::machine_io::watchdog::WATCHDOG_TIMEOUT_MS;
use servoplot::motion::drawing::{self, Request};
use servoplot::motion::interp::Interpolator;
use servoplot::settings::Settings;
use servoplot::sim::cpu::CpuModel;
use servoplot::sim::keys::KeyScript;
use servoplot::sim::serial::SimSerial;
use servoplot::sim::{self, KeysStart, SimConfig, SimReport};

mod support;

/// 200 steps/mm, the pen to X −199 mm, then a function whose walk is 24 million steps: 158 waves
/// of ±190 mm, rising 475 mm per mm of X (a few seconds of the board's time to build).
const LONG_FUNCTION: &str = "$100=200\n$101=200\nG0 X-199\n$F X-199 U199 Y=sin((x+199)/0.4)*190\n";

/// A status query, sent while the long function is built.
const QUERY_AT_US: u64 = 2_000_000;

/// Longest a status query may wait for its answer while a drawing is built, µs. A slice of a
/// build takes at most about 1.7 ms of the board's time (`cost/`), and the host link's receiver
/// reads the query once the slice under way is over; 20 ms leaves room for a whole answer ahead
/// of it in the link's outbox.
const QUERY_ANSWERED_WITHIN_US: u64 = 20_000;

fn f407() -> CpuModel {
    CpuModel::f407().expect("the F407 table reads")
}

/// `program` streamed on the UART, with `timed` bytes sent at their times, on the modelled F407.
fn run(program: &str, timed: &[(u64, &[u8])]) -> SimReport {
    let mut serial = SimSerial::with_input(program.as_bytes());
    for &(t, bytes) in timed {
        for &b in bytes {
            serial = serial.with_byte_at(t, b);
        }
    }
    sim::run(SimConfig { serial, cpu: Some(f407()), ..SimConfig::default() })
}

/// When the firmware wrote each line equal to `line`, µs.
fn times_of(report: &SimReport, line: &str) -> Vec<u64> {
    report.serial_lines.iter().filter(|(_, l)| l == line).map(|(t, _)| *t).collect()
}

/// The settings `LONG_FUNCTION` sets.
fn settings_200() -> Settings {
    let mut s = Settings::default();
    s.set(100, 200.0).unwrap();
    s.set(101, 200.0).unwrap();
    s
}

#[test]
fn a_function_built_for_seconds_keeps_the_link_and_the_watchdog_alive_then_is_drawn() {
    // A reset long after the build, once the function is being drawn, ends the run.
    let reset_at_us = 30_000_000;
    let report = run(LONG_FUNCTION, &[(QUERY_AT_US, b"?"), (reset_at_us, b"\x18")]);
    assert!(!report.timed_out, "{}", report.answers());
    let oks = times_of(&report, "ok");
    assert_eq!(oks.len(), 4, "every line answered: {}", report.answers());
    // The function's line came once the G0's was answered; its `ok` once it was built.
    let build_us = oks[3] - oks[2];
    assert!((2_000_000..20_000_000).contains(&build_us), "built in {build_us} µs of the board's time");
    // The query, sent while the function was built, was answered at once.
    let status = report.serial_lines.iter().find(|(_, l)| l.starts_with('<')).expect("a status report");
    assert!(status.0 < oks[3], "answered while the build went on");
    assert!(
        status.0 - QUERY_AT_US <= QUERY_ANSWERED_WITHIN_US,
        "answered {} µs after it was asked",
        status.0 - QUERY_AT_US
    );
    // The servo task fed the watchdog throughout.
    assert!(
        report.watchdog_unfed_us < u64::from(WATCHDOG_TIMEOUT_MS) * 1000 / 40,
        "unfed for {} µs (timeout {} ms)",
        report.watchdog_unfed_us,
        WATCHDOG_TIMEOUT_MS
    );
    // After the move to X −199 mm, the pen drew the function's own path, step for step, until
    // the reset.
    let path = report.path();
    let start = Point::new(-199 * 200, 0);
    let at_start = path.iter().position(|p| *p == start).expect("the pen reached X -199 mm");
    let drawn = &path[at_start..];
    assert!(drawn.len() > 10_000, "{} steps drawn", drawn.len());
    let expr = servoplot::motion::expr::parse("sin((x+199)/0.4)*190").unwrap();
    let request = Request::Function { expr, x0_mm: -199.0, x1_mm: 199.0 };
    let drawing = drawing::build(&request, start, &settings_200()).unwrap().unwrap();
    let mut curve = drawing.into_curve();
    let mut at = start;
    for (i, p) in drawn.iter().enumerate().skip(1) {
        at = at.stepped(curve.next_step().unwrap().unwrap());
        assert_eq!(*p, at, "step {i} of the function");
    }
}

#[test]
fn a_reset_while_a_function_is_built_abandons_it_unanswered_and_plans_on_from_the_pen() {
    // The function once the pen is at X −199 mm (G4 waits for it): its build runs from then on
    // for seconds; the reset comes in the middle of it, then a line of its own.
    let program = LONG_FUNCTION.replace("G0 X-199\n", "G0 X-199\nG4 P0\n");
    let (reset_at_us, after_us) = (5_000_000, 6_000_000);
    let report = run(&program, &[(reset_at_us, b"\x18"), (after_us, b"G91 G0 X1\n")]);
    assert!(!report.timed_out, "{}", report.answers());
    let oks = times_of(&report, "ok");
    // Four lines answered before the reset (the G4's once the pen was there), none for the
    // function, then the new line's.
    assert_eq!(oks.len(), 5, "{}", report.answers());
    assert!(oks[3] < reset_at_us && oks[4] >= after_us, "{oks:?}");
    // The reset acts at once, mid-build: the banner.
    let banners = times_of(&report, "Grbl 1.1h ['$' for help]");
    assert_eq!(banners.len(), 2, "{}", report.answers());
    assert!(
        banners[1] - reset_at_us <= QUERY_ANSWERED_WITHIN_US,
        "banner {} µs after the reset",
        banners[1] - reset_at_us
    );
    // Nothing of the function was drawn: the pen went to X −199 mm, then 1 mm to the right.
    assert_eq!(report.position, Point::new(-198 * 200, 0));
    assert!(report.path().iter().all(|p| p.y == 0), "not one step of the function");
}

#[test]
fn a_keypad_drawing_is_built_in_slices_and_keys_are_read_meanwhile() {
    // The pen at X −199 mm from the host link; then on the keypad a sine of 159 waves of
    // ±190 mm: 12 million steps to walk, seconds of the board's time. `D`, a second into the
    // build, drops it.
    let sine = "D 5 1 9 0 # 2 * 5 # # 3 9 8 #";
    let keys = |script: &str| KeyScript::parse(script).unwrap();
    let config = |script: &str| SimConfig {
        serial: SimSerial::with_input(b"G0 X-199\n"),
        keys: keys(script),
        keys_start: KeysStart::AfterSerial,
        cpu: Some(f407()),
        ..SimConfig::default()
    };
    let dropped = sim::run(config(&format!("{sine} wait:1000 D wait:500")));
    assert!(!dropped.timed_out);
    // No preview was ever shown: `D` came while the drawing was being built, and dropped it.
    let previewed = |r: &SimReport| r.frames.iter().find(|(_, f)| support::text(f, 2, 6) == "# draw").map(|(t, _)| *t);
    assert_eq!(previewed(&dropped), None);
    // Still the form, as typed, after `D`; nothing drawn.
    let (_, last) = dropped.frames.last().unwrap();
    assert!(support::text(last, 0, 24).starts_with("SINE 4/4"), "{}", support::text(last, 0, 24));
    assert_eq!(dropped.position, Point::new(-199 * 100, 0), "nothing drawn");
    assert!(dropped.watchdog_unfed_us < u64::from(WATCHDOG_TIMEOUT_MS) * 1000 / 40);

    // Left alone, the same build ends in its preview, seconds after the last `#`.
    let shown = sim::run(config(&format!("{sine} wait:12000")));
    assert!(!shown.timed_out);
    let typed = shown.frames.iter().find(|(_, f)| support::text(f, 2, 14) == "Length mm: 398").map(|(t, _)| *t);
    let (typed, previewed) = (typed.expect("the length typed"), previewed(&shown).expect("the preview shown"));
    assert!(previewed - typed > 2_000_000, "built in {} µs", previewed - typed);
    let (_, last) = shown.frames.last().unwrap();
    assert!(support::text(last, 0, 13).starts_with("Sine A190"), "{}", support::text(last, 0, 13));
    assert_eq!(shown.position, Point::new(-199 * 100, 0), "nothing drawn before `#`");
    assert!(shown.watchdog_unfed_us < u64::from(WATCHDOG_TIMEOUT_MS) * 1000 / 40);
}
