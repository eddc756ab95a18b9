//! The step timer: TIM1 counting at the step tick rate, PWM mode 2 on CH1 (PE9, X PULS) and
//! CH2 (PE11, Y PULS) so that each period ends with a pulse the hardware times to the tick,
//! ARR and CCR preloaded so the next period follows by itself. Its update interrupt runs the
//! pulse engine at the highest priority; the motion task pends that interrupt to start it.
//! TIM4 counts TIM1's update events in hardware, so the engine learns how many periods really
//! ended when its interrupt comes late.

use core::ptr::null_mut;
use core::sync::atomic::{AtomicPtr, Ordering};

use embassy_stm32::Peri;
use embassy_stm32::gpio::{Level, Output};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::InterruptExt;
use embassy_stm32::pac::timer::regs::SrAdv;
use embassy_stm32::peripherals::{TIM1, TIM4};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{MasterMode, OutputCompareMode, OutputPolarity, SlaveMode, Timer, TriggerSource};
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{Ch1, Ch2, Channel};
use static_cell::StaticCell;

use super::inputs::InputPins;
use servoplot::geom::{Axis, TICK_HZ, TICKS_PER_US};
use servoplot::machine::{Machine, PulseWriter};
use servoplot::machine_io::inputs::InputLevels;
use servoplot::motion::pulse::{PulseEngine, StepConsumer, StepTimer};

/// The channels driving X and Y PULS.
const PULS_CHANNELS: [Channel; 2] = [Channel::Ch1, Channel::Ch2];

/// A compare value the 16-bit counter never reaches (its periods end at 65_534): no pulse.
const NO_PULSE: u16 = u16::MAX;

/// The longest the update interrupt's SIGN write comes after the update event. Cortex-M4
/// exception entry is 12 cycles (ARM's Cortex-M4 TRM, 3.9), a few more for the vector fetch
/// through flash wait states; the handler then runs up to some 55 instructions before its last
/// GPIO write (about 110 cycles with the ART accelerator on); and nothing else in the firmware
/// masks interrupts for longer than 80 instructions, some 150 cycles (`cost/count.py --masked`
/// counts the longest stretch and fails above that). Under 300 cycles in all at 168 MHz: 2 µs
/// (336) keeps a margin.
const SIGN_LATENCY_US: u32 = 2;

/// TIM1 driving PULS, the SIGN outputs, and the input pins the engine watches; TIM4 counting
/// TIM1's update events.
pub struct Tim1StepTimer {
    timer: Timer<'static, TIM1>,
    updates: Timer<'static, TIM4>,
    sign: [Output<'static>; 2],
    inputs: InputPins,
    width_ticks: u32,
    _puls: (PwmPin<'static, TIM1, Ch1>, PwmPin<'static, TIM1, Ch2>),
}

impl Tim1StepTimer {
    /// TIM1 set up and stopped, PULS low, SIGN low; TIM4 counting its update events.
    pub fn new(
        tim: Peri<'static, TIM1>,
        update_counter: Peri<'static, TIM4>,
        puls_x: PwmPin<'static, TIM1, Ch1>,
        puls_y: PwmPin<'static, TIM1, Ch2>,
        sign: [Output<'static>; 2],
        inputs: InputPins,
    ) -> Self {
        let mut timer = Timer::new(tim);
        // 168 MHz / 4 MHz: a prescaler of 42 (PSC = 41), whole.
        timer.set_tick_freq(Hertz(TICK_HZ));
        timer.set_autoreload_preload(true);
        for channel in PULS_CHANNELS {
            timer.set_output_compare_mode(channel, OutputCompareMode::PwmMode2);
            timer.set_output_compare_preload(channel, true);
            timer.set_output_polarity(channel, OutputPolarity::ActiveHigh);
            timer.set_compare_value(channel, NO_PULSE);
            timer.enable_channel(channel, true);
        }
        timer.set_moe(true);
        // TRGO pulses at every update event (RM0090, TIMx_CR2: MMS = 010, "the update event is
        // selected as trigger output").
        timer.set_master_mode(MasterMode::UPDATE);
        // TIM4 counts TRGO's pulses: its internal trigger 0 is TIM1's TRGO (RM0090, TIMx_SMCR:
        // the table of internal trigger connections), and external clock mode 1 (SMS = 111)
        // clocks the counter with every rising edge of the chosen trigger. Prescaler 0 and the
        // reset ARR of 0xFFFF: CNT counts update events, wrapping at 2¹⁶.
        let updates = Timer::new(update_counter);
        updates.set_trigger_source(TriggerSource::ITR0);
        updates.set_slave_mode(SlaveMode::EXT_CLOCK_MODE);
        updates.start();
        // Setting the tick rate made an update event: its flag is no period of ours.
        timer.regs_core().sr().write_value(embassy_stm32::pac::timer::regs::SrCore(!1));
        timer.enable_update_interrupt(true);
        Tim1StepTimer { timer, updates, sign, inputs, width_ticks: 0, _puls: (puls_x, puls_y) }
    }
}

impl StepTimer for Tim1StepTimer {
    const MAX_PERIOD_TICKS: u32 = NO_PULSE as u32;
    const SIGN_LATENCY_TICKS: u32 = SIGN_LATENCY_US * TICKS_PER_US;

    fn set_sign(&mut self, axis: Axis, high: bool) {
        self.sign[axis.index()].set_level(if high { Level::High } else { Level::Low });
    }

