//! The pulse engine: what the step timer does at every one of its periods. It owns the
//! PULS/SIGN timing and is the only writer of the position counters, so the position is the
//! pulses emitted, always.
//!
//! The motion task fills the step queue ([`StepQueue`], single producer, single consumer, no lock)
//! with step commands, and marks where its motion comes to rest. The step timer counts one *period*
//! at a time; a period is as long as the interval before a step, and the hardware ends it with a
//! pulse of the pulse width on the axes that step (PWM outputs), so every pulse edge is placed by
//! the timer, not by software. The period after the current one is *preloaded*: the timer switches
//! to it by itself. At the start of each period (an update event) [`PulseEngine::on_period`] runs:
//! it counts the pulses of the period that just ended, drives SIGN for the pulse that ends the
//! period now starting (so SIGN settles for nearly a whole period before its edge, and never
//! changes under a pulse), and preloads the next period from the next command.
//!
//! * A command whose directions differ from the last ones gets a period of at least the pulse
//!   width plus the direction setup (`$0`, `$200`), and no period is shorter than one period of
//!   `$205`.
//! * An interval longer than the timer counts is split into pulse-less periods before its
//!   pulse.
//! * When the queue runs dry while the motion is not at rest ([`StepProducer::rest`]), the
//!   engine counts an *underrun* (the motion task fell behind) and waits in short pulse-less
//!   periods; the next pulse then comes a whole interval after the wait, never sooner than
//!   planned.
//! * When the queue runs dry at a rest, the engine stops the timer once the last pulse is out,
//!   and signals the motion task.
//!
//! At the start of each period the engine also samples the machine's inputs ([`crate::inputs`]):
//! the limit switches the step now starting runs towards, the drivers' alarms and the emergency
//! stop. Once one has tripped, or anything else has tripped the machine ([`Machine::trip`]), it
//! halts the timer before that period's pulse, so the pulses stop within one period, and starts
//! nothing until the alarm is cleared.
//!
//! Nothing here decides anything about motion. On the board [`PulseEngine::on_period`] runs in
//! the step timer's interrupt, the highest priority; in the simulator a model of the timer
//! calls it at the virtual times the hardware would.

use crate::geom::{Axis, StepCmd, TICK_HZ};
use crate::inputs::{ALWAYS_WATCHED, Debounce, InputLevels, InputSetup, LIMITS, limits_toward};
use crate::machine::Machine;
use crate::math;
use crate::settings::Settings;

pub use queue::{STEP_QUEUE_LEN, StepConsumer, StepProducer, StepQueue};

mod queue;

/// Length of a pulse-less period while the engine waits for the motion task, ticks.
pub const UNDERRUN_WAIT_TICKS: u32 = 20 * (TICK_HZ / 1_000_000);

/// Length of the pulse-less period after the last pulse, at whose start the timer stops.
const TAIL_TICKS: u32 = 10 * (TICK_HZ / 1_000_000);

/// The hardware the engine drives and watches: a timer that counts one period at a time and ends
/// each with a pulse on the axes chosen for it, the two SIGN outputs, and the machine's input
/// pins.
pub trait StepTimer {
    /// Longest period the timer counts, ticks.
    const MAX_PERIOD_TICKS: u32;

    /// Drives the SIGN output of `axis` high or low.
    fn set_sign(&mut self, axis: Axis, high: bool);

    /// Loads the period after the current one: `ticks` long, ending with a pulse on the axes of
    /// `axes` (bit 0 X, bit 1 Y; none: no pulse).
    fn preload(&mut self, ticks: u32, axes: u8);

    /// Starts counting with pulses `width_ticks` wide: the preloaded period begins at once, as
    /// at an update event, so [`PulseEngine::on_period`] must run now.
    fn start(&mut self, width_ticks: u32);

    /// Stops counting: no period follows the current one.
    fn stop(&mut self);

    /// Stops counting at once, PULS low, whatever the period was to end with.
    fn halt(&mut self);

    /// The levels of the machine's input pins, read at once.
    fn input_levels(&mut self) -> InputLevels;
}

