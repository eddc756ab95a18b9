//! The keypad and the host link take turns at one plan: a host line starts where a keypad
//! drawing leaves the pen, whether it comes while the drawing runs or after it, and a host line
//! planned before a keypad job was handed over is refused (`error:9`), never drawn from where
//! the pen was.

use servoplot::geom::Point;
use servoplot::sim::cpu::CpuModel;
use servoplot::sim::keys::KeyScript;
use servoplot::sim::serial::SimSerial;
use servoplot::sim::{self, SimConfig, SimReport};

mod support;
use support::links::{line_answers, paste};

/// Mode 2 (line), dX 10 mm, dY 5 mm, drawn: the pen goes from the origin to (10, 5) mm. On the
/// simulated board the line is drawn from about 0.98 s to 1.27 s.
const KEYPAD_LINE: &str = "2 1 0 # 5 # #";

/// The keypad's line, and `host` pasted on the UART at `t_us`.
fn keypad_then_host(t_us: u64, host: &str, cpu: Option<CpuModel>) -> SimReport {
    let keys = KeyScript::parse(KEYPAD_LINE).unwrap();
    let serial = paste(SimSerial::default(), t_us, host.as_bytes());
    let report = sim::run(SimConfig { keys, serial, cpu, ..SimConfig::default() });
    assert!(!report.timed_out, "came to rest: {}", report.answers());
    report
}

#[test]
fn host_lines_start_where_the_keypad_drawing_ends_sent_while_it_runs_or_after() {
    // A relative move 5 mm along X, then an absolute one to (20, 0) mm: at 100 steps/mm, from
    // the keypad's end (1000, 500) to (1500, 500), then to (2000, 0).
    let host = "G91 G1 X5 F1000\nG90 G1 X20 Y0\n";
    for t_us in [1_000_000, 1_100_000, 1_200_000, 2_000_000] {
        let report = keypad_then_host(t_us, host, None);
        let answers = report.answers();
        assert_eq!(line_answers(&answers), ["ok", "ok"], "sent at {t_us} µs");
        let path = report.path();
        let keypad_end = path.iter().position(|&p| p == Point::new(1000, 500));
        let relative_end = path.iter().position(|&p| p == Point::new(1500, 500));
        let (Some(k), Some(r)) = (keypad_end, relative_end) else {
            panic!("sent at {t_us} µs: the keypad's end and the G91 move's end are on the path")
        };
        assert!(path[k..=r].iter().all(|p| p.y == 500), "sent at {t_us} µs: G91 X5 went along X from the keypad's end");
        assert!(path.iter().all(|p| p.x <= 2000 && p.y >= 0), "sent at {t_us} µs: never past where it was sent");
        assert_eq!(report.position, Point::new(2000, 0), "sent at {t_us} µs: G90 X20 Y0 reached");
    }
}

#[test]
fn a_host_line_planned_before_a_keypad_job_was_handed_over_is_refused_and_never_drawn() {
    // On the modelled F407, the function's walk takes seconds: the keypad hands its line over
    // while the host's function, planned from the origin, is still being built. At 200 steps/mm
    // the keypad's line ends at (2000, 1000); the function would swing ±190 mm from the origin.
    let host = "$100=200\n$101=200\n$F X0 U190 Y=sin(x/0.4)*190\nG91 G1 X5 F1000\n";
    let cpu = Some(CpuModel::f407().expect("the F407 table reads"));
    let report = keypad_then_host(0, host, cpu);
    let answers = report.answers();
    assert_eq!(line_answers(&answers), ["ok", "ok", "error:9", "ok"], "{answers}");
    let path = report.path();
    assert!(path.contains(&Point::new(2000, 1000)), "the keypad's line was drawn");
    assert!(path.iter().all(|p| p.y >= 0 && p.y <= 1000 && p.x >= 0), "nothing of the function was drawn");
    // The next line plans from where the keypad left the pen.
    assert_eq!(report.position, Point::new(3000, 1000));
}
