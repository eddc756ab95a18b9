//! The board's processor, modelled for the simulator: how long the motion task's work and the
//! builds of drawings take on the STM32F407, and how much of the processor the step timer's
//! interrupt takes meanwhile. The figures are the instructions the cost harness counts on a
//! Cortex-M4F and the cycles they take on average (`cost/f407.txt`).
//!
//! With the model in place the motion task publishes a batch of steps only once the chip would
//! have computed it, so the pulses wait for it, and an underrun is counted, exactly where the
//! board would fall behind. The motion task runs at interrupt priority on the board, so its work
//! holds up no other task here either.
//!
//! A slice of a build runs in thread mode, which the board's one core shares between the host
//! link, the keypad, the LCD, the servo and homing tasks: while it is charged ([`SimSlices`]) the
//! simulator polls none of them ([`ThreadLevel`]), so a build delays a status report, a key or
//! the watchdog's food as it would on the board, while the pulses and the motion go on.

use core::cell::Cell;
use core::future::Future;
use std::collections::BTreeMap;
use std::string::String;

use embassy_time::{Duration, Instant, Timer};

use crate::geom::TICK_HZ;
use crate::machine::Machine;
use crate::motion::drawing::{Drawing, Slice};
use crate::motion::interp::Method;
use crate::motion::interp::{Shape, ShapeKind};
use crate::motion::planner::Emitted;
use crate::tasks::motion::WorkTime;
use crate::tasks::slices::BetweenSlices;

/// The measured cost of the motion path on the STM32F407 (see the file's header).
const F407_TABLE: &str = include_str!("../../cost/f407.txt");

/// Longest a batch may keep the motion task busy in the model: beyond it the pulse engine's
/// interrupt alone would take the whole processor.
const MAX_BATCH_SECONDS: f32 = 1.0;

/// The methods in a model's table, in the order of its figures.
const METHODS: [(&str, Method); 2] = [("classic", Method::Classic), ("diagonal", Method::Diagonal)];

/// A processor's speed and the cost of the motion path and of the builder on it. Figures per
/// kind of curve are by [`ShapeKind`] and method (classic, diagonal).
#[derive(Clone, Debug, PartialEq)]
pub struct CpuModel {
    pub clock_hz: f32,
    /// Instructions of the step timer's interrupt per pulse.
    pub pulse_instructions: f32,
    /// The cycles each of them takes on average, the interrupt's entry and return included.
    pub pulse_cycles_per_instruction: f32,
    /// Instructions of the motion task per step; for a function, besides its X steps'.
    pub step_instructions: [[f32; 2]; 5],
    /// Instructions of the motion task per X step of a function (where the planner evaluates
    /// it), besides `function_x_step_op`.
    pub function_x_step_instructions: [f32; 2],
    /// The same per operation of the function's expression.
    pub function_x_step_op_instructions: [f32; 2],
    /// The cycles each of the motion task's instructions takes on average.
    pub step_cycles_per_instruction: [[f32; 2]; 5],
    /// Instructions of the builder per step walked (a line is not walked: 0).
    pub build_step_instructions: [[f32; 2]; 5],
    /// Instructions of the builder per X step of a sine or a function, besides the step: the
    /// evaluation of the curve at a column; for a function, besides `build_function_op`.
    pub build_x_step_instructions: [[f32; 2]; 5],
    /// Instructions of the builder per X step of a function, per operation of its expression.
    pub build_function_op_instructions: [f32; 2],
    /// The cycles each of the builder's instructions takes on average (a line: 0).
    pub build_cycles_per_instruction: [[f32; 2]; 5],
}

impl CpuModel {
    /// The STM32F407 at 168 MHz, from `cost/f407.txt`.
    pub fn f407() -> Result<CpuModel, String> {
        CpuModel::parse(F407_TABLE)
    }