/// Pulse timing, taken from the settings whenever the timer starts.
#[derive(Clone, Copy, Debug)]
struct Timing {
    width_ticks: u32,
    /// Shortest period: the pulse width plus the direction setup, where SIGN changes.
    dir_change_ticks: u32,
    /// Shortest period between two pulses (`$205`).
    min_period_ticks: u32,
    invert_mask: u8,
}

impl Timing {
    fn from_settings(s: &Settings) -> Timing {
        let ticks_per_us = (TICK_HZ / 1_000_000) as f32;
        let width_ticks = math::ceil(s.pulse_width_us * ticks_per_us) as u32;
        Timing {
            width_ticks,
            dir_change_ticks: width_ticks + math::ceil(s.dir_setup_us * ticks_per_us) as u32,
            min_period_ticks: math::ceil(TICK_HZ as f32 / s.max_pulse_rate_hz) as u32,
            invert_mask: s.dir_invert_mask,
        }
    }
}

/// SIGN levels of both axes as bits (bit 0 X, bit 1 Y), and which of them are known.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Signs {
    high: u8,
    known: u8,
}

impl Signs {
    /// Of the axes in `moving`, those whose level is not `high` (or not known yet).
    #[inline(always)]
    fn changes(self, moving: u8, high: u8) -> u8 {
        moving & (!self.known | (self.high ^ high))
    }

    /// The levels once the axes in `moving` are set to `high`.
    #[inline(always)]
    fn set(&mut self, moving: u8, high: u8) {
        self.high = (self.high & !moving) | high;
        self.known |= moving;
    }
}

/// The axes `cmd` steps (bits, bit 0 X, bit 1 Y), and the SIGN levels it needs on them with
/// the direction invert mask `invert` (`$3`).
#[inline(always)]
fn step_bits(cmd: StepCmd, invert: u8) -> (u8, u8) {
    let s = cmd.step;
    let moving = u8::from(s.x != 0) | (u8::from(s.y != 0) << 1);
    let forward = u8::from(s.x > 0) | (u8::from(s.y > 0) << 1);
    (moving, (forward ^ invert) & moving)
}

/// One period of the timer.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Period {
    /// `ticks` long, ending with the pulse of this step.
    Step { cmd: StepCmd, ticks: u32 },
    /// `ticks` long, no pulse: waiting through a long interval, or for the motion task.
    Wait { ticks: u32 },
    /// The timer stops when this period starts.
    Tail,
}

impl Period {
    /// Ticks, and the axes pulsed at the end (bit 0 X, bit 1 Y).
    #[inline(always)]
    fn timer_load(self) -> (u32, u8) {
        match self {
            Period::Step { cmd, ticks } => (ticks, step_bits(cmd, 0).0),
            Period::Wait { ticks } => (ticks, 0),
            Period::Tail => (TAIL_TICKS, 0),
        }
    }
}

/// See the module documentation. `T` is the step timer.
pub struct PulseEngine<'q, T: StepTimer> {
    timer: T,
    queue: StepConsumer<'q>,
    timing: Timing,
    running: bool,
    /// The period counting now and the one preloaded after it.
    active: Period,
    preloaded: Period,
    /// SIGN levels driven, and those in force once the preloaded period starts.
    sign: Signs,
    sign_preloaded: Signs,
    /// A step whose interval is longer than the timer counts, and the ticks still to wait.
    long_wait: Option<(StepCmd, u32)>,
    /// The queue ran dry before a rest: an underrun is under way (counted once).
    starving: bool,
    /// The inputs as the settings were when the timer started, and their debounce.
    inputs: InputSetup,
    debounce: Debounce,
    /// Ticks counted (wrapping), up to the end of the preloaded period: the debounce's clock.
    clock_ticks: u32,
    /// The limit switches the step of the active period runs towards.
    toward: u8,
}

impl<'q, T: StepTimer> PulseEngine<'q, T> {
    pub fn new(timer: T, queue: StepConsumer<'q>) -> Self {
        PulseEngine {
            timer,
            queue,
            timing: Timing::from_settings(&Settings::default()),
            running: false,
            active: Period::Tail,
            preloaded: Period::Tail,
            sign: Signs::default(),
            sign_preloaded: Signs::default(),
            long_wait: None,
            starving: false,
            inputs: InputSetup::from_settings(&Settings::default()),
            debounce: Debounce::default(),
            clock_ticks: 0,
            toward: 0,
        }
    }

