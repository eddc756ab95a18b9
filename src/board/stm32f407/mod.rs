//! The STM32F407VG board: clocks, the whole pin map, and the peripherals behind the firmware's
//! tasks (`crate::firmware`), with their interrupts at the firmware's priorities.
//!
//! Nothing else in the firmware names a pin or a peripheral instance. The pulse engine runs in
//! the step timer's update interrupt (TIM1, see `step_timer`); embassy-time's timer is TIM2; the
//! motion task's interrupt executor runs on UART5's vector and the thread-mode executor's
//! pender on UART4's (both unused as UARTs); the host links are USART2 and the USB port; the
//! servo task feeds the independent watchdog.
//!
//! | signal              | pin  | notes                                              |
//! |---------------------|------|----------------------------------------------------|
//! | X PULS / X SIGN     | PE9 / PE10  | TIM1 CH1 / GPIO, to the X driver's PULS+/SIGN+ |
//! | Y PULS / Y SIGN     | PE11 / PE12 | TIM1 CH2 / GPIO, to the Y driver's PULS+/SIGN+ |
//! | servo on (SON)      | PE13 | high once the tasks run; low asleep (`$SLP`), after a driver alarm, idle (`$1`), a fault |
//! | X / Y limit min     | PE4 / PE5 | inputs with pull-ups, switch to GND (normally open; `$5=1` normally closed) |
//! | X / Y limit max     | PE6 / PE7 | as the min switches                        |
//! | X / Y driver ALM    | PE8 / PE14 | inputs with pull-ups, from the drivers' ALM+ (ALM- to GND): open = alarm (`$207`) |
//! | run LED / buzzer    | PD12 / PB0 | high lights / sounds (`$214`, `$215`)          |
//! | pen servo (PWM)     | PC6  | TIM3 CH1, 50 Hz: the RC servo's signal (`$210`-`$213`) |
//! | e-stop              | PE15 | input with pull-up, normally closed button to GND: open = stop (`$208`) |
//! | keypad columns 1-4  | PD0-PD3 | open-drain outputs, driven low one at a time, else released |
//! | keypad rows 1-4     | PD8-PD11 | inputs with pull-ups                           |
//! | LCD SCLK (E)        | PB13 | SPI2 SCK                                           |
//! | LCD SID (R/W)       | PB15 | SPI2 MOSI                                          |
//! | LCD CS (RS)         | PB12 | active high, driven by the LCD driver              |
//! | LCD RST             | PB11 | PSB tied to GND selects serial mode                |
//! | host TX / RX        | PA2 / PA3 | USART2, 115200 8N1, to a USB-serial adapter   |
//! | USB DM / DP         | PA11 / PA12 | OTG FS, a host link's CDC-ACM serial port   |
//! | USB VBUS            | PA9  | OTG FS VBUS sensing, from the USB connector's VBUS |
//! | USB host power off  | PC0  | high: the Discovery board's STMPS2141 VBUS switch (enable active low) stays off |
//! | card SCK / MISO / MOSI | PB3 / PB4 / PB5 | SPI3, to the microSD socket (see `card`) |
//! | card CS             | PD6  | the card's chip select, active low             |
//! | card detect         | PD7  | input with pull-up, the socket's switch to GND: low while a card is in |

mod card;
mod chip;
mod flash;
mod inputs;
mod iwdg;
mod panic;
mod pen;
pub mod poll_clock;
mod spi_delay;
mod step_timer;
mod usb;

use core::convert::Infallible;

use defmt_rtt as _;
use embassy_executor::{SendSpawner, Spawner};
use embassy_stm32::gpio::OutputType;
use embassy_stm32::gpio::{Input, Level, Output as Pin, OutputOpenDrain, Pull, Speed};
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::mode::Blocking;
use embassy_stm32::peripherals::USART2;
use embassy_stm32::spi::{self, Spi};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::simple_pwm::PwmPin;
use embassy_stm32::usart::{self, BufferedUart, BufferedUartRx, BufferedUartTx};
use embassy_stm32::{Config, bind_interrupts, interrupt, pac};
use embassy_time::Delay;
use embedded_hal_bus::spi::ExclusiveDevice;
use servoplot::machine::PulseWriter;
use servoplot::machine_io::inputs::InputLevels;
use servoplot::motion::pulse::StepConsumer;
use servoplot::tasks::lcd::St7920Lcd;
use spi_delay::SpiDelay;
use static_cell::StaticCell;
use step_timer::Tim1StepTimer;

