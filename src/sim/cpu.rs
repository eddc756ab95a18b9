//! The board's processor, modelled for the simulator: how long the motion task's work takes on
//! the STM32F407, and how much of the processor the step timer's interrupt takes meanwhile. The
//! figures are the instructions the cost harness counts on a Cortex-M4F (`cost/f407.txt`). With
//! the model in place the motion task publishes a batch of steps only once the chip would have
//! computed it, so the pulses wait for it, and an underrun is counted, exactly where the board
//! would fall behind.

use std::string::String;

use embassy_time::{Duration, Timer};

use crate::geom::TICK_HZ;
use crate::interp::Method;
use crate::interp::ShapeKind;
use crate::machine::Machine;
use crate::planner::Emitted;
use crate::tasks::motion::WorkTime;

/// The measured cost of the motion path on the STM32F407 (see the file's header).
const F407_TABLE: &str = include_str!("../../cost/f407.txt");

/// Longest a batch may keep the motion task busy in the model: beyond it the pulse engine's
/// interrupt alone would take the whole processor.
const MAX_BATCH_SECONDS: f32 = 1.0;

/// A processor's speed and the cost of the motion path on it.
#[derive(Clone, Debug, PartialEq)]
pub struct CpuModel {
    pub clock_hz: f32,
    pub cycles_per_instruction: f32,
    /// Instructions of the step timer's interrupt per pulse.
    pub pulse_instructions: f32,
    /// Instructions of the motion task per step, by [`ShapeKind`] and method (classic, diagonal).
    pub step_instructions: [[f32; 2]; 5],
}

impl CpuModel {
    /// The STM32F407 at 168 MHz, from `cost/f407.txt`.
    pub fn f407() -> Result<CpuModel, String> {
        CpuModel::parse(F407_TABLE)
    }

    /// A model from its table: `clock_hz`, `cycles_per_instruction`, `pulse N`, and
    /// `<kind> <method> N` for every kind and method; `#` starts a comment.
    pub fn parse(text: &str) -> Result<CpuModel, String> {
        let (mut clock, mut cpi, mut pulse) = (None, None, None);
        let mut steps = [[None; 2]; 5];
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
            let words: std::vec::Vec<&str> = line.split_whitespace().collect();
            let number = |w: &str| w.parse::<f32>().map_err(|_| std::format!("not a number: {line}"));
            match words[..] {
                ["clock_hz", v] => clock = Some(number(v)?),
                ["cycles_per_instruction", v] => cpi = Some(number(v)?),
                ["pulse", v] => pulse = Some(number(v)?),
                [kind, method, v] => {
                    let k = ShapeKind::ALL
                        .iter()
                        .position(|k| kind_name(*k) == kind)
                        .ok_or_else(|| std::format!("unknown curve kind: {line}"))?;
                    let m = match method {
                        "classic" => 0,
                        "diagonal" => 1,
                        _ => return Err(std::format!("unknown method: {line}")),
                    };
                    steps[k][m] = Some(number(v)?);
                }
                _ => return Err(std::format!("cannot read: {line}")),
            }
        }
        let clock_hz = clock.ok_or("no clock_hz")?;
        let cycles_per_instruction = cpi.ok_or("no cycles_per_instruction")?;
        let pulse_instructions = pulse.ok_or("no pulse cost")?;
        let mut step_instructions = [[0.0; 2]; 5];
        for (k, row) in steps.iter().enumerate() {
            for (m, v) in row.iter().enumerate() {
                step_instructions[k][m] = v.ok_or_else(|| {
                    std::format!("no cost for {} {}", kind_name(ShapeKind::ALL[k]), ["classic", "diagonal"][m])
                })?;
            }
        }
        Ok(CpuModel { clock_hz, cycles_per_instruction, pulse_instructions, step_instructions })
    }

    fn seconds(&self, instructions: f32) -> f32 {
        instructions * self.cycles_per_instruction / self.clock_hz
    }

    /// Seconds the motion task takes per step of `kind` with `method`.
    pub fn step_seconds(&self, kind: ShapeKind, method: Method) -> f32 {
        let k = ShapeKind::ALL.iter().position(|&x| x == kind).unwrap_or(0);
        let m = usize::from(method == Method::Diagonal);
        self.seconds(self.step_instructions[k][m])
    }

    /// Seconds the step timer's interrupt takes per pulse.
    pub fn pulse_seconds(&self) -> f32 {
        self.seconds(self.pulse_instructions)
    }
}