    #[inline(always)]
    fn preload(&mut self, ticks: u32, axes: u8) {
        let regs = self.timer.regs_gp16();
        // The engine keeps 2·width ≤ ticks ≤ MAX_PERIOD_TICKS for periods that pulse.
        regs.arr().write(|w| w.set_arr((ticks - 1) as u16));
        // The pulse's leading edge, or on an axis without a pulse NO_PULSE (all ones).
        let edge = ticks.wrapping_sub(self.width_ticks) as u16;
        let on = |axis: u8| edge | u16::from(axes & axis == 0).wrapping_neg();
        regs.ccr(0).write(|w| w.set_ccr(on(1)));
        regs.ccr(1).write(|w| w.set_ccr(on(2)));
    }

    fn start(&mut self, width_ticks: u32) {
        self.width_ticks = width_ticks;
        // After a halt the outputs were forced low.
        for channel in PULS_CHANNELS {
            self.timer.set_output_compare_mode(channel, OutputCompareMode::PwmMode2);
        }
        let regs = self.timer.regs_core();
        // The update event loads the preloaded period and raises the update interrupt.
        regs.egr().write(|w| w.set_ug(true));
        self.timer.start();
    }

    fn stop(&mut self) {
        self.timer.stop();
    }

    fn halt(&mut self) {
        self.timer.stop();
        for channel in PULS_CHANNELS {
            self.timer.set_output_compare_mode(channel, OutputCompareMode::ForceInactive);
        }
    }

    #[inline(always)]
    fn input_levels(&mut self) -> InputLevels {
        self.inputs.levels()
    }

    #[inline(always)]
    fn update_count(&mut self) -> u16 {
        self.updates.regs_core().cnt().read().cnt()
    }

    fn pend_news(&mut self) {
        interrupt::TIM7.pend();
    }
}

/// The engine and the pulse interrupt's handle to the machine it counts for.
struct Pulses {
    engine: PulseEngine<'static, Tim1StepTimer>,
    machine: PulseWriter<'static>,
}

/// Where [`start`] builds the engine, once.
static PULSES_CELL: StaticCell<Pulses> = StaticCell::new();

/// The engine, for the interrupt: null until [`start`] has built it. From then on only the
/// interrupt uses it, one run at a time (nothing else can reach it, and the interrupt does not
/// nest in itself), so it takes no lock and masks nothing.
static PULSES: AtomicPtr<Pulses> = AtomicPtr::new(null_mut());

/// The machine the engine's news is for, for the news interrupt: set once by [`start`]. It only
/// hands the news on, which needs no writer's handle (the engine's handle stays the engine's).
static NEWS_FOR: AtomicPtr<Machine> = AtomicPtr::new(null_mut());

/// Hands the engine to the interrupt and enables it at `priority`, and the news interrupt
/// (TIM7's vector, TIM7 unused as a timer) at `news_priority`; once, at power-on.
pub fn start(
    timer: Tim1StepTimer,
    steps: StepConsumer<'static>,
    machine: PulseWriter<'static>,
    priority: interrupt::Priority,
    news_priority: interrupt::Priority,
) {
    NEWS_FOR.store(core::ptr::from_ref(machine.machine()).cast_mut(), Ordering::Release);
    interrupt::TIM7.set_priority(news_priority);
    interrupt::TIM7.unpend();
    // SAFETY: the handler below only reads NEWS_FOR, set just above.
    unsafe { interrupt::TIM7.enable() };
    let pulses = PULSES_CELL.init(Pulses { engine: PulseEngine::new(timer, steps), machine });
    PULSES.store(pulses, Ordering::Release);
    interrupt::TIM1_UP_TIM10.set_priority(priority);
    interrupt::TIM1_UP_TIM10.unpend();
    // SAFETY: the handler below only touches PULSES, set just above.
    unsafe { interrupt::TIM1_UP_TIM10.enable() };
}

/// Wakes the engine: the motion task queued steps.
pub fn kick() {
    interrupt::TIM1_UP_TIM10.pend();
}

#[interrupt]
fn TIM1_UP_TIM10() {
    let regs = embassy_stm32::pac::TIM1;
    let update = regs.sr().read().uif();
    if update {
        // rc_w0: a 0 clears UIF, the 1s leave the other flags alone.
        regs.sr().write_value(SrAdv(!1));
    }
    let pulses = PULSES.load(Ordering::Acquire);
    // SAFETY: non-null, it is the `&'static mut` that `start` took from PULSES_CELL (which
    // hands out one, once) and gave up to this interrupt; this is its only user, and a run of
    // it never overlaps another.
    let Some(p) = (unsafe { pulses.as_mut() }) else { return };
    if update {
        p.engine.on_period(p.machine);
    }
    if !p.engine.is_running() {
        // Pended by the motion task: start if steps are queued.
        p.engine.kick(p.machine);
    }
}

/// The news interrupt: hands on what the pulse engine left in the machine (pended by it, below
/// it; see `servoplot::machine`'s pulse news).
#[interrupt]
fn TIM7() {
    // SAFETY: non-null, it is the `&'static Machine` `start` stored; only shared use.
    if let Some(machine) = unsafe { NEWS_FOR.load(Ordering::Acquire).as_ref() } {
        machine.deliver_pulse_news();
    }
}