    /// A model from its table: `clock_hz`, `pulse N`, and for every kind and method `<kind>
    /// <method> N` (the motion task per step), `function <method> per_x_step N` and `function
    /// <method> per_x_step_op N`, and `build <kind> <method> N` (the builder per step walked)
    /// for every kind but the line, `build <kind> <method> per_x_step N` for the sine and the
    /// function, and `build function <method> per_x_step_op N`. Each of `pulse`, `<kind>
    /// <method>` and `build <kind> <method>` has its `... cycles_per_instruction N` too, for all
    /// of its figures; `#` starts a comment.
    pub fn parse(text: &str) -> Result<CpuModel, String> {
        let mut figures = BTreeMap::new();
        for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
            let words: std::vec::Vec<&str> = line.split_whitespace().collect();
            let Some((value, name)) = words.split_last() else { continue };
            let value = value.parse::<f32>().map_err(|_| std::format!("not a number: {line}"))?;
            let known = match name {
                ["clock_hz"] | ["pulse"] | ["pulse", "cycles_per_instruction"] => true,
                [kind, method]
                | ["build", kind, method]
                | [kind, method, "per_x_step" | "per_x_step_op" | "cycles_per_instruction"]
                | ["build", kind, method, "per_x_step" | "per_x_step_op" | "cycles_per_instruction"] => {
                    kind_of(kind).is_some() && method_of(method).is_some()
                }
                _ => false,
            };
            if !known {
                return Err(std::format!("cannot read: {line}"));
            }
            figures.insert(name.join(" "), value);
        }
        let get = |name: &str| figures.get(name).copied().ok_or_else(|| std::format!("no {name}"));
        let mut model = CpuModel {
            clock_hz: get("clock_hz")?,
            pulse_instructions: get("pulse")?,
            pulse_cycles_per_instruction: get("pulse cycles_per_instruction")?,
            step_instructions: [[0.0; 2]; 5],
            function_x_step_instructions: [0.0; 2],
            function_x_step_op_instructions: [0.0; 2],
            step_cycles_per_instruction: [[0.0; 2]; 5],
            build_step_instructions: [[0.0; 2]; 5],
            build_x_step_instructions: [[0.0; 2]; 5],
            build_function_op_instructions: [0.0; 2],
            build_cycles_per_instruction: [[0.0; 2]; 5],
        };
        for (m, (method, _)) in METHODS.iter().enumerate() {
            for (k, kind) in ShapeKind::ALL.iter().enumerate() {
                let name = kind.name();
                model.step_instructions[k][m] = get(&std::format!("{name} {method}"))?;
                model.step_cycles_per_instruction[k][m] = get(&std::format!("{name} {method} cycles_per_instruction"))?;
                if *kind != ShapeKind::Straight {
                    model.build_step_instructions[k][m] = get(&std::format!("build {name} {method}"))?;
                    model.build_cycles_per_instruction[k][m] =
                        get(&std::format!("build {name} {method} cycles_per_instruction"))?;
                }
                if matches!(kind, ShapeKind::Sine | ShapeKind::Function) {
                    model.build_x_step_instructions[k][m] = get(&std::format!("build {name} {method} per_x_step"))?;
                }
            }
            model.function_x_step_instructions[m] = get(&std::format!("function {method} per_x_step"))?;
            model.function_x_step_op_instructions[m] = get(&std::format!("function {method} per_x_step_op"))?;
            model.build_function_op_instructions[m] = get(&std::format!("build function {method} per_x_step_op"))?;
        }
        Ok(model)
    }

    fn seconds(&self, instructions: f32, cycles_per_instruction: f32) -> f32 {
        instructions * cycles_per_instruction / self.clock_hz
    }

    /// Seconds the motion task takes for `steps` steps of `kind` with `method`, `x_steps` of
    /// them along X; `expr_ops` is the size of a function's expression (a function is evaluated
    /// once per X step).
    pub fn steps_seconds(&self, kind: ShapeKind, method: Method, expr_ops: u8, steps: u32, x_steps: u32) -> f32 {
        let (k, m) = (kind_index(kind), method_index(method));
        let per_x_step = match kind {
            ShapeKind::Function => {
                self.function_x_step_instructions[m] + self.function_x_step_op_instructions[m] * f32::from(expr_ops)
            }
            _ => 0.0,
        };
        let instructions = self.step_instructions[k][m] * steps as f32 + per_x_step * x_steps as f32;
        self.seconds(instructions, self.step_cycles_per_instruction[k][m])
    }

    /// Seconds the step timer's interrupt takes per pulse.
    pub fn pulse_seconds(&self) -> f32 {
        self.seconds(self.pulse_instructions, self.pulse_cycles_per_instruction)
    }

    /// Seconds the builder takes for `slice`, walked with `method`.
    pub fn build_seconds(&self, slice: &Slice, method: Method) -> f32 {
        let (k, m) = (kind_index(slice.kind), method_index(method));
        let ops = if slice.kind == ShapeKind::Function { f32::from(slice.expr_ops) } else { 0.0 };
        let per_x_step = self.build_x_step_instructions[k][m] + self.build_function_op_instructions[m] * ops;
        let instructions = self.build_step_instructions[k][m] * slice.steps as f32 + per_x_step * slice.x_steps as f32;
        self.seconds(instructions, self.build_cycles_per_instruction[k][m])
    }
}

