//! Driving the simulated board's two host links at once: bytes pasted at a time, a run that must
//! come to rest, and the answers to lines picked out of what a link wrote.

use servoplot::sim::{self, SimConfig, SimReport, serial::SimSerial};

/// Bytes written at `t_us`, all at once, without waiting for answers.
pub fn paste(link: SimSerial, t_us: u64, text: &[u8]) -> SimSerial {
    text.iter().fold(link, |l, &b| l.with_byte_at(t_us, b))
}

/// Runs the board with `uart` and `usb` as its two host links, until it comes to rest.
pub fn run(uart: SimSerial, usb: SimSerial) -> SimReport {
    let report = sim::run(SimConfig { serial: uart, usb, ..SimConfig::default() });
    assert!(!report.timed_out, "the machine came to rest: {} / {}", report.answers(), report.usb_answers());
    report
}

/// The answers to lines (`ok`, `error:N`), in order, without pushed messages and reports.
pub fn line_answers(text: &str) -> Vec<&str> {
    text.lines().filter(|l| *l == "ok" || l.starts_with("error:")).collect()
}
