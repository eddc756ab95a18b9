//! The model board: QEMU's mps2-an386, a Cortex-M4F, with its data RAM cut to the F407's
//! 128 KiB (memory.x). CI boots the firmware's whole task set on it (`crate::firmware`, the same
//! as on the F407) to see it run on the chip's instruction set, with the F407's stack and
//! statics, its interrupt priorities and its executors, in the F407's time (see `clock`).
//!
//! | F407 board                         | model                                               |
//! |------------------------------------|-----------------------------------------------------|
//! | TIM1 update interrupt, PULS/SIGN   | CMSDK timer 1 (IRQ 9), pulses counted (`step_timer`) |
//! | TIM2, embassy-time's timer         | timer 0 free-running (IRQ 8), dual timer 1 alarm (IRQ 10) |
//! | IWDG                               | dual timer 2 (IRQ 10): run out, QEMU stops with a failure |
//! | USART2, the host link              | UART 0 (IRQs 0, 1)                                  |
//! | USB CDC-ACM, the second link       | UART 1 (IRQs 2, 3)                                  |
//! | UART5 / UART4 vectors, executors   | IRQ 14 (motion) / IRQ 15 (thread-mode pender)       |
//! | TIM7 vector, the pulse news        | IRQ 16                                              |
//! | flash sectors 10-11, the store     | code RAM at the same offsets (`devices::ModelFlash`) |
//! | ST7920 on SPI2                     | the same driver on a bus that takes the F407's time |
//! | keypad matrix                      | keys tapped by the host on UART 2 (`keys`)          |
//! | microSD card on SPI3               | a FAT image QEMU loads into its PSRAM (`card`)      |
//! | SON, LED, buzzer, pen              | pins that drive nothing; inputs idle                |
//! | defmt over RTT                     | defmt over semihosting, to QEMU's standard output   |
//!
//! A panic, a hard fault, an unexpected interrupt or the watchdog running out ends QEMU with a
//! non-zero status (semihosting), after a line in the log.

mod card;
mod clock;
mod devices;
mod keys;
pub mod poll_clock;
mod regs;
mod step_timer;
mod uart;

use cortex_m::peripheral::NVIC;
use defmt_semihosting as _;
use embassy_executor::{SendSpawner, Spawner};
use embassy_time::Delay;
use servoplot::machine::PulseWriter;
use servoplot::machine_io::inputs::InputLevels;
use servoplot::machine_io::watchdog::WATCHDOG_TIMEOUT_MS;
use servoplot::motion::pulse::StepConsumer;
use servoplot::tasks::lcd::St7920Lcd;

use crate::firmware::executor::{self, Irq};
use crate::firmware::priority;
use step_timer::ModelStepTimer;

/// What the log calls the board.
pub const NAME: &str = "mps2-an386 (Cortex-M4F model of the STM32F407)";

/// The thread-mode executor's pender.
pub const THREAD_PENDER_IRQ: u16 = regs::THREAD_PENDER_IRQ;

/// QEMU's exit status when the model stops on a fault.
const EXIT_PANIC: i32 = 101;
const EXIT_HARD_FAULT: i32 = 102;
const EXIT_UNEXPECTED_INTERRUPT: i32 = 103;
const EXIT_WATCHDOG: i32 = 104;
const EXIT_WRONG_MACHINE: i32 = 105;

/// The system controller's ID register, and what it reads on the AN386 image.
const SCC_ID: usize = 0x4002_FFFC;
const SCC_ID_AN386: u32 = 0x4104_3860;

pub type Column = keys::ModelColumn;
pub type Row = keys::ModelRow;
pub type Output = devices::NoPin;
pub type PenPwm = devices::NoPwm;
pub type Flash = devices::ModelFlash;
pub type HostRx = uart::UartRx;
pub type HostTx = uart::UartTx;
pub type LinkRx = uart::UartRx;
pub type LinkTx = uart::UartTx;
pub type Lcd = St7920Lcd<devices::LcdBus, devices::NoPin, Delay>;
pub type Card = card::ModelCard;
pub type Watchdog = clock::Watchdog;

/// Everything the firmware's tasks drive, set up and idle.
pub struct Board {
    pub step_timer: ModelStepTimer,
    pub son: Output,
    pub pen: PenPwm,
    pub lights: [Output; 2],
    pub columns: [Column; 4],
    pub rows: [Row; 4],
    pub watchdog: Watchdog,
    pub flash: Flash,
    pub host: (HostRx, HostTx),
    pub second_link: (LinkRx, LinkTx),
    pub lcd: Lcd,
    pub card: &'static mut Card,
}

/// At reset: the step timer stopped.
pub fn safe_outputs() {
    regs::write(regs::TIMER1, regs::TIMER_CTRL, 0);
}

