//! Whether the board keeps up: the simulator charges the firmware's work the time it takes on
//! the STM32F407 (instructions counted on a Cortex-M4F, `cost/f407.txt`), so the pulses wait
//! for the motion task wherever the real chip would fall behind.

use servoplot::sim::cpu::CpuModel;
use servoplot::sim::serial::SimSerial;
use servoplot::sim::{self, SimConfig, SimReport};

/// One drawing of every kind the machine draws, from the host link, at the axes' max rate: the
/// pulses as fast as the default settings allow.
const EVERY_CURVE: [&str; 9] = [
    "G1 X40 Y15 F6000",
    "G2 X20 Y0 I10 J0 F6000",
    "$O R12 S30 W250 F6000",
    "$E A30 B15 F6000",
    "$S A10 W0.3 L60 F6000",
    "$F X-30 U30 F6000 Y=20*exp(-x^2/200)",
    "$F X-30 U30 F6000 Y=x^3/400",
    "$F X-30 U30 F6000 Y=sin(x)*x/10",
    "G0 X-60 Y-40",
];

fn run_on(input: &str, cpu: CpuModel, status_at_us: Option<u64>) -> SimReport {
    let mut serial = SimSerial::with_input(input.as_bytes());
    if let Some(t) = status_at_us {
        serial = serial.with_byte_at(t, b'?');
    }
    sim::run(SimConfig { serial, cpu: Some(cpu), ..SimConfig::default() })
}

#[test]
fn every_curve_keeps_up_at_the_default_settings_on_the_stm32f407() {
    let f407 = CpuModel::f407().expect("the F407 table reads");
    for method in [0, 1] {
        for line in EVERY_CURVE {
            let report = run_on(&format!("$202={method}\n{line}\n"), f407.clone(), None);
            assert!(!report.timed_out);
            assert!(report.answers().lines().filter(|l| *l == "ok").count() == 2, "{line}: {}", report.answers());
            assert_eq!(report.underruns, 0, "method {method}: {line} made the pulses wait");
            assert_eq!(*report.path().last().unwrap(), report.position);
        }
    }
}

#[test]
fn a_chip_too_slow_counts_the_waits_reports_them_and_loses_no_step() {
    // The F407's figures on a processor ten times slower, at a pulse rate it cannot feed.
    let f407 = CpuModel::f407().expect("the F407 table reads");
    let slow = CpuModel { clock_hz: f407.clock_hz / 10.0, ..f407 };
    let setup = "$110=30000\n$111=30000\n$120=5000\n$121=5000\n$205=50000\n";
    let drawing = "$F X-30 U30 F30000 Y=20*exp(-x^2/200)\n";
    let fast = run_on(&format!("{setup}{drawing}"), f407.clone(), None);
    // A status report once the drawing is done.
    let behind = run_on(&format!("{setup}{drawing}"), slow, Some(10_000_000));
    assert!(behind.underruns > 0, "a processor ten times slower kept up");
    // The host is told: the status report carries the count.
    let status = behind.answers().lines().find(|l| l.starts_with('<')).map(str::to_owned).unwrap_or_default();
    assert!(status.contains(&format!("|Un:{}", behind.underruns)), "{status}");
    // Waiting costs time, never a step or a pulse sooner than planned.
    assert_eq!(behind.position, fast.position);
    assert_eq!(behind.path(), fast.path());
    assert!(behind.last_pulse_us() > fast.last_pulse_us());
    let min_interval_us = 1_000_000 / 50_000;
    let steps = behind.trace.steps(0);
    assert!(steps.windows(2).all(|w| w[1].0 - w[0].0 >= min_interval_us));
}
