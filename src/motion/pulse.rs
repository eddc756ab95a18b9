//! The pulse engine: what the step timer does at every one of its periods. It owns the
//! PULS/SIGN timing and is the only writer of the position counters, so the position is the
//! pulses emitted, always.
//!
//! The motion task fills the step queue ([`StepQueue`], single producer, single consumer, no lock)
//! with step commands, and marks where its motion comes to rest. The step timer counts one *period*
//! at a time; a period ends with a pulse of the pulse width (`$0`) on the axes that step (PWM
//! outputs), so every pulse edge is placed by the timer, not by software. The period after the
//! current one is *preloaded*: the timer switches to it by itself. At the start of each period (an
//! update event) [`PulseEngine::on_period`] runs: it drives the SIGN levels the period's pulse
//! needs, if they change, counts the pulses of the period that just ended, and preloads the next
//! period from the next command.
//!
//! * SIGN timing. A pulse's SIGN level is steady from at least the hold (`$29`) after the
//!   previous pulse's trailing edge to at least the set-up (`$200`) before its own leading edge.
//!   Where a command's direction differs from the levels in force, the engine puts a pulse-less
//!   period of the hold first (it starts at the previous pulse's trailing edge, an update event),
//!   then the period ending in the command's pulse, at whose start it writes SIGN: that period
//!   lasts at least the timer's interrupt latency ([`StepTimer::SIGN_LATENCY_TICKS`]) plus the
//!   set-up plus the pulse width. The two together last the command's interval, or that minimum.
//!   Where the direction stays, SIGN is not written at all.
//! * No period between two pulses is shorter than one period of `$205`, nor than twice the pulse
//!   width, so PULS is low at least as long as it is high at every rate.
//! * An interval longer than the timer counts is split into pulse-less periods before its
//!   pulse.
//! * When the queue runs dry while the motion is not at rest ([`StepProducer::rest`]), the
//!   engine counts an *underrun* (the motion task fell behind) and waits in short pulse-less
//!   periods; the next pulse then comes a whole interval after the wait, never sooner than
//!   planned.
//! * When the queue runs dry at a rest, the engine stops the timer once the last pulse is out,
//!   and signals the motion task.
//! * A *missed update*: should the interrupt come a whole period late (or later), the timer has
//!   meanwhile repeated the preloaded period, pulse included, as nothing preloaded another. The
//!   engine learns from the timer how many update events really happened
//!   ([`StepTimer::update_count`]), counts the repeated pulses into the position with the SIGN
//!   levels they went out with (so the position stays the pulses emitted), counts the fault
//!   ([`PulseWriter::count_missed_update`](crate::machine::PulseWriter::count_missed_update)), trips the machine ([`Trip::MissedUpdate`]) and lets the
//!   timer stop once the repeat under way is out, whole.
//!
//! At the start of each period the engine also samples the machine's inputs ([`crate::machine_io::inputs`]):
//! the limit switches the step now starting runs towards, the drivers' alarms and the emergency
//! stop. Once one has tripped, or anything else has tripped the machine ([`Machine::trip`](crate::machine::Machine::trip)), it
//! halts the timer before that period's pulse, so the pulses stop within one period, and starts
//! nothing until the alarm is cleared.
//!
//! Nothing here decides anything about motion. On the board [`PulseEngine::on_period`] runs in
//! the step timer's interrupt, the highest priority; in the simulator a model of the timer
//! calls it at the virtual times the hardware would.

use crate::geom::{Axis, StepCmd, TICK_HZ, TICKS_PER_US, us_to_ticks};
use crate::machine::PulseWriter;
use crate::machine_io::inputs::{ALWAYS_WATCHED, Debounce, InputLevels, InputSetup, LIMITS, Trip};
use crate::math;
use crate::settings::Settings;

pub use queue::{STEP_QUEUE_LEN, StepConsumer, StepProducer, StepQueue};

mod queue;
#[cfg(test)]
mod tests;

/// Length of a pulse-less period while the engine waits for the motion task, ticks.
pub const UNDERRUN_WAIT_TICKS: u32 = 20 * TICKS_PER_US;

/// Length of the pulse-less period after the last pulse, at whose start the timer stops.
const TAIL_TICKS: u32 = 10 * TICKS_PER_US;