    /// The timer, to read what it did (the simulator's model).
    pub fn timer(&self) -> &T {
        &self.timer
    }

    pub fn timer_mut(&mut self) -> &mut T {
        &mut self.timer
    }

    /// True while the timer runs.
    pub fn is_running(&self) -> bool {
        self.running
    }

    /// The motion task queued commands: starts the timer if it is stopped and a step is queued.
    pub fn kick(&mut self, machine: &Machine) {
        if self.running || machine.halted() {
            return;
        }
        if !self.queue.ready() {
            return;
        }
        let settings = machine.settings();
        self.timing = Timing::from_settings(&settings);
        self.inputs = InputSetup::from_settings(&settings);
        if machine.homing() {
            // The homing cycle's approaches end at their switch.
            self.inputs.watched |= LIMITS;
        }
        self.debounce.clear();
        self.sign_preloaded = self.sign;
        let first = self.next_period(machine);
        self.active = Period::Tail;
        self.preload(first);
        self.running = true;
        machine.set_pulsing(true);
        self.timer.start(self.timing.width_ticks);
    }

    /// A period starts (the timer's update event): counts the pulses of the period that ended,
    /// drives SIGN for this period's pulse, and preloads the next period. What it calls is
    /// `#[inline(always)]`: the image is built for size, and this is the one path where a call
    /// costs more than it saves (`cost/` counts it per pulse).
    pub fn on_period(&mut self, machine: &Machine) {
        if !self.running {
            return;
        }
        if let Period::Step { cmd, .. } = self.active {
            machine.emitted(cmd);
        }
        self.active = self.preloaded;
        // The axes this period's pulse steps, and those it steps forward.
        let mut directions = (0, 0);
        if let Period::Step { cmd, .. } = self.active {
            directions = step_bits(cmd, 0);
            self.toward = limits_toward(directions.0, directions.1);
        }
        if self.tripped(machine) {
            self.timer.halt();
            self.stopped(machine);
            return;
        }
        match self.active {
            Period::Step { .. } => self.drive_signs(directions.0, directions.1),
            Period::Wait { .. } => {}
            Period::Tail => {
                // The last pulse is out. Go on from rest if more came in behind the rest.
                let next = self.next_period(machine);
                if next == Period::Tail {
                    self.timer.stop();
                    self.stopped(machine);
                    return;
                }
                self.preload(next);
                return;
            }
        }
        let next = self.next_period(machine);
        self.preload(next);
    }

    /// Samples the inputs the active period watches; true once the machine has tripped, by them
    /// or otherwise.
    #[inline(always)]
    fn tripped(&mut self, machine: &Machine) -> bool {
        let levels = self.timer.input_levels();
        let active = self.inputs.active(levels) & (self.toward | ALWAYS_WATCHED);
        if (active != 0 || self.debounce.holding())
            && let Some(trip) = self.debounce.sample(active, self.clock_ticks, self.inputs.debounce_ticks)
        {
            machine.trip(trip);
        }
        machine.halted()
    }

    /// The timer has stopped: the engine is ready for the next kick.
    fn stopped(&mut self, machine: &Machine) {
        self.running = false;
        self.active = Period::Tail;
        self.preloaded = Period::Tail;
        self.long_wait = None;
        self.starving = false;
        machine.set_pulsing(false);
        machine.pulses_stopped();
    }

    #[inline(always)]
    fn preload(&mut self, period: Period) {
        self.preloaded = period;
        let (ticks, axes) = period.timer_load();
        // The debounce's clock runs one period ahead: only its differences count.
        self.clock_ticks = self.clock_ticks.wrapping_add(ticks);
        self.timer.preload(ticks, axes);
    }

    /// Drives SIGN for the axes in `moving`, those in `forward` forward.
    #[inline(always)]
    fn drive_signs(&mut self, moving: u8, forward: u8) {
        let high = (forward ^ self.timing.invert_mask) & moving;
        let changes = self.sign.changes(moving, high);
        if changes != 0 {
            for axis in Axis::ALL {
                let bit = 1 << axis.index();
                if changes & bit != 0 {
                    self.timer.set_sign(axis, high & bit != 0);
                }
            }
            self.sign.set(moving, high);
        }
    }