/// The name of `kind` in a model's table.
pub fn kind_name(kind: ShapeKind) -> &'static str {
    match kind {
        ShapeKind::Straight => "line",
        ShapeKind::Arc => "arc",
        ShapeKind::Ellipse => "ellipse",
        ShapeKind::Sine => "sine",
        ShapeKind::Function => "function",
    }
}

/// The simulator's [`WorkTime`]: with a model, each batch of steps takes its time on the
/// modelled processor; without one, no time at all.
pub struct SimCpu<'m> {
    model: Option<CpuModel>,
    machine: &'m Machine,
    /// The kinds of job taken since the pulses last stopped: a batch is charged as the most
    /// costly of them (a batch may hold steps of several jobs).
    kinds: [bool; 5],
}

impl<'m> SimCpu<'m> {
    pub fn new(model: Option<CpuModel>, machine: &'m Machine) -> Self {
        SimCpu { model, machine, kinds: [false; 5] }
    }
}

impl WorkTime for SimCpu<'_> {
    fn took(&mut self, emitted: &Emitted) -> impl Future<Output = ()> {
        let seconds = match (&self.model, self.machine.drawing()) {
            (Some(model), Some(kind)) if emitted.steps > 0 => {
                if self.machine.pulses_idle() {
                    self.kinds = [false; 5];
                }
                if let Some(i) = ShapeKind::ALL.iter().position(|&k| k == kind) {
                    self.kinds[i] = true;
                }
                let method = self.machine.settings().method;
                let per_step = ShapeKind::ALL
                    .iter()
                    .zip(self.kinds)
                    .filter(|(_, taken)| *taken)
                    .map(|(&k, _)| model.step_seconds(k, method))
                    .fold(0.0, f32::max);
                // Meanwhile the pulses go on at the batch's own rate, each taking the interrupt's
                // time from the motion task.
                let interval_s = emitted.ticks as f32 / TICK_HZ as f32 / emitted.steps as f32;
                let left_for_motion = 1.0 - model.pulse_seconds() / interval_s;
                if left_for_motion > 0.0 {
                    (per_step * emitted.steps as f32 / left_for_motion).min(MAX_BATCH_SECONDS)
                } else {
                    MAX_BATCH_SECONDS
                }
            }
            _ => 0.0,
        };
        let ticks = (seconds * TICK_HZ as f32).ceil() as u64;
        async move {
            if ticks > 0 {
                Timer::after(Duration::from_ticks(ticks)).await;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_f407_table_reads_and_every_figure_is_there() {
        let model = CpuModel::f407().unwrap();
        assert_eq!(model.clock_hz, 168e6);
        assert!(model.pulse_instructions > 0.0);
        assert!(model.step_instructions.iter().flatten().all(|&v| v > 0.0));
        // 168 MHz at 1.3 cycles per instruction: a 100-instruction step takes 0.77 µs.
        let line = model.step_seconds(ShapeKind::Straight, Method::Diagonal);
        assert!((line - model.step_instructions[0][1] * 1.3 / 168e6).abs() < 1e-12);
    }

    #[test]
    fn a_bad_table_is_refused_with_the_line() {
        assert!(CpuModel::parse("clock_hz 1\n").unwrap_err().contains("cycles_per_instruction"));
        assert!(CpuModel::parse("line sideways 3\n").unwrap_err().contains("line sideways 3"));
        assert!(CpuModel::parse("pulse fast\n").unwrap_err().contains("pulse fast"));
    }
}