/// The hardware the engine drives and watches: a timer that counts one period at a time and ends
/// each with a pulse on the axes chosen for it, the two SIGN outputs, and the machine's input
/// pins.
pub trait StepTimer {
    /// Longest period the timer counts, ticks.
    const MAX_PERIOD_TICKS: u32;

    /// Longest time from an update event until a SIGN level the engine drives in that event's
    /// interrupt is on the pin, ticks: the interrupt's worst latency (its entry, and the longest
    /// anything else keeps interrupts masked) and the code before the write. A period that
    /// changes SIGN lasts this much longer, so the set-up holds however late the write comes.
    const SIGN_LATENCY_TICKS: u32;

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

    /// The timer's update events so far, from any origin, wrapping at 2¹⁶: every period that
    /// ended, whether or not its interrupt ran. The engine reads it once per interrupt and
    /// compares it with its last reading, so only the difference matters: one when the
    /// interrupt comes in time, more when periods ended meanwhile (the timer repeats the
    /// preloaded period and its pulse until something preloads another). The update event of
    /// [`start`](Self::start) may count or not.
    ///
    /// A board with a counter clocked by the timer's update event reads it (the STM32F407
    /// clocks TIM4 from TIM1's update). A board with only a free-running clock counts in
    /// software: it keeps the time of the last update it counted and the lengths of the active
    /// and the preloaded period (from [`preload`](Self::preload)), and here counts every period
    /// that has ended by now, the active one first, then the preloaded one as often as it fits.
    fn update_count(&mut self) -> u16;

    /// Pends the interrupt that hands the engine's news on (`Machine::deliver_pulse_news`), below
    /// this one: the engine has left news in the machine (a stop, a trip, an underrun). The
    /// interrupt runs above every critical section, so it never delivers the news itself.
    fn pend_news(&mut self);
}

/// Pulse timing, taken from the settings whenever the timer starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timing {
    /// The pulse width (`$0`).
    pub width_ticks: u32,
    /// Shortest period ending in a pulse: one period of `$205`, and at least twice the width.
    pub min_period_ticks: u32,
    /// The pulse-less period after a pulse before SIGN changes (`$29`).
    pub hold_ticks: u32,
    /// Shortest period at whose start SIGN changes: the interrupt's latency, the set-up
    /// (`$200`) and the pulse width.
    pub sign_period_ticks: u32,
    /// `$3`: the axes whose SIGN is high for backward steps.
    pub invert_mask: u8,
}

impl Timing {
    /// The timing of `s` on a timer whose SIGN writes come up to `sign_latency_ticks` late.
    pub fn new(s: &Settings, sign_latency_ticks: u32) -> Timing {
        let width_ticks = us_to_ticks(s.pulse_width_us);
        let rate_period_ticks = math::ceil(TICK_HZ as f32 / s.max_pulse_rate_hz) as u32;
        Timing {
            width_ticks,
            min_period_ticks: rate_period_ticks.max(2 * width_ticks),
            hold_ticks: us_to_ticks(s.dir_hold_us),
            sign_period_ticks: sign_latency_ticks + us_to_ticks(s.dir_setup_us) + width_ticks,
            invert_mask: s.dir_invert_mask,
        }
    }
}

/// SIGN of both axes as bits (bit 0 X, bit 1 Y): set where high (or, as the engine plans ahead,
/// where forward), and which of them are known.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Signs {
    set: u8,
    known: u8,
}

impl Signs {
    /// Of the axes in `moving`, those whose bit is not as in `set` (or not known yet).
    #[inline(always)]
    fn changes(self, moving: u8, set: u8) -> u8 {
        moving & (!self.known | (self.set ^ set))
    }

    /// The bits once those of `axes` are as in `set` (within `axes`).
    #[inline(always)]
    fn put(&mut self, axes: u8, set: u8) {
        self.set = (self.set & !axes) | set;
        self.known |= axes;
    }

    /// The same signs with `mask`'s bits flipped: levels from directions, or back, with the
    /// direction invert mask.
    fn flipped(self, mask: u8) -> Signs {
        Signs { set: self.set ^ mask, known: self.known }
    }
}