/// Sets the model up: its clock and watchdog (running from here on), the step timer, the two
/// UARTs, at the firmware's priorities, and the keys' UART.
#[inline(never)]
pub fn init(_spawner: Spawner) -> Board {
    if regs::read(SCC_ID, 0) != SCC_ID_AN386 {
        defmt::error!("not QEMU's mps2-an386 (SCC ID {=u32:#x})", regs::read(SCC_ID, 0));
        stop(EXIT_WRONG_MACHINE);
    }
    clock::start();
    // SAFETY: priorities are set before the lines are unmasked; their handlers are below.
    unsafe {
        let mut core = cortex_m::Peripherals::steal();
        for irq in [regs::TIMER0_IRQ, regs::DUALTIMER_IRQ] {
            core.NVIC.set_priority(Irq(irq), priority::TIME_DRIVER);
            NVIC::unmask(Irq(irq));
        }
    }
    let watchdog = clock::Watchdog::start(WATCHDOG_TIMEOUT_MS);
    keys::start();
    Board {
        step_timer: ModelStepTimer::new(),
        son: devices::NoPin,
        pen: devices::NoPwm,
        lights: [devices::NoPin, devices::NoPin],
        columns: [0, 1, 2, 3].map(keys::ModelColumn),
        rows: [0, 1, 2, 3].map(keys::ModelRow),
        watchdog,
        flash: devices::ModelFlash,
        host: uart::open(&uart::UART0_PORT, priority::HOST_LINK),
        second_link: uart::open(&uart::UART1_PORT, priority::HOST_LINK),
        lcd: St7920Lcd::new(devices::LcdBus, devices::NoPin, devices::NoPin, Delay, devices::LCD_SPI_HZ),
        card: {
            static CARD: static_cell::StaticCell<Card> = static_cell::StaticCell::new();
            card::ModelCard::place(CARD.uninit())
        },
    }
}

/// Hands the pulse engine to the step timer's interrupt, at the pulse priority.
pub fn start_pulses(timer: ModelStepTimer, steps: StepConsumer<'static>, machine: PulseWriter<'static>) {
    step_timer::start(timer, steps, machine, priority::PULSE, priority::PULSE_NEWS);
}

/// Wakes the pulse engine: the motion task queued steps.
pub fn kick_pulses() {
    step_timer::kick();
}

/// Starts the motion task's interrupt executor on its spare line, at the motion priority.
pub fn start_motion_executor() -> SendSpawner {
    // SAFETY: the priority is set before the executor unmasks the line.
    unsafe { cortex_m::Peripherals::steal().NVIC.set_priority(Irq(regs::MOTION_EXECUTOR_IRQ), priority::MOTION) };
    executor::MOTION_EXECUTOR.start(Irq(regs::MOTION_EXECUTOR_IRQ))
}

/// Every machine input's level: all idle.
pub fn read_inputs() -> InputLevels {
    servoplot::machine_io::inputs::LIMITS
}

/// Logs the pulses the step timer has emitted, per axis and direction.
pub fn log_pulses() {
    let [xh, xl, yh, yl] = step_timer::pulses_emitted();
    defmt::info!("step timer pulses: X {} with SIGN high, {} low; Y {} high, {} low", xh, xl, yh, yl);
}

/// Ends the run: QEMU exits with `status`.
fn stop(status: i32) -> ! {
    log_pulses();
    semihosting::process::exit(status)
}

unsafe extern "C" fn uart0_rx() {
    uart::UART0_PORT.on_receive();
}

unsafe extern "C" fn uart0_tx() {
    uart::UART0_PORT.on_transmit();
}

unsafe extern "C" fn uart1_rx() {
    uart::UART1_PORT.on_receive();
}

unsafe extern "C" fn uart1_tx() {
    uart::UART1_PORT.on_transmit();
}

unsafe extern "C" fn timer0() {
    clock::on_wrap();
}

unsafe extern "C" fn timer1() {
    step_timer::on_interrupt();
}

unsafe extern "C" fn dual_timer() {
    if clock::on_dual_timer() {
        defmt::error!("watchdog: not fed for {} ms; the board would reset", WATCHDOG_TIMEOUT_MS);
        stop(EXIT_WATCHDOG);
    }
}

unsafe extern "C" fn pulse_news() {
    step_timer::on_news();
}

unsafe extern "C" fn motion_executor() {
    // SAFETY: this line serves only as the motion executor's interrupt.
    unsafe { executor::MOTION_EXECUTOR.on_interrupt() }
}

unsafe extern "C" fn thread_pender() {
    executor::on_thread_pender();
}

unsafe extern "C" fn unexpected() {
    defmt::error!("unexpected interrupt");
    stop(EXIT_UNEXPECTED_INTERRUPT)
}

/// The model's interrupt vectors (cortex-m-rt's `device` feature, enabled through the F407's
/// HAL, takes them from here).
#[unsafe(link_section = ".vector_table.interrupts")]
#[unsafe(no_mangle)]
pub static __INTERRUPTS: [unsafe extern "C" fn(); regs::IRQ_LINES] = {
    let mut table: [unsafe extern "C" fn(); regs::IRQ_LINES] = [unexpected; regs::IRQ_LINES];
    table[regs::UART0_RX_IRQ as usize] = uart0_rx;
    table[regs::UART0_TX_IRQ as usize] = uart0_tx;
    table[regs::UART1_RX_IRQ as usize] = uart1_rx;
    table[regs::UART1_TX_IRQ as usize] = uart1_tx;
    table[regs::TIMER0_IRQ as usize] = timer0;
    table[regs::TIMER1_IRQ as usize] = timer1;
    table[regs::DUALTIMER_IRQ as usize] = dual_timer;
    table[regs::MOTION_EXECUTOR_IRQ as usize] = motion_executor;
    table[regs::THREAD_PENDER_IRQ as usize] = thread_pender;
    table[regs::PULSE_NEWS_IRQ as usize] = pulse_news;
    table
};

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panicked");
    stop(EXIT_PANIC)
}

crate::firmware::stack::hard_fault_entry!(hard_fault);

fn hard_fault() -> ! {
    defmt::error!("hard fault (a stack overflow runs off the bottom of RAM and faults)");
    stop(EXIT_HARD_FAULT)
}
