//! The pulse path's cost per pulse: the firmware's pulse engine in the interrupt of a timer of
//! the model (the CMSDK timer of QEMU's mps2-an386), writing the model's registers where the
//! board writes TIM1's and the GPIO's, exactly as many of them.
//!
//! The engine and the steps are set up, then the timer runs until the engine stops it; the
//! harness sleeps (WFI) meanwhile. Two runs of different lengths give the cost per pulse: from
//! the timer's interrupt entry to its return, and the sleep loop around it.

use core::ptr::{addr_of, addr_of_mut, null_mut, read_volatile, write_volatile};
use core::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

use servoplot::geom::{Axis, StepCmd, TICKS_PER_US};
use servoplot::machine::{Machine, PulseWriter};
use servoplot::machine_io::inputs::InputLevels;
use servoplot::motion::pulse::{PulseEngine, StepQueue, StepTimer};
use servoplot::settings::Settings;

use crate::{cost_mark, report_steps};

/// CMSDK APB timer 0 of the model: control, reload, interrupt status/clear.
const TIMER0_CTRL: *mut u32 = 0x4000_0000 as *mut u32;
const TIMER0_RELOAD: *mut u32 = 0x4000_0008 as *mut u32;
const TIMER0_INTCLEAR: *mut u32 = 0x4000_000C as *mut u32;
const TIMER_ENABLE: u32 = 1;
const TIMER_IRQ_ENABLE: u32 = 1 << 3;
/// Its interrupt line.
pub const TIMER0_IRQ: u16 = 8;
/// The model's timer counts at 25 MHz: 25 clocks a microsecond, 6.25 a step tick (periods
/// here are whole microseconds).
const TIMER_CLOCKS_PER_US: u32 = 25;
/// Where the board writes its two compare registers and a SIGN output (one store each).
static mut COMPARE: [u32; 2] = [0; 2];
static mut SIGN_OUT: u32 = 0;
/// Where the board reads its input port (one load, then as many shifts and masks): every input
/// idle, the switches open (high), the drivers' alarms and the e-stop low.
static mut INPUT_PORT: u32 = !(1 << 8 | 1 << 14 | 1 << 15);
/// Where the board reads its update counter (one load): the model has none, so the interrupt
/// counts here before the engine runs.
static mut UPDATES: u16 = 0;

/// The model's timer standing in for TIM1.
pub struct ModelStepTimer {
    width_ticks: u32,
}

impl StepTimer for ModelStepTimer {
    const MAX_PERIOD_TICKS: u32 = 65_535;
    const SIGN_LATENCY_TICKS: u32 = 2 * TICKS_PER_US;

    fn set_sign(&mut self, axis: Axis, high: bool) {
        // One store, as the board's BSRR write.
        let bit = 1u32 << (axis.index() + if high { 0 } else { 16 });
        // SAFETY: SIGN_OUT is only written here, from the interrupt.
        unsafe { write_volatile(addr_of_mut!(SIGN_OUT), bit) };
    }

    fn preload(&mut self, ticks: u32, axes: u8) {
        // As the board's: the edge, or on an axis without a pulse a compare never reached.
        let edge = ticks.wrapping_sub(self.width_ticks);
        let on = |axis: u8| edge | u32::from(axes & axis == 0).wrapping_neg();
        // SAFETY: the model's timer registers; COMPARE is only written here, from the interrupt.
        unsafe {
            write_volatile(TIMER0_RELOAD, ticks * TIMER_CLOCKS_PER_US / TICKS_PER_US);
            write_volatile(addr_of_mut!(COMPARE[0]), on(1));
            write_volatile(addr_of_mut!(COMPARE[1]), on(2));
        }
    }

    fn start(&mut self, width_ticks: u32) {
        self.width_ticks = width_ticks;
        // SAFETY: the model's timer register.
        unsafe { write_volatile(TIMER0_CTRL, TIMER_ENABLE | TIMER_IRQ_ENABLE) };
        // The board's update event raises the interrupt at once: so does this.
        cortex_m::peripheral::NVIC::pend(Irq);
    }

    fn stop(&mut self) {
        // SAFETY: the model's timer register.
        unsafe { write_volatile(TIMER0_CTRL, 0) };
    }

    fn halt(&mut self) {
        self.stop();
    }

    fn input_levels(&mut self) -> InputLevels {
        // SAFETY: INPUT_PORT is only read.
        let port = unsafe { read_volatile(addr_of!(INPUT_PORT)) };
        (((port >> 4) & 0x1F) | ((port >> 9) & 0x60)) as InputLevels
    }

    fn update_count(&mut self) -> u16 {
        // SAFETY: UPDATES is written only by the interrupt, which runs this.
        unsafe { read_volatile(addr_of!(UPDATES)) }
    }

    /// Nothing here waits for the engine's news.
    fn pend_news(&mut self) {}
}

/// The model's interrupt number for the NVIC.
#[derive(Clone, Copy)]
struct Irq;

