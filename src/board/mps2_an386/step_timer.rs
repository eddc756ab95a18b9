//! The model's step timer: CMSDK timer 1 in place of the F407's TIM1. Its reload value is loaded
//! into the counter each time the count reaches 0, as TIM1's preloaded ARR is at an update
//! event, and its interrupt is the update interrupt: the pulse engine preloads the next period
//! there, at the pulse priority. The model has no PULS pins: the timer counts, per axis and
//! direction, the pulse each period ends with, from the periods and SIGN levels the engine gave
//! it — what a logic analyser on the F407's PULS/SIGN pins would count — so a run can be checked
//! against the position the engine counted.
//!
//! Its update events, as the pulse engine learns of them (`StepTimer::update_count`), are the
//! periods whose pulses it counts: one for each update its interrupt handles. A period QEMU lets
//! the timer count again before the interrupt runs (with `-icount sleep=off` it skips idle time
//! to the reloaded deadline) ends with no pulse on the model, so it is no update to count.

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicBool, AtomicPtr, AtomicU32, Ordering};

use cortex_m::peripheral::NVIC;
use servoplot::geom::{Axis, TICK_HZ, TICKS_PER_US};
use servoplot::machine::{Machine, PulseWriter};
use servoplot::machine_io::inputs::{InputLevels, LIMITS};
use servoplot::motion::pulse::{PulseEngine, StepConsumer, StepTimer};

use super::clock::CLOCKS_PER_US;
use super::regs::{self, *};
use crate::firmware::executor::Irq;

/// Timer counts per step tick.
const CLOCKS_PER_TICK: u32 = CLOCKS_PER_US / (TICK_HZ / 1_000_000);
const _: () = assert!(CLOCKS_PER_US.is_multiple_of(TICK_HZ / 1_000_000));

/// The machine's inputs, all idle: the limit switches open (their pull-ups read high), the
/// drivers well and the e-stop closed (both read low).
const IDLE_INPUTS: InputLevels = LIMITS;

/// The pulses the timer has ended its periods with: X with SIGN high, X with SIGN low, then Y
/// likewise. Read from outside the model too (`model/run.py` reads them from the model's RAM,
/// as a debugger would).
static PULSES_EMITTED: [AtomicU32; 4] = [const { AtomicU32::new(0) }; 4];

/// CMSDK timer 1 driving the (modelled) PULS outputs.
pub struct ModelStepTimer {
    /// SIGN levels, per axis.
    sign: [bool; 2],
    /// The axes the period counting now ends with a pulse on, and the preloaded period.
    active_axes: u8,
    preloaded_axes: u8,
    /// `start` raised an update event the interrupt has yet to see.
    starting: bool,
    /// Update events handled so far (wrapping): the periods counted.
    updates: u16,
}

impl ModelStepTimer {
    /// Timer 1 stopped.
    pub fn new() -> Self {
        regs::write(TIMER1, TIMER_CTRL, 0);
        regs::write(TIMER1, TIMER_INTCLEAR, 1);
        ModelStepTimer { sign: [false; 2], active_axes: 0, preloaded_axes: 0, starting: false, updates: 0 }
    }

    /// An update event: the period that was counting has ended with its pulses, and the
    /// preloaded one counts now.
    fn period_ended(&mut self) {
        for axis in Axis::ALL {
            if self.active_axes & (1 << axis.index()) != 0 {
                let n = &PULSES_EMITTED[2 * axis.index() + usize::from(!self.sign[axis.index()])];
                n.store(n.load(Ordering::Relaxed).wrapping_add(1), Ordering::Relaxed);
            }
        }
        self.active_axes = self.preloaded_axes;
        self.updates = self.updates.wrapping_add(1);
    }
}

impl StepTimer for ModelStepTimer {
    /// The F407's 16-bit period, so the engine splits long intervals the same way.
    const MAX_PERIOD_TICKS: u32 = u16::MAX as u32 - 1;
    /// The F407's, so the engine times SIGN on the model as on the chip.
    const SIGN_LATENCY_TICKS: u32 = 2 * TICKS_PER_US;

    fn set_sign(&mut self, axis: Axis, high: bool) {
        self.sign[axis.index()] = high;
    }

    fn preload(&mut self, ticks: u32, axes: u8) {
        // The count runs from the reload value down to 0 and one more: reload + 1 counts.
        regs::write(TIMER1, TIMER_RELOAD, ticks * CLOCKS_PER_TICK - 1);
        self.preloaded_axes = axes;
    }

    fn start(&mut self, _width_ticks: u32) {
        regs::write(TIMER1, TIMER_VALUE, regs::read(TIMER1, TIMER_RELOAD));
        regs::write(TIMER1, TIMER_CTRL, TIMER_ENABLE | TIMER_IRQ_ENABLE);
        // As TIM1's update generation: the preloaded period begins, and the interrupt runs.
        self.starting = true;
        NVIC::pend(Irq(TIMER1_IRQ));
    }

