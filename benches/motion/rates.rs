//! The highest max pulse rate (`$205`) at which the STM32F407 keeps up with each kind of curve:
//! the simulator runs each drawing with the board's processor modelled (`--cpu f407`, from the
//! instructions counted on a Cortex-M4F), at rates from slow to fast, and keeps the last rate
//! at which the pulses never had to wait for the motion task (0 step-queue underruns).

use servoplot::motion::interp::Method;
use servoplot::settings::Settings;
use servoplot::sim::cpu::CpuModel;
use servoplot::sim::serial::SimSerial;
use servoplot::sim::{self, SimConfig};
use servoplot::store::Record;

/// Rates tried, slow to fast; a curve's figure is the last one it keeps up with.
const RATES_HZ: [f32; 13] = [10e3, 20e3, 30e3, 40e3, 50e3, 60e3, 80e3, 100e3, 120e3, 140e3, 160e3, 180e3, 200e3];

/// One drawing of each kind, at the axes' max rate, large and gentle enough that its own
/// curvature lets the pen reach the rates tried (the three functions are the cost budget's,
/// stretched along X).
const DRAWINGS: [&str; 8] = [
    "G1 X150 Y60 F60000",
    "$O R90 F60000",
    "$O R90 S30 W250 F60000",
    "$E A90 B60 F60000",
    "$S A10 W0.05 L150 F60000",
    "$F X-90 U90 F60000 Y=20*exp(-x^2/20000)",
    "$F X-90 U90 F60000 Y=x^3/40000",
    "$F X-90 U90 F60000 Y=sin(x/20)*x/10",
];

/// Settings where the pulse rate is what binds: 200 steps/mm, 1,000 mm/s and 10,000 mm/s² on
/// both axes, the shortest pulse and direction setup the drivers take.
fn settings(method: Method, rate_hz: f32) -> Settings {
    Settings {
        steps_per_mm: [200.0; 2],
        max_rate_mm_per_min: [60_000.0; 2],
        accel_mm_per_s2: [10_000.0; 2],
        pulse_width_us: 2.5,
        dir_setup_us: 5.0,
        max_pulse_rate_hz: rate_hz,
        method,
        ..Settings::default()
    }
}

/// The highest rate of [`RATES_HZ`] at which `line` draws with no underrun, if any, and the
/// fastest pulse rate the pen reached then (over 2 ms), Hz.
fn highest_rate(line: &str, method: Method, cpu: &CpuModel) -> Option<(f32, f32)> {
    let mut best = None;
    for rate in RATES_HZ {
        let report = sim::run(SimConfig {
            flash: sim::flash_keeping(Record { settings: settings(method, rate), ..Record::default() }),
            serial: SimSerial::with_input(format!("{line}\n").as_bytes()),
            cpu: Some(cpu.clone()),
            ..SimConfig::default()
        });
        if report.timed_out || !report.answers().contains("ok") {
            panic!("{line} did not draw at {rate} Hz: {}", report.answers());
        }
        if report.underruns > 0 {
            break;
        }
        best = Some((rate, fastest_rate_hz(&report)));
    }
    best
}

/// Window over which the fastest pulse rate is measured, µs.
const RATE_WINDOW_US: u64 = 2_000;

/// The most steps (pulses on one axis or both at once) in any window of [`RATE_WINDOW_US`], per
/// second.
fn fastest_rate_hz(report: &sim::SimReport) -> f32 {
    let times: Vec<u64> = report.trace.steps(0).iter().map(|&(t, _)| t).collect();
    let mut most = 0;
    let mut start = 0;
    for (end, &t) in times.iter().enumerate() {
        while t - times[start] >= RATE_WINDOW_US {
            start += 1;
        }
        most = most.max(end + 1 - start);
    }
    most as f32 * 1e6 / RATE_WINDOW_US as f32
}

/// Prints the table.
pub fn table() {
    let cpu = match CpuModel::f407() {
        Ok(cpu) => cpu,
        Err(e) => panic!("cost/f407.txt: {e}"),
    };
    println!("### What the STM32F407 sustains: the highest `$205` with no underrun\n");
    println!(
        "Each drawing at F60000 with 200 steps/mm, 1,000 mm/s and 10,000 mm/s² on both axes, so that \
         the pulse rate binds; the simulator charges the firmware's work the time it takes on the F407 \
         (`--cpu f407`, {:.0} instructions and {:.0} cycles per pulse for the step timer's interrupt). \
         Rates tried: 10 to 200 kHz; \"≥ 200\" means every rate kept up. \"Fastest reached\": the most \
         steps in any 2 ms, at that `$205`.\n",
        cpu.pulse_instructions,
        cpu.pulse_instructions * cpu.pulse_cycles_per_instruction
    );
    println!(
        "| drawing | classic: highest `$205` (kHz) | fastest reached (kHz) | diagonal: highest `$205` (kHz) | fastest reached (kHz) |"
    );
    println!("|---|---:|---:|---:|---:|");
    for line in DRAWINGS {
        let cells = |method| match highest_rate(line, method, &cpu) {
            Some((r, reached)) if r >= RATES_HZ[RATES_HZ.len() - 1] => {
                format!("≥ {:.0} | {:.0}", r / 1e3, reached / 1e3)
            }
            Some((r, reached)) => format!("{:.0} | {:.0}", r / 1e3, reached / 1e3),
            None => format!("< {:.0} | ", RATES_HZ[0] / 1e3),
        };
        println!("| `{line}` | {} | {} |", cells(Method::Classic), cells(Method::Diagonal));
    }
    println!();
}
