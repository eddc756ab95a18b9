//! Inputs the fuzz targets (`fuzz/`) found faults with, each kept as a test of what a user sees:
//! a clear error, and nothing changed: no motion planned, no position lost.

use servoplot::host::GrblError;
use servoplot::host::gcode::GcodeState;
use servoplot::settings::Settings;
use servoplot::status::RunState;

/// Runs `lines` at rest; each must be accepted.
fn parser_after(lines: &[&str], settings: &Settings) -> GcodeState {
    let mut gcode = GcodeState::new();
    for line in lines {
        if let Err(e) = gcode.execute(line, settings, RunState::Idle) {
            panic!("{line:?} refused: {e:?}");
        }
    }
    gcode
}

/// `line` is refused with GRBL error `code` and leaves the parser as it was.
fn refused(gcode: &mut GcodeState, line: &str, settings: &Settings, code: u8) {
    let before = *gcode;
    let got = gcode.execute(line, settings, RunState::Idle).map(|commands| commands.count());
    assert_eq!(got.map_err(GrblError::code), Err(code), "{line:?}");
    assert_eq!(*gcode, before, "{line:?} changed the parser's state");
}

#[test]
fn a_function_span_beyond_the_step_range_is_outside_the_travel() {
    // From a pen right of the origin, x0 to x1 spans more steps than an i32 holds: the sum of
    // the pen's step and the span overflowed.
    let settings = Settings::default();
    let mut gcode = parser_after(&["G0 X10"], &settings);
    let huge = "9".repeat(27);
    for line in [format!("$F X0 U{huge} Y=sqrt(x)"), format!("$F X-5 U{huge} Y=1")] {
        refused(&mut gcode, &line, &settings, 15);
    }
}