    /// What follows the preloaded period.
    #[inline(always)]
    fn next_period(&mut self, machine: &Machine) -> Period {
        if let Some((cmd, left)) = self.long_wait {
            return self.step_period(cmd, left);
        }
        match self.queue.pop() {
            Some(cmd) => {
                self.starving = false;
                let ticks = self.step_ticks(cmd);
                self.step_period(cmd, ticks)
            }
            None if self.queue.at_rest() => Period::Tail,
            None => {
                if !self.starving {
                    self.starving = true;
                    machine.count_underrun();
                }
                Period::Wait { ticks: UNDERRUN_WAIT_TICKS }
            }
        }
    }

    /// The period before `cmd`'s pulse: its interval, at least one period of the max pulse
    /// rate, and where a direction changes, at least the pulse width plus the direction setup.
    #[inline(always)]
    fn step_ticks(&mut self, cmd: StepCmd) -> u32 {
        let mut ticks = cmd.interval_ticks.max(self.timing.min_period_ticks);
        let (moving, high) = step_bits(cmd, self.timing.invert_mask);
        if self.sign_preloaded.changes(moving, high) != 0 {
            ticks = ticks.max(self.timing.dir_change_ticks);
            self.sign_preloaded.set(moving, high);
        }
        ticks
    }

    /// `ticks` before `cmd`'s pulse: pulse-less periods first where the timer cannot count so
    /// far.
    #[inline(always)]
    fn step_period(&mut self, cmd: StepCmd, ticks: u32) -> Period {
        if ticks > T::MAX_PERIOD_TICKS {
            let wait = T::MAX_PERIOD_TICKS / 2;
            self.long_wait = Some((cmd, ticks - wait));
            return Period::Wait { ticks: wait };
        }
        self.long_wait = None;
        Period::Step { cmd, ticks }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::geom::{Point, Step};
    use std::vec::Vec;

    /// What a mock timer saw: every period in the order the hardware counted them, with the
    /// SIGN levels in force while it counted.
    #[derive(Default)]
    struct MockTimer {
        preload: (u32, u8),
        running: bool,
        started: bool,
        sign: [bool; 2],
        /// (ticks, axes pulsed at the end, SIGN levels).
        periods: Vec<(u32, u8, [bool; 2])>,
        /// The input levels read, and from which read on (counting from 1) they change to what.
        levels: InputLevels,
        then: Option<(usize, InputLevels)>,
        reads: usize,
        halts: usize,
    }

    impl StepTimer for MockTimer {
        const MAX_PERIOD_TICKS: u32 = 65_535;
        fn set_sign(&mut self, axis: Axis, high: bool) {
            self.sign[axis.index()] = high;
        }
        fn preload(&mut self, ticks: u32, axes: u8) {
            self.preload = (ticks, axes);
        }
        fn start(&mut self, _width_ticks: u32) {
            self.running = true;
            self.started = true;
        }
        fn stop(&mut self) {
            self.running = false;
        }
        fn halt(&mut self) {
            self.running = false;
            self.halts += 1;
        }
        fn input_levels(&mut self) -> InputLevels {
            self.reads += 1;
            match self.then {
                Some((from, levels)) if self.reads >= from => levels,
                _ => self.levels,
            }
        }
    }

    /// Runs the engine as the hardware would until it stops (or `max` periods): at each update
    /// event the preloaded period becomes active and the interrupt runs. `between` runs after
    /// each period, as the motion task could.
    fn run(engine: &mut PulseEngine<'_, MockTimer>, machine: &Machine, max: usize, mut between: impl FnMut(usize)) {
        engine.kick(machine);
        if !core::mem::take(&mut engine.timer_mut().started) {
            return;
        }
        for k in 0..max {
            let (ticks, axes) = engine.timer().preload;
            engine.on_period(machine);
            if !engine.timer().running {
                return;
            }
            let sign = engine.timer().sign;
            engine.timer_mut().periods.push((ticks, axes, sign));
            between(k);
        }
    }

    fn step(x: i8, y: i8, interval_ticks: u32) -> StepCmd {
        StepCmd { step: Step::new(x, y), interval_ticks }
    }

    /// Publishes `cmds`, then a rest if `rest`.
    fn queue(p: &mut StepProducer<'_>, cmds: &[StepCmd], rest: bool) {
        let slots = p.free_slots();
        slots[..cmds.len()].copy_from_slice(cmds);
        p.publish(cmds.len());
        if rest {
            p.rest();
        }
    }

    #[test]
    fn steps_become_periods_ending_in_their_pulses_and_the_timer_stops_after_the_rest() {
        let machine = Machine::new(Settings::default()); // 5 µs pulses, 10 µs direction setup
        let mut q = StepQueue::new();
        let (mut p, c) = q.split();
        queue(&mut p, &[step(1, 0, 100), step(1, 1, 60), step(0, 1, 60)], true);
        machine.set_queued(3, 220);
        let mut engine = PulseEngine::new(MockTimer::default(), c);
        run(&mut engine, &machine, 100, |_| {});
        let periods = &engine.timer().periods;
        assert_eq!(periods.iter().map(|&(t, a, _)| (t, a)).collect::<Vec<_>>()[..3], [(100, 1), (60, 3), (60, 2)]);
        // SIGN high (forward) on each moving axis for its pulse.
        assert_eq!(periods[1].2, [true, true]);
        assert!(!engine.is_running());
        assert_eq!(machine.position(), Point::new(2, 2));
        assert!(machine.pulses_idle());
        assert_eq!(machine.underruns(), 0);
        assert_eq!(machine.queued_ticks(), 0);
    }

    /// The ticks of the periods an engine with `settings` makes of `cmds`.
    fn period_ticks(settings: Settings, cmds: &[StepCmd]) -> Vec<u32> {
        let machine = Machine::new(settings);
        let mut q = StepQueue::new();
        let (mut p, c) = q.split();
        queue(&mut p, cmds, true);
        let mut engine = PulseEngine::new(MockTimer::default(), c);
        run(&mut engine, &machine, 100, |_| {});
        engine.timer().periods.iter().map(|p| p.0).collect()
    }

    #[test]
    fn a_direction_change_gets_the_pulse_width_plus_the_direction_setup() {
        // 5 µs pulses and 10 µs direction setup; at up to 100 kHz a reversal 10 µs after the
        // last pulse is stretched to 15 µs, the steps after it keep their 10 µs.
        let fast = Settings { max_pulse_rate_hz: 100_000.0, ..Settings::default() };
        let cmds = [step(1, 0, 50), step(-1, 0, 10), step(-1, 0, 10), step(-1, 1, 10)];
        assert_eq!(period_ticks(fast, &cmds)[..4], [50, 15, 10, 15]);
        // At the default 20 kHz the 50 µs floor of `$205` covers the setup.
        assert_eq!(period_ticks(Settings::default(), &cmds)[..4], [50, 50, 50, 50]);
        // SIGN changes at the start of the period that ends with the reversed pulse.
        let machine = Machine::new(fast);
        let mut q = StepQueue::new();
        let (mut p, c) = q.split();
        queue(&mut p, &cmds, true);
        let mut engine = PulseEngine::new(MockTimer::default(), c);
        run(&mut engine, &machine, 100, |_| {});
        let signs: Vec<[bool; 2]> = engine.timer().periods.iter().map(|p| p.2).collect();
        assert_eq!(signs[..4], [[true, false], [false, false], [false, false], [false, true]]);
    }

    #[test]
    fn an_interval_longer_than_the_timer_counts_waits_in_pulseless_periods() {
        let machine = Machine::new(Settings::default());
        let mut q = StepQueue::new();
        let (mut p, c) = q.split();
        queue(&mut p, &[step(0, -1, 600_000), step(0, -1, 100)], true);
        let mut engine = PulseEngine::new(MockTimer::default(), c);
        run(&mut engine, &machine, 100, |_| {});
        let periods = &engine.timer().periods;
        let until_first: u32 = periods.iter().take_while(|p| p.1 == 0).map(|p| p.0).sum::<u32>();
        let first = periods.iter().position(|p| p.1 != 0).unwrap();
        assert_eq!(until_first + periods[first].0, 600_000);
        assert!(periods.iter().all(|p| p.0 <= 65_535));
        assert_eq!(periods[first + 1], (100, 2, [false, false]));
        assert_eq!(machine.position(), Point::new(0, -2));
    }

    #[test]
    fn a_queue_run_dry_before_the_rest_is_one_underrun_and_never_a_burst() {
        let machine = Machine::new(Settings::default());
        let mut q = StepQueue::new();
        let (mut p, c) = q.split();
        queue(&mut p, &[step(1, 0, 100); 3], false);
        let mut engine = PulseEngine::new(MockTimer::default(), c);
        // The motion task catches up only after the 10th period, then finishes.
        run(&mut engine, &machine, 1_000, |k| {
            if k == 10 {
                queue(&mut p, &[step(1, 0, 100); 2], true);
            }
        });
        let periods = &engine.timer().periods;
        assert_eq!(machine.underruns(), 1);
        assert_eq!(machine.position(), Point::new(5, 0));
        // Every pulse comes at least its interval after the one before.
        let mut since = 0;
        let mut gaps = Vec::new();
        for &(t, a, _) in periods.iter() {
            since += t;
            if a != 0 {
                gaps.push(since);
                since = 0;
            }
        }
        assert!(gaps.iter().all(|&g| g >= 100), "{gaps:?}");
        assert!(periods.iter().any(|p| p.1 == 0 && p.0 == UNDERRUN_WAIT_TICKS));
    }

    #[test]
    fn a_limit_switch_ahead_halts_the_timer_before_the_next_pulse_and_nothing_starts_until_unlocked() {
        use crate::inputs::{LIMIT_X_MAX, LIMIT_X_MIN, LIMITS, Trip};
        // Hard limits, no debounce; normally open switches read low when pressed.
        let settings = Settings { hard_limits: true, input_debounce_ms: 0, ..Settings::default() };
        let machine = Machine::new(settings);
        let mut q = StepQueue::new();
        let (mut p, c) = q.split();
        queue(&mut p, &[step(1, 0, 100); 10], true);
        // The X min switch, behind the pen, is pressed from the start and never stops it; the X
        // max switch closes at the fifth period.
        let timer = MockTimer {
            levels: LIMITS & !LIMIT_X_MIN,
            then: Some((5, LIMITS & !LIMIT_X_MIN & !LIMIT_X_MAX)),
            ..MockTimer::default()
        };
        let mut engine = PulseEngine::new(timer, c);
        run(&mut engine, &machine, 100, |_| {});
        assert_eq!(engine.timer().halts, 1);
        assert!(machine.halted());
        assert_eq!(machine.position(), Point::new(4, 0), "the pulses of the periods before");
        assert_eq!(machine.take_trip(), Some(Trip::Limit { axis: Axis::X, max: true }));
        engine.kick(&machine);
        assert!(!engine.is_running(), "halted: no kick starts the timer");
        machine.unlock();
        engine.kick(&machine);
        assert!(engine.is_running(), "unlocked, the queued steps go on");
    }

    #[test]
    fn steps_queued_behind_a_rest_before_the_timer_stops_go_on_from_rest() {
        let machine = Machine::new(Settings::default());
        let mut q = StepQueue::new();
        let (mut p, c) = q.split();
        queue(&mut p, &[step(1, 0, 100)], true);
        let mut engine = PulseEngine::new(MockTimer::default(), c);
        let mut more = Some(step(0, 1, 2_000));
        run(&mut engine, &machine, 100, |_| {
            if let Some(cmd) = more.take() {
                queue(&mut p, &[cmd], true);
            }
        });
        assert_eq!(machine.position(), Point::new(1, 1));
        assert_eq!(machine.underruns(), 0);
        assert!(!engine.is_running());
        // A kick with nothing queued does not start the timer.
        let mut q = StepQueue::new();
        let (mut p, c) = q.split();
        p.rest();
        let mut engine = PulseEngine::new(MockTimer::default(), c);
        engine.kick(&machine);
        assert!(!engine.is_running());
    }
}
