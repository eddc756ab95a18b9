//! The step timer: TIM1 counting at the step tick rate, PWM mode 2 on CH1 (PE9, X PULS) and
//! CH2 (PE11, Y PULS) so that each period ends with a pulse the hardware times to the tick,
//! ARR and CCR preloaded so the next period follows by itself. Its update interrupt runs the
//! pulse engine at the highest priority; the motion task pends that interrupt to start it.

use core::cell::RefCell;
use core::mem::MaybeUninit;

use embassy_stm32::Peri;
use embassy_stm32::gpio::{Level, Output};
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::InterruptExt;
use embassy_stm32::pac::timer::regs::SrAdv;
use embassy_stm32::peripherals::TIM1;
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{OutputCompareMode, OutputPolarity, Timer};
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::timer::{Ch1, Ch2, Channel};
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

use super::inputs::InputPins;
use servoplot::geom::{Axis, TICK_HZ};
use servoplot::inputs::InputLevels;
use servoplot::machine::Machine;
use servoplot::pulse::{PulseEngine, StepConsumer, StepTimer};

/// The channels driving X and Y PULS.
const PULS_CHANNELS: [Channel; 2] = [Channel::Ch1, Channel::Ch2];

/// A compare value the 16-bit counter never reaches (its periods end at 65_534): no pulse.
const NO_PULSE: u16 = u16::MAX;

/// TIM1 driving PULS, the SIGN outputs, and the input pins the engine watches.
pub struct Tim1StepTimer {
    timer: Timer<'static, TIM1>,
    sign: [Output<'static>; 2],
    inputs: InputPins,
    width_ticks: u32,
    _puls: (PwmPin<'static, TIM1, Ch1>, PwmPin<'static, TIM1, Ch2>),
}

impl Tim1StepTimer {
    /// TIM1 set up and stopped, PULS low, SIGN low.
    pub fn new(
        tim: Peri<'static, TIM1>,
        puls_x: PwmPin<'static, TIM1, Ch1>,
        puls_y: PwmPin<'static, TIM1, Ch2>,
        sign: [Output<'static>; 2],
        inputs: InputPins,
    ) -> Self {
        let mut timer = Timer::new(tim);
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
        // Setting the tick rate made an update event: its flag is no period of ours.
        timer.regs_core().sr().write_value(embassy_stm32::pac::timer::regs::SrCore(!1));
        timer.enable_update_interrupt(true);
        Tim1StepTimer { timer, sign, inputs, width_ticks: 0, _puls: (puls_x, puls_y) }
    }
}

impl StepTimer for Tim1StepTimer {
    const MAX_PERIOD_TICKS: u32 = NO_PULSE as u32;

    fn set_sign(&mut self, axis: Axis, high: bool) {
        self.sign[axis.index()].set_level(if high { Level::High } else { Level::Low });
    }

    fn preload(&mut self, ticks: u32, axes: u8) {
        let regs = self.timer.regs_gp16();
        // The engine keeps 2·width ≤ ticks ≤ MAX_PERIOD_TICKS for periods that pulse.
        regs.arr().write(|w| w.set_arr((ticks - 1) as u16));
        let edge = ticks.saturating_sub(self.width_ticks) as u16;
        regs.ccr(0).write(|w| w.set_ccr(if axes & 1 != 0 { edge } else { NO_PULSE }));
        regs.ccr(1).write(|w| w.set_ccr(if axes & 2 != 0 { edge } else { NO_PULSE }));
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
}

/// The engine and the machine it counts for, owned by the interrupt.
struct Pulses {
    engine: PulseEngine<'static, Tim1StepTimer>,
    machine: &'static Machine,
}

/// Where the interrupt finds the engine once [`start`] has put it there. Not an
/// `Option<Pulses>`: its `None` is not all zero bytes, so the static would be copied from flash
/// at boot (120 B of it); this one is zero, in `.bss`, and the interrupt tests one byte all the
/// same.
struct Slot {
    /// `pulses` holds the engine.
    filled: bool,
    pulses: MaybeUninit<Pulses>,
}

impl Slot {
    fn get(&mut self) -> Option<&mut Pulses> {
        // SAFETY: `filled` is set only once `pulses` is written, and never cleared.
        self.filled.then(|| unsafe { self.pulses.assume_init_mut() })
    }
}

static PULSES: Mutex<CriticalSectionRawMutex, RefCell<Slot>> =
    Mutex::new(RefCell::new(Slot { filled: false, pulses: MaybeUninit::uninit() }));

/// Hands the engine to the interrupt and enables it at `priority`; once, at power-on.
pub fn start(
    timer: Tim1StepTimer,
    steps: StepConsumer<'static>,
    machine: &'static Machine,
    priority: interrupt::Priority,
) {
    let pulses = Pulses { engine: PulseEngine::new(timer, steps), machine };
    PULSES.lock(|p| {
        let mut slot = p.borrow_mut();
        slot.pulses.write(pulses);
        slot.filled = true;
    });
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
    PULSES.lock(|p| {
        if let Some(p) = p.borrow_mut().get() {
            if update {
                p.engine.on_period(p.machine);
            }
            if !p.engine.is_running() {
                // Pended by the motion task: start if steps are queued.
                p.engine.kick(p.machine);
            }
        }
    });
}