fn kind_of(name: &str) -> Option<ShapeKind> {
    ShapeKind::ALL.into_iter().find(|k| k.name() == name)
}

fn method_of(name: &str) -> Option<Method> {
    METHODS.iter().find(|(n, _)| *n == name).map(|(_, m)| *m)
}

fn kind_index(kind: ShapeKind) -> usize {
    ShapeKind::ALL.iter().position(|&k| k == kind).unwrap_or(0)
}

fn method_index(method: Method) -> usize {
    usize::from(method == Method::Diagonal)
}

/// The size of a function's expression (0 for the other curves).
fn expr_ops(drawing: &Drawing) -> u8 {
    match drawing.shape() {
        Shape::Function { expr, .. } => u8::try_from(expr.op_count()).unwrap_or(u8::MAX),
        _ => 0,
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
    /// The largest expression among the functions planned since the pulses last stopped.
    expr_ops: u8,
}

impl<'m> SimCpu<'m> {
    pub fn new(model: Option<CpuModel>, machine: &'m Machine) -> Self {
        SimCpu { model, machine, kinds: [false; 5], expr_ops: 0 }
    }
}

impl WorkTime for SimCpu<'_> {
    fn planned(&mut self, drawing: &Drawing) {
        let ops = expr_ops(drawing);
        self.expr_ops = if self.machine.pulses_idle() { ops } else { self.expr_ops.max(ops) };
    }

    fn took(&mut self, emitted: &Emitted) -> impl Future<Output = ()> {
        let seconds = match (&self.model, self.machine.drawing()) {
            (Some(model), Some(kind)) if emitted.steps > 0 => {
                if self.machine.pulses_idle() {
                    self.kinds = [false; 5];
                }
                self.kinds[kind_index(kind)] = true;
                let method = self.machine.settings().method;
                // A function moves X one way: its X steps are how far the batch moved along X.
                let (steps, x_steps) = (emitted.steps as u32, emitted.moved.x.unsigned_abs());
                let work = ShapeKind::ALL
                    .iter()
                    .zip(self.kinds)
                    .filter(|(_, taken)| *taken)
                    .map(|(&k, _)| model.steps_seconds(k, method, self.expr_ops, steps, x_steps))
                    .fold(0.0, f32::max);
                // Meanwhile the pulses go on at the batch's own rate, each taking the interrupt's
                // time from the motion task.
                let interval_s = emitted.ticks as f32 / TICK_HZ as f32 / emitted.steps as f32;
                let left_for_motion = 1.0 - model.pulse_seconds() / interval_s;
                if left_for_motion > 0.0 { (work / left_for_motion).min(MAX_BATCH_SECONDS) } else { MAX_BATCH_SECONDS }
            }
            _ => 0.0,
        };
        let us = (seconds * 1e6).ceil() as u64;
        async move {
            if us > 0 {
                Timer::after(Duration::from_micros(us)).await;
            }
        }
    }
}

/// The board's thread mode: until `busy_until_us` it is taken by work charged there, and the
/// simulator polls none of its tasks; see the module documentation.
#[derive(Debug, Default)]
pub struct ThreadLevel {
    busy_until_us: Cell<u64>,
}

impl ThreadLevel {
    /// Until when thread mode is taken (in the past: it is free).
    pub fn busy_until_us(&self) -> u64 {
        self.busy_until_us.get()
    }

    /// True while thread mode is taken.
    pub fn busy(&self) -> bool {
        Instant::now().as_micros() < self.busy_until_us.get()
    }

    /// Takes thread mode until `t_us`.
    fn hold_until(&self, t_us: u64) {
        self.busy_until_us.set(self.busy_until_us.get().max(t_us));
    }
}

/// The simulator's [`BetweenSlices`]: with a model, each slice of a build takes thread mode for
/// its time on the modelled processor; without one it takes no time, and the other tasks have
/// their turn.
pub struct SimSlices<'a> {
    model: Option<CpuModel>,
    machine: &'a Machine,
    thread: &'a ThreadLevel,
}