use crate::firmware::{executor, priority};

pub use iwdg::Watchdog;
pub use panic::safe_outputs;
pub use pen::PenPwm;

/// What the log calls the board.
pub const NAME: &str = "STM32F407VG at 168 MHz";

/// Crystal and core clock (see `clocks`).
const HSE_HZ: u32 = 8_000_000;
const SYSCLK_HZ: u32 = 168_000_000;
const _: () = assert!(SYSCLK_HZ == poll_clock::PER_US * 1_000_000);

/// APB1's clock, SYSCLK / 4 (see `clocks`), and what TIM2-TIM7 count at: twice that.
const APB1_HZ: u32 = SYSCLK_HZ / 4;
const APB1_TIMER_HZ: u32 = APB1_HZ * 2;

/// The thread-mode executor's pender: UART4's interrupt, unused as a UART.
pub const THREAD_PENDER_IRQ: u16 = pac::Interrupt::UART4 as u16;

/// Serial host link speed.
const HOST_BAUD: u32 = 115_200;
/// UART ring buffers. GRBL senders keep at most 128 unanswered bytes in flight (character
/// counting), so 256 never overflows; answers are short, status reports the longest.
const HOST_RX_BUFFER_BYTES: usize = 256;
const HOST_TX_BUFFER_BYTES: usize = 256;
/// ST7920 serial clock: the controller takes at most ~1 MHz at 5 V (datasheet t_scyc). SPI2
/// divides APB1's 42 MHz by a power of two (SPI_CR1.BR, RM0090 §28.5.1): by 64, 656 kHz. Asked
/// for exactly, embassy picks that divider (kernel clock / frequency = 64), and the LCD driver
/// paces its writes from this figure, so it must be the clock the link really runs at.
const LCD_SPI_HZ: u32 = APB1_HZ / 64;

bind_interrupts!(struct Irqs {
    USART2 => usart::BufferedInterruptHandler<USART2>;
});

#[interrupt]
unsafe fn UART5() {
    // SAFETY: UART5 serves only as the motion executor's interrupt.
    unsafe { executor::MOTION_EXECUTOR.on_interrupt() }
}

#[interrupt]
fn UART4() {
    executor::on_thread_pender();
}

/// Keypad pins: columns driven low or released (open-drain), rows read.
pub type Column = OutputOpenDrain<'static>;
pub type Row = Input<'static>;
/// SON, the run LED and the buzzer.
pub type Output = Pin<'static>;
/// The flash the store keeps its sectors in: sectors 10 and 11, erased and programmed at x32.
pub type Flash = flash::StoreFlash;
/// The host link on USART2.
pub type HostRx = BufferedUartRx<'static>;
pub type HostTx = BufferedUartTx<'static>;
/// The second host link: the USB port's CDC-ACM serial port.
pub type LinkRx = usb::UsbRx;
pub type LinkTx = usb::UsbTx;
/// The ST7920 on SPI2.
pub type Lcd =
    St7920Lcd<ExclusiveDevice<Spi<'static, Blocking, spi::mode::Master>, NoCs, SpiDelay>, Pin<'static>, Delay>;

/// The microSD card's slot, on SPI3.
pub type Card = card::SpiCard;

/// Everything the firmware's tasks drive, set up and idle.
pub struct Board {
    pub step_timer: Tim1StepTimer,
    pub son: Output,
    pub pen: PenPwm,
    /// The run LED and the buzzer.
    pub lights: [Output; 2],
    pub columns: [Column; 4],
    pub rows: [Row; 4],
    pub watchdog: Watchdog,
    pub flash: Flash,
    pub host: (HostRx, HostTx),
    pub second_link: (LinkRx, LinkTx),
    pub lcd: Lcd,
    /// In static storage, built in place (its block buffer is 512 bytes).
    pub card: &'static mut Card,
}