/// What a step needs of the outputs and the inputs, as bits (bit 0 X, bit 1 Y).
#[derive(Clone, Copy, Debug)]
struct StepBits {
    /// The axes it steps.
    moving: u8,
    /// Those it steps forward.
    forward: u8,
    /// The limit switches it runs towards.
    toward: u8,
}

impl StepBits {
    /// From the command's direction bits: the motion task worked them out, the interrupt only
    /// shifts and masks them.
    #[inline(always)]
    fn of(cmd: StepCmd) -> StepBits {
        // Backward bits 0-1, forward bits 2-3: the limit switches ahead (`limits_toward`).
        let toward = cmd.directions();
        let forward = toward >> 2;
        StepBits { moving: (toward | forward) & 3, forward, toward }
    }
}

/// What a period is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Ends with the pulse of a queued step.
    Step,
    /// No pulse: SIGN's hold, a long interval, or waiting for the motion task.
    Wait,
    /// The timer stops when this period starts.
    Tail,
}

/// One period of the timer, as the engine keeps it while the timer has it: what its start and
/// its end need (the timer has its length). Three words, copied as such at every update.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
struct Period {
    /// The step whose pulse ends the period ([`Kind::Step`]), as queued: what the machine counts.
    cmd: StepCmd,
    kind: Kind,
    /// The axes whose SIGN changes as the period starts (bits, bit 0 X, bit 1 Y), to the levels
    /// `cmd` needs.
    sign_changes: u8,
    /// The limit switches its motion runs towards.
    toward: u8,
}

impl Period {
    const TAIL: Period = Period::pulseless(Kind::Tail, 0);

    const fn pulseless(kind: Kind, toward: u8) -> Period {
        let cmd = StepCmd::NONE;
        Period { kind, cmd, sign_changes: 0, toward }
    }

    /// A pulse-less period in a motion towards the switches of `toward`: they stay watched
    /// while it waits.
    const fn wait(toward: u8) -> Period {
        Period::pulseless(Kind::Wait, toward)
    }