impl<'a> SimSlices<'a> {
    pub fn new(model: Option<CpuModel>, machine: &'a Machine, thread: &'a ThreadLevel) -> Self {
        SimSlices { model, machine, thread }
    }
}

impl BetweenSlices for SimSlices<'_> {
    fn after(&mut self, slice: &Slice) -> impl Future<Output = ()> {
        let seconds = self.model.as_ref().map_or(0.0, |m| m.build_seconds(slice, self.machine.settings().method));
        let us = (seconds * 1e6).ceil() as u64;
        // Taken from now, even should the future be dropped: the work is done.
        let until = Instant::now().as_micros() + us;
        self.thread.hold_until(until);
        async move {
            if us > 0 {
                Timer::at(Instant::from_micros(until)).await;
            } else {
                embassy_futures::yield_now().await;
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
        assert!(model.function_x_step_op_instructions.iter().all(|&v| v > 0.0));
        // Every kind but the line is walked by the builder.
        assert!(model.build_step_instructions[1..].iter().flatten().all(|&v| v > 0.0));
        // The Cortex-M4 takes at least a cycle an instruction, and from flash at most a few.
        let cpis = core::iter::once(model.pulse_cycles_per_instruction)
            .chain(model.step_cycles_per_instruction.iter().flatten().copied())
            .chain(model.build_cycles_per_instruction[1..].iter().flatten().copied());
        assert!(cpis.into_iter().all(|c| (1.0..3.0).contains(&c)));
        // A step's time is its instructions at their cycles each, at 168 MHz.
        let line = model.steps_seconds(ShapeKind::Straight, Method::Diagonal, 0, 1, 1);
        let cpi = model.step_cycles_per_instruction[0][1];
        assert!((line - model.step_instructions[0][1] * cpi / 168e6).abs() < 1e-12);
    }

    #[test]
    fn a_slice_of_a_build_takes_its_steps_x_steps_and_operations_time() {
        let model = CpuModel::f407().unwrap();
        let slice = |kind, expr_ops, steps, x_steps| Slice { kind, expr_ops, steps, x_steps, done: false };
        let d = Method::Diagonal;
        let seconds = |kind: ShapeKind, instructions: f32| {
            instructions * model.build_cycles_per_instruction[kind_index(kind)][1] / 168e6
        };
        let arc = model.build_seconds(&slice(ShapeKind::Arc, 0, 1000, 700), d);
        assert!(
            (arc - seconds(ShapeKind::Arc, 1000.0 * model.build_step_instructions[1][1])).abs() < 1e-9,
            "X steps cost an arc nothing"
        );
        // A function's X step evaluates its expression: each operation adds to it.
        let short = model.build_seconds(&slice(ShapeKind::Function, 3, 100, 100), d);
        let long = model.build_seconds(&slice(ShapeKind::Function, 30, 100, 100), d);
        let per_op = seconds(ShapeKind::Function, 100.0 * 27.0 * model.build_function_op_instructions[1]);
        assert!((long - short - per_op).abs() < 1e-9);
        // Steep: most steps walk without an evaluation.
        let steep = model.build_seconds(&slice(ShapeKind::Function, 3, 2000, 10), d);
        assert!(steep < 2000.0 / 100.0 * short, "a step without an evaluation is cheaper");
        // The motion task's steps of a function too.
        let f = ShapeKind::Function;
        assert!(model.steps_seconds(f, d, 30, 100, 100) > model.steps_seconds(f, d, 3, 100, 100));
    }

    #[test]
    fn a_bad_table_is_refused_with_the_line() {
        assert!(CpuModel::parse("clock_hz 1\n").unwrap_err().contains("no pulse"));
        assert!(CpuModel::parse("build line sideways 3\n").unwrap_err().contains("build line sideways 3"));
        assert!(CpuModel::parse("line sideways 3\n").unwrap_err().contains("line sideways 3"));
        assert!(CpuModel::parse("pulse fast\n").unwrap_err().contains("pulse fast"));
        assert!(CpuModel::parse("pulse 140 1.7\n").unwrap_err().contains("pulse 140 1.7"));
        // Every figure's cycles per instruction is there.
        let without = |name: &str| F407_TABLE.lines().filter(|l| !l.starts_with(name)).collect::<std::vec::Vec<_>>();
        let table = without("arc diagonal cycles_per_instruction").join("\n");
        assert!(CpuModel::parse(&table).unwrap_err().contains("no arc diagonal cycles_per_instruction"));
    }
}