    fn stop(&mut self) {
        regs::write(TIMER1, TIMER_CTRL, 0);
    }

    fn halt(&mut self) {
        regs::write(TIMER1, TIMER_CTRL, 0);
        // The period under way ends with no pulse.
        self.active_axes = 0;
    }

    fn input_levels(&mut self) -> InputLevels {
        IDLE_INPUTS
    }

    fn update_count(&mut self) -> u16 {
        self.updates
    }

    fn pend_news(&mut self) {
        NVIC::pend(Irq(PULSE_NEWS_IRQ));
    }
}

/// The engine and the pulse interrupt's handle to the machine it counts for, owned by the
/// interrupt once [`start`] has put them in the slot.
struct Pulses {
    engine: PulseEngine<'static, ModelStepTimer>,
    machine: PulseWriter<'static>,
}

struct Slot {
    filled: AtomicBool,
    pulses: UnsafeCell<Option<Pulses>>,
}

// SAFETY: `start` writes the slot once, before the interrupt is unmasked; from then on only the
// interrupt (one priority, never re-entered) touches it.
unsafe impl Sync for Slot {}

static SLOT: Slot = Slot { filled: AtomicBool::new(false), pulses: UnsafeCell::new(None) };

/// The machine the engine's news is for, for the news interrupt: set once by [`start`]. It only
/// hands the news on, which needs no writer's handle (the engine's handle stays the engine's).
static NEWS_FOR: AtomicPtr<Machine> = AtomicPtr::new(core::ptr::null_mut());

/// Hands the engine to timer 1's interrupt, at `priority`, and enables the news interrupt at
/// `news_priority`; once, at power-on.
pub fn start(
    timer: ModelStepTimer,
    steps: StepConsumer<'static>,
    machine: PulseWriter<'static>,
    priority: u8,
    news_priority: u8,
) {
    if SLOT.filled.load(Ordering::Acquire) {
        return;
    }
    NEWS_FOR.store(core::ptr::from_ref(machine.machine()).cast_mut(), Ordering::Release);
    // SAFETY: the priority is set before the line is unmasked; the handler only reads NEWS_FOR.
    unsafe {
        let mut core = cortex_m::Peripherals::steal();
        core.NVIC.set_priority(Irq(PULSE_NEWS_IRQ), news_priority);
        NVIC::unmask(Irq(PULSE_NEWS_IRQ));
    }
    // SAFETY: the interrupt is masked and nothing else touches the slot (see `Slot`).
    unsafe { *SLOT.pulses.get() = Some(Pulses { engine: PulseEngine::new(timer, steps), machine }) };
    SLOT.filled.store(true, Ordering::Release);
    // SAFETY: the priority is set before the line is unmasked; the handler touches only SLOT.
    unsafe {
        let mut core = cortex_m::Peripherals::steal();
        core.NVIC.set_priority(Irq(TIMER1_IRQ), priority);
        NVIC::unpend(Irq(TIMER1_IRQ));
        NVIC::unmask(Irq(TIMER1_IRQ));
    }
}

/// Wakes the engine: the motion task queued steps.
pub fn kick() {
    NVIC::pend(Irq(TIMER1_IRQ));
}

/// Timer 1's interrupt: an update event (the count reached 0 and reloaded, or `start`), or the
/// motion task's kick.
pub fn on_interrupt() {
    if !SLOT.filled.load(Ordering::Acquire) {
        return;
    }
    // SAFETY: only this interrupt touches the slot once it is filled (see `Slot`).
    let Some(p) = (unsafe { &mut *SLOT.pulses.get() }).as_mut() else { return };
    let counted = regs::read(TIMER1, TIMER_INTCLEAR) & 1 != 0;
    let update = counted || core::mem::take(&mut p.engine.timer_mut().starting);
    if counted {
        regs::write(TIMER1, TIMER_INTCLEAR, 1);
    }
    if update {
        p.engine.timer_mut().period_ended();
        p.engine.on_period(p.machine);
    }
    if !p.engine.is_running() {
        // Kicked by the motion task: start if steps are queued.
        p.engine.kick(p.machine);
    }
}

/// The news interrupt: hands on what the pulse engine left in the machine (pended by it, below
/// it; see `servoplot::machine`'s pulse news).
pub fn on_news() {
    // SAFETY: non-null, it is the `&'static Machine` `start` stored; only shared use.
    if let Some(machine) = unsafe { NEWS_FOR.load(Ordering::Acquire).as_ref() } {
        machine.deliver_pulse_news();
    }
}

/// The pulses emitted so far: X with SIGN high, X with SIGN low, then Y likewise.
pub fn pulses_emitted() -> [u32; 4] {
    PULSES_EMITTED.each_ref().map(|n| n.load(Ordering::Relaxed))
}