/// The LCD driver drives CS itself (active high); the SPI device's own CS is this no-op.
pub struct NoCs;

impl embedded_hal::digital::ErrorType for NoCs {
    type Error = Infallible;
}

impl embedded_hal::digital::OutputPin for NoCs {
    fn set_low(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

/// SYSCLK_HZ from the HSE_HZ crystal: 8 / 4 * 168 / 2 = 168 MHz; 48 MHz for USB from Q; APB1
/// 42 MHz, APB2 84 MHz.
fn clocks() -> Config {
    use embassy_stm32::rcc::*;
    let mut config = embassy_stm32::Config::default();
    config.rcc.hse = Some(Hse { freq: Hertz(HSE_HZ), mode: HseMode::Oscillator });
    config.rcc.pll_src = PllSource::HSE;
    config.rcc.pll = Some(Pll {
        prediv: PllPreDiv::DIV4,
        mul: PllMul::MUL168,
        divp: Some(PllPDiv::DIV2),
        divq: Some(PllQDiv::DIV7),
        divr: None,
    });
    config.rcc.ahb_pre = AHBPrescaler::DIV1;
    config.rcc.apb1_pre = APBPrescaler::DIV4;
    config.rcc.apb2_pre = APBPrescaler::DIV2;
    config.rcc.sys = Sysclk::PLL1_P;
    config
}

/// Sets the board up: clocks, the watchdog (running from here on), every pin and peripheral,
/// the host links (the USB device's task on `spawner`). Nothing moves: PULS low, SON low.
#[inline(never)]
pub fn init(spawner: Spawner) -> Board {
    let p = embassy_stm32::init(clocks());
    chip::flash_accelerator_on();
    chip::timers_stop_on_debug_halt();
    chip::usb_host_power_off(p.PC0);
    if pac::RCC.csr().read().wdgrstf() {
        defmt::warn!("reset by the watchdog: the pulses or the motion had stalled");
    }
    pac::RCC.csr().modify(|w| w.set_rmvf(true));
    let watchdog = Watchdog::start(p.IWDG);
    poll_clock::start();
    interrupt::TIM2.set_priority(Priority::from(priority::TIME_DRIVER));

    // Step/direction outputs, low (no pulse) until the pulse engine drives them.
    // PULS on TIM1's PWM outputs (low until a period ends with a pulse), SIGN on GPIO.
    let step_timer = Tim1StepTimer::new(
        p.TIM1,
        p.TIM4,
        PwmPin::new(p.PE9, OutputType::PushPull),
        PwmPin::new(p.PE11, OutputType::PushPull),
        [Pin::new(p.PE10, Level::Low, Speed::VeryHigh), Pin::new(p.PE12, Level::Low, Speed::VeryHigh)],
        inputs::InputPins::new(p.PE4, p.PE5, p.PE6, p.PE7, p.PE8, p.PE14, p.PE15),
    );
    // Servo on: low until the servo task, started with the pulse engine running, turns it on.
    let son = Pin::new(p.PE13, Level::Low, Speed::Low);
    // The pen servo: TIM3's 50 Hz PWM, no pulse until the servo task drives it (`$213`).
    let pen = PenPwm::new(p.TIM3, PwmPin::new(p.PC6, OutputType::PushPull), APB1_TIMER_HZ);
    // The run LED (the Discovery board's green LED) and the buzzer, off.
    let lights = [Pin::new(p.PD12, Level::Low, Speed::Low), Pin::new(p.PB0, Level::Low, Speed::Low)];
    // Keypad columns open-drain (GPIOx_OTYPER = 1, RM0090 §8.4.2): a column is driven low while
    // it is scanned and released otherwise, never driven high, so two keys pressed in one row
    // join the low column to a released one instead of shorting it to a high output. The rows'
    // pull-ups (DS8626: R_PU 30-50 kΩ) take them back high.
    let columns = [
        OutputOpenDrain::new(p.PD0, Level::High, Speed::Low),
        OutputOpenDrain::new(p.PD1, Level::High, Speed::Low),
        OutputOpenDrain::new(p.PD2, Level::High, Speed::Low),
        OutputOpenDrain::new(p.PD3, Level::High, Speed::Low),
    ];
    let rows = [
        Input::new(p.PD8, Pull::Up),
        Input::new(p.PD9, Pull::Up),
        Input::new(p.PD10, Pull::Up),
        Input::new(p.PD11, Pull::Up),
    ];

    static RX_BUF: StaticCell<[u8; HOST_RX_BUFFER_BYTES]> = StaticCell::new();
    static TX_BUF: StaticCell<[u8; HOST_TX_BUFFER_BYTES]> = StaticCell::new();
    let mut uart_config = usart::Config::default();
    uart_config.baudrate = HOST_BAUD;
    let uart = match BufferedUart::new(
        p.USART2,
        p.PA3,
        p.PA2,
        TX_BUF.init([0; HOST_TX_BUFFER_BYTES]),
        RX_BUF.init([0; HOST_RX_BUFFER_BYTES]),
        Irqs,
        uart_config,
    ) {
        Ok(uart) => uart,
        // Only a baud rate the clocks cannot make is refused: a fault of the build.
        Err(_) => defmt::panic!("USART2 cannot run at {} baud", HOST_BAUD),
    };
    // Below the pulse and motion executors: a burst of received bytes never delays a pulse.
    interrupt::USART2.set_priority(Priority::from(priority::HOST_LINK));
    let (tx, rx) = uart.split();
    let usb = usb::start(spawner, p.USB_OTG_FS, p.PA12, p.PA11, Priority::from(priority::HOST_LINK));

    let mut spi_config = spi::Config::default();
    spi_config.frequency = Hertz(LCD_SPI_HZ);
    spi_config.mode = spi::MODE_3;
    let spi_bus = Spi::new_blocking_txonly(p.SPI2, p.PB13, p.PB15, spi_config);
    let spi_dev = defmt::unwrap!(ExclusiveDevice::new(spi_bus, NoCs, SpiDelay));
    let lcd_cs = Pin::new(p.PB12, Level::Low, Speed::Low);
    let lcd_rst = Pin::new(p.PB11, Level::High, Speed::Low);
    let lcd = St7920Lcd::new(spi_dev, lcd_rst, lcd_cs, Delay, LCD_SPI_HZ);

    // The card: brought up at its slow clock when first looked at (see `card`).
    let card_config = card::spi_config(APB1_HZ / card::CARD_INIT_SPI_DIVIDER);
    let card_bus = Spi::new_blocking(p.SPI3, p.PB3, p.PB5, p.PB4, card_config);
    let card_cs = Pin::new(p.PD6, Level::High, Speed::VeryHigh);
    let card_spi = defmt::unwrap!(ExclusiveDevice::new(card_bus, card_cs, SpiDelay));
    static CARD: StaticCell<Card> = StaticCell::new();
    let card = card::SpiCard::place(CARD.uninit(), card_spi, Input::new(p.PD7, Pull::Up), APB1_HZ);

    Board {
        step_timer,
        son,
        pen,
        lights,
        columns,
        rows,
        watchdog,
        flash: flash::StoreFlash::new(p.FLASH),
        host: (rx, tx),
        second_link: usb,
        lcd,
        card,
    }
}

/// Hands the pulse engine to the step timer's interrupt, at the pulse priority.
pub fn start_pulses(timer: Tim1StepTimer, steps: StepConsumer<'static>, machine: PulseWriter<'static>) {
    step_timer::start(timer, steps, machine, Priority::from(priority::PULSE), Priority::from(priority::PULSE_NEWS));
}

/// Wakes the pulse engine: the motion task queued steps.
pub fn kick_pulses() {
    step_timer::kick();
}

/// Starts the motion task's interrupt executor on UART5's vector, at the motion priority.
pub fn start_motion_executor() -> SendSpawner {
    interrupt::UART5.set_priority(Priority::from(priority::MOTION));
    executor::MOTION_EXECUTOR.start(interrupt::UART5)
}

/// Every machine input's level (see `inputs`).
pub fn read_inputs() -> InputLevels {
    inputs::read()
}
