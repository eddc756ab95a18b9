//! The watchdog on the simulated plotter: whatever the firmware does in good order (drawing fast
//! or at a crawl, holding, homing, standing still), the servo task feeds the watchdog well within
//! its timeout, so the board is never reset under a healthy machine.

use servoplot::machine_io::watchdog::WATCHDOG_TIMEOUT_MS;
use servoplot::sim::inputs::{InputScript, Switches};
use servoplot::sim::{self, SimConfig, serial::SimSerial};

#[test]
fn a_healthy_machine_always_feeds_the_watchdog() {
    // One step per 0.6 s at F1, a hold of 2 s mid-circle, homing with its pauses, then rest.
    let lines = "$22=1\nG1 X0.05 F1\n$O R10 S0 F3000\nG4 P0\n$H\n";
    let mut serial = SimSerial::with_input(lines.as_bytes());
    for (t, b) in [(3_200_000, b'!'), (5_200_000, b'~')] {
        serial = serial.with_byte_at(t, b);
    }
    let config = SimConfig {
        serial,
        switches: Some(Switches { beyond_travel_mm: 1.0 }),
        events: InputScript::parse("").unwrap(),
        ..SimConfig::default()
    };
    let report = sim::run(config);
    assert!(!report.timed_out);
    assert!(report.answers().ends_with("ok\r\nok\r\nok\r\nok\r\nok\r\n"), "{}", report.answers());
    assert!(
        report.watchdog_unfed_us <= 20_000,
        "unfed for {} µs (timeout {} ms)",
        report.watchdog_unfed_us,
        WATCHDOG_TIMEOUT_MS
    );
}