// SAFETY: line 8 is the model's timer 0 interrupt.
unsafe impl cortex_m::interrupt::InterruptNumber for Irq {
    fn number(self) -> u16 {
        TIMER0_IRQ
    }
}

struct Pulses {
    engine: PulseEngine<'static, ModelStepTimer>,
    machine: PulseWriter<'static>,
}

/// The engine of the run under way, for the interrupt: as the board's, a pointer the interrupt
/// alone uses once it is set (each run sets it while the interrupt is masked).
static PULSES: AtomicPtr<Pulses> = AtomicPtr::new(null_mut());
static mut PULSES_STORE: Option<Pulses> = None;

/// Whether the engine runs the timer, as the interrupt leaves it: what the sleep loop reads.
static RUNNING: AtomicBool = AtomicBool::new(false);

/// The timer's interrupt: as the board's, a status read and clear, then the engine.
pub extern "C" fn timer0_interrupt() {
    // SAFETY: the model's timer register; writing 1 clears the interrupt. UPDATES is only
    // written here.
    unsafe {
        write_volatile(TIMER0_INTCLEAR, 1);
        write_volatile(addr_of_mut!(UPDATES), read_volatile(addr_of!(UPDATES)).wrapping_add(1));
    }
    // SAFETY: set by `measure` while this interrupt was masked; only this interrupt uses it.
    let Some(p) = (unsafe { PULSES.load(Ordering::Acquire).as_mut() }) else { return };
    p.engine.on_period(p.machine);
    RUNNING.store(p.engine.is_running(), Ordering::Relaxed);
}

static MACHINE: static_machine::Slot = static_machine::Slot::new();

mod static_machine {
    use core::cell::UnsafeCell;
    use core::mem::MaybeUninit;
    use servoplot::machine::Machine;

    /// A place for the one machine the pulse path counts for.
    pub struct Slot(UnsafeCell<MaybeUninit<Machine>>);

    // SAFETY: written once before the interrupt is enabled, only read afterwards.
    unsafe impl Sync for Slot {}

    impl Slot {
        pub const fn new() -> Slot {
            Slot(UnsafeCell::new(MaybeUninit::uninit()))
        }

        /// Puts `machine` in the slot; call once.
        pub fn init(&'static self, machine: Machine) -> &'static Machine {
            // SAFETY: called once, before anything reads the slot.
            unsafe { (*self.0.get()).write(machine) }
        }
    }
}

static mut QUEUE: StepQueue = StepQueue::new();

/// Emits `steps` (at most the queue's capacity less one) and reports the run's instructions.
pub fn measure(steps: &[StepCmd], label: &str, machine: PulseWriter<'static>) {
    // SAFETY: each run splits the queue anew while the interrupt is off; nothing else uses it.
    let queue: &'static mut StepQueue = unsafe { &mut *addr_of_mut!(QUEUE) };
    *queue = StepQueue::new();
    let (mut producer, consumer) = queue.split();
    let slots = producer.free_slots();
    if slots.len() < steps.len() {
        panic!("pulse path: too many steps");
    }
    slots[..steps.len()].copy_from_slice(steps);
    producer.publish(steps.len());
    producer.rest();
    let engine = PulseEngine::new(ModelStepTimer { width_ticks: 0 }, consumer);
    // SAFETY: the interrupt is masked (as after the last run), so nothing else uses the store.
    let p = unsafe { (*addr_of_mut!(PULSES_STORE)).insert(Pulses { engine, machine }) };
    PULSES.store(p, Ordering::Release);
    cost_mark();
    // Kicked as the board's motion task does, from outside the interrupt: before unmasking it.
    p.engine.kick(p.machine);
    RUNNING.store(p.engine.is_running(), Ordering::Relaxed);
    // SAFETY: the handler only touches PULSES, set just above.
    unsafe { cortex_m::peripheral::NVIC::unmask(Irq) };
    // Sleep until the engine has stopped the timer. Interrupts are off while deciding to sleep,
    // so the last one cannot slip in between; WFI still wakes on it.
    cortex_m::interrupt::disable();
    loop {
        if !RUNNING.load(Ordering::Relaxed) {
            break;
        }
        cortex_m::asm::wfi();
        // SAFETY: the pending timer interrupt runs here; nothing else is enabled.
        unsafe { cortex_m::interrupt::enable() };
        cortex_m::interrupt::disable();
    }
    // SAFETY: as above.
    unsafe { cortex_m::interrupt::enable() };
    cost_mark();
    cortex_m::peripheral::NVIC::mask(Irq);
    report_steps("pulse", label, "both", steps.len() as u64);
}

/// The pulse interrupt's handle to the machine the pulse path counts for.
pub fn machine(settings: Settings) -> PulseWriter<'static> {
    let Some(handles) = MACHINE.init(Machine::new(settings)).handles() else { panic!("handles") };
    handles.pulse
}