    /// The period ending with `cmd`'s pulse, changing SIGN on the axes of `changes`.
    #[inline(always)]
    fn step(cmd: StepCmd, bits: StepBits, changes: u8) -> Period {
        Period { kind: Kind::Step, cmd, sign_changes: changes, toward: bits.toward }
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
    /// SIGN levels driven, and the directions they stand for once the preloaded period starts.
    sign: Signs,
    direction_preloaded: Signs,
    /// A step whose pulse comes after pulse-less periods (SIGN's hold, an interval longer than
    /// the timer counts), and the ticks from the end of those to its pulse.
    pending: Option<(StepCmd, u32)>,
    /// The queue ran dry before a rest: an underrun is under way (counted once).
    starving: bool,
    /// The inputs as the settings were when the timer started, and their debounce.
    inputs: InputSetup,
    debounce: Debounce,
    /// Ticks counted (wrapping), up to the end of the preloaded period: the debounce's clock.
    clock_ticks: u32,
    /// [`StepTimer::update_count`] when the engine last ran.
    updates: u16,
}

impl<'q, T: StepTimer> PulseEngine<'q, T> {
    pub fn new(timer: T, queue: StepConsumer<'q>) -> Self {
        PulseEngine {
            timer,
            queue,
            timing: Timing::new(&Settings::default(), T::SIGN_LATENCY_TICKS),
            running: false,
            active: Period::TAIL,
            preloaded: Period::TAIL,
            sign: Signs::default(),
            direction_preloaded: Signs::default(),
            pending: None,
            starving: false,
            inputs: InputSetup::from_settings(&Settings::default()),
            debounce: Debounce::default(),
            clock_ticks: 0,
            updates: 0,
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

    /// The timing in force since the timer last started.
    pub fn timing(&self) -> Timing {
        self.timing
    }

    /// The motion task queued commands: starts the timer if it is stopped and a step is queued.
    pub fn kick(&mut self, machine: PulseWriter<'_>) {
        if self.running || machine.halted() {
            return;
        }
        if !self.queue.ready() {
            return;
        }
        let settings = machine.settings();
        self.timing = Timing::new(&settings, T::SIGN_LATENCY_TICKS);
        self.inputs = InputSetup::from_settings(&settings);
        if machine.homing() {
            // The homing cycle's approaches end at their switch.
            self.inputs.watched |= LIMITS;
        }
        self.debounce.clear();
        self.direction_preloaded = self.sign.flipped(self.timing.invert_mask);
        self.active = Period::TAIL;
        self.preload_queued::<true>(machine);
        self.updates = self.timer.update_count();
        self.running = true;
        machine.set_pulsing(true);
        self.timer.start(self.timing.width_ticks);
    }

    /// A period starts (the timer's update event): drives SIGN for this period's pulse if it
    /// changes, counts the pulses of the period that ended, and preloads the next period. What
    /// it calls on the way of every pulse is `#[inline(always)]` (`cost/` counts it per pulse).
    pub fn on_period(&mut self, machine: PulseWriter<'_>) {
        if !self.running {
            return;
        }
        let count = self.timer.update_count();
        let updates = count.wrapping_sub(self.updates);
        self.updates = count;
        if updates > 1 {
            self.missed_updates(machine, updates - 1);
            return;
        }
        // SIGN first: the sooner after the update event, the less of the set-up it takes.
        let changes = self.preloaded.sign_changes;
        if changes != 0 {
            self.drive_signs(changes, StepBits::of(self.preloaded.cmd).forward ^ self.timing.invert_mask);
        }
        if self.active.kind == Kind::Step {
            machine.emitted(self.active.cmd);
        }
        self.active = self.preloaded;
        if self.tripped(machine) {
            self.timer.halt();
            self.stopped(machine);
            return;
        }
        if self.active.kind != Kind::Step {
            self.after_pause(machine);
            return;
        }
        // After a step the queue had one: no underrun is under way.
        self.preload_queued::<false>(machine);
    }

    /// A pulse-less period has started: a step may be pending behind it, and after the last
    /// pulse the timer stops, unless more came in behind the rest.
    #[cold]
    #[inline(never)]
    fn after_pause(&mut self, machine: PulseWriter<'_>) {
        if let Some((cmd, ticks)) = self.pending {
            self.pending = None;
            self.preload_pulse_after(cmd, ticks, StepBits::of(cmd));
            return;
        }
        if self.active.kind == Kind::Tail && !self.queue.ready() && self.queue.at_rest() {
            self.timer.stop();
            self.stopped(machine);
            return;
        }
        self.preload_queued::<true>(machine);
    }

    /// The interrupt came `extra` whole periods late: see the module documentation.
    #[cold]
    #[inline(never)]
    fn missed_updates(&mut self, machine: PulseWriter<'_>, extra: u16) {
        if self.active.kind == Kind::Step {
            machine.emitted(self.active.cmd);
        }
        // The preloaded period ran `extra` times and runs once more now. Its SIGN levels, if it
        // was to change them, were never driven: its pulses went out with those in force.
        let mut repeated = self.preloaded;
        repeated.sign_changes = 0;
        if repeated.kind == Kind::Step {
            let axes = StepBits::of(repeated.cmd).moving;
            let forward = self.sign.set ^ self.timing.invert_mask;
            let along = |axis: u8| -> i8 {
                match (axes & axis != 0, forward & axis != 0) {
                    (false, _) => 0,
                    (true, true) => 1,
                    (true, false) => -1,
                }
            };
            repeated.cmd = StepCmd::new(crate::geom::Step::new(along(1), along(2)), repeated.cmd.interval_ticks);
            for _ in 0..extra {
                machine.emitted(repeated.cmd);
            }
        }
        self.active = repeated;
        machine.count_missed_update();
        machine.pulse_trip(Trip::MissedUpdate);
        self.timer.pend_news();
        // Nothing more: the timer stops once the repeat under way is out.
        self.preload(TAIL_TICKS, 0, Period::TAIL);
    }

    /// Samples the inputs the active period watches; true once the machine has tripped, by them
    /// or otherwise.
    #[inline(always)]
    fn tripped(&mut self, machine: PulseWriter<'_>) -> bool {
        let levels = self.timer.input_levels();
        let toward = self.active.toward;
        let active = self.inputs.active(levels) & (toward | ALWAYS_WATCHED);
        if (active != 0 || self.debounce.holding())
            && let Some(trip) = self.debounce.sample(active, self.clock_ticks, self.inputs.debounce_ticks)
        {
            machine.pulse_trip(trip);
            self.timer.pend_news();
        }
        machine.halted()
    }

    /// The timer has stopped: the engine is ready for the next kick.
    fn stopped(&mut self, machine: PulseWriter<'_>) {
        self.running = false;
        self.active = Period::TAIL;
        self.preloaded = Period::TAIL;
        self.pending = None;
        self.starving = false;
        machine.set_pulsing(false);
        machine.pulses_stopped();
        self.timer.pend_news();
    }

    /// Preloads `period`, `ticks` long, pulsing the axes of `axes` at its end.
    #[inline(always)]
    fn preload(&mut self, ticks: u32, axes: u8, period: Period) {
        self.preloaded = period;
        // The debounce's clock runs one period ahead: only its differences count.
        self.clock_ticks = self.clock_ticks.wrapping_add(ticks);
        self.timer.preload(ticks, axes);
    }

    /// Drives SIGN high or low as `high` says on the axes of `changes`.
    #[inline(always)]
    fn drive_signs(&mut self, changes: u8, high: u8) {
        for axis in Axis::ALL {
            let bit = 1 << axis.index();
            if changes & bit != 0 {
                self.timer.set_sign(axis, high & bit != 0);
            }
        }
        self.sign.put(changes, high & changes);
    }

    /// Preloads what follows the preloaded period from the next queued command, none pending.
    /// Each way preloads its own period, so the common one (the next step, in the same
    /// directions) builds it in place. `MAY_STARVE`: an underrun may be under way (not after a
    /// step, which the queue had).
    #[inline(always)]
    fn preload_queued<const MAY_STARVE: bool>(&mut self, machine: PulseWriter<'_>) {
        let Some(cmd) = self.queue.pop() else {
            self.preload_dry(machine);
            return;
        };
        if MAY_STARVE {
            self.starving = false;
        }
        let ticks = cmd.interval_ticks.max(self.timing.min_period_ticks);
        let bits = StepBits::of(cmd);
        if self.direction_preloaded.changes(bits.moving, bits.forward) != 0 {
            // SIGN holds after the last pulse, then changes as the pulse's own period starts.
            let hold = self.timing.hold_ticks;
            self.pending = Some((cmd, ticks.saturating_sub(hold).max(self.timing.sign_period_ticks)));
            self.preload(hold, 0, Period::wait(bits.toward));
            return;
        }
        if ticks > T::MAX_PERIOD_TICKS {
            self.preload_pulse_after(cmd, ticks, bits);
            return;
        }
        self.preload(ticks, bits.moving, Period::step(cmd, bits, 0));
    }

    /// The queue has nothing: the rest, or an underrun.
    #[cold]
    #[inline(never)]
    fn preload_dry(&mut self, machine: PulseWriter<'_>) {
        if self.queue.at_rest() {
            self.preload(TAIL_TICKS, 0, Period::TAIL);
            return;
        }
        if !self.starving {
            self.starving = true;
            machine.count_underrun();
            self.timer.pend_news();
        }
        let toward = self.preloaded.toward;
        self.preload(UNDERRUN_WAIT_TICKS, 0, Period::wait(toward));
    }

    /// Preloads the period of `ticks` that ends with `cmd`'s pulse, driving the SIGN levels it
    /// needs; or where the timer cannot count so far, a pulse-less period before it.
    #[cold]
    #[inline(never)]
    fn preload_pulse_after(&mut self, cmd: StepCmd, ticks: u32, bits: StepBits) {
        if ticks > T::MAX_PERIOD_TICKS {
            let wait = T::MAX_PERIOD_TICKS / 2;
            self.pending = Some((cmd, ticks - wait));
            self.preload(wait, 0, Period::wait(bits.toward));
            return;
        }
        let changes = self.direction_preloaded.changes(bits.moving, bits.forward);
        self.direction_preloaded.put(bits.moving, bits.forward);
        self.preload(ticks, bits.moving, Period::step(cmd, bits, changes));
    }
}
