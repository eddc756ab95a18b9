//! The LCD task: redraws the 122x32 screen when what it shows changes, at most every
//! `LCD_FRAME_MIN_MS`, at the lowest priority, and keeps the path drawn for the preview.
//!
//! Every frame is drawn whole from the menu and machine state (no stale digits), into the
//! driver's buffer, and only the visible region is sent to the controller (~14 ms at 600 kHz).
//! While a run is under way the task reads the pen's position every `PREVIEW_SAMPLE_MS` into
//! the run's [`Trail`]: the path of the steps emitted, read from the position the pulse engine
//! counts, which costs the motion and the pulses nothing.

use embassy_futures::select::select;
use embassy_time::{Duration, Timer};
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::SpiDevice;

use crate::machine::Machine;
use crate::pen::PenLift;
use crate::ui::layout::{SCREEN_HEIGHT_PX, SCREEN_WIDTH_PX};
use crate::ui::run::RunPath;
use crate::ui::screen::{self, Live};

/// Shortest time between two frames (10 Hz at most).
pub const LCD_FRAME_MIN_MS: u64 = 100;
/// While the pen moves, the position is redrawn this often even without other changes.
pub const LCD_POLL_MS: u64 = 200;
/// While a run is under way, the pen's position is read into the path this often: at 3000
/// mm/min, a point every millimetre.
pub const PREVIEW_SAMPLE_MS: u64 = 20;

/// A display the LCD task can draw on and show.
pub trait Lcd: DrawTarget<Color = BinaryColor> {
    /// Prepares the controller; called once before the first frame.
    fn init(&mut self);
    /// Sends what was drawn to the glass.
    fn show(&mut self);
}

/// An ST7920 in serial mode behind the `st7920` driver, showing its top-left 122x32 pixels.
pub struct St7920Lcd<SPI: SpiDevice, RST: OutputPin, D: DelayNs> {
    driver: st7920::ST7920<SPI, RST, RST>,
    delay: D,
}

impl<SPI: SpiDevice, RST: OutputPin, D: DelayNs> St7920Lcd<SPI, RST, D> {
    /// `cs` is the controller's chip select (RS pin, active high), driven by the driver.
    pub fn new(spi: SPI, rst: RST, cs: RST, delay: D) -> Self {
        St7920Lcd { driver: st7920::ST7920::new(spi, rst, Some(cs), false), delay }
    }
}

impl<SPI: SpiDevice, RST: OutputPin, D: DelayNs> embedded_graphics::geometry::OriginDimensions
    for St7920Lcd<SPI, RST, D>
{
    fn size(&self) -> embedded_graphics::geometry::Size {
        embedded_graphics::geometry::Size::new(SCREEN_WIDTH_PX, SCREEN_HEIGHT_PX)
    }
}

impl<SPI: SpiDevice, RST: OutputPin, D: DelayNs> DrawTarget for St7920Lcd<SPI, RST, D> {
    type Color = BinaryColor;
    type Error = core::convert::Infallible;

    fn draw_iter<I: IntoIterator<Item = embedded_graphics::Pixel<BinaryColor>>>(
        &mut self,
        pixels: I,
    ) -> Result<(), Self::Error> {
        self.driver.draw_iter(pixels)
    }
}

impl<SPI: SpiDevice, RST: OutputPin, D: DelayNs> Lcd for St7920Lcd<SPI, RST, D> {
    fn init(&mut self) {
        if self.driver.init(&mut self.delay).is_err() {
            warn!("LCD init failed");
        }
    }

    fn show(&mut self) {
        let r = self.driver.flush_region(0, 0, SCREEN_WIDTH_PX as u8, SCREEN_HEIGHT_PX as u8, &mut self.delay);
        if r.is_err() {
            warn!("LCD flush failed");
        }
    }
}

/// Draws the screen forever.
pub async fn run<L: Lcd>(machine: &Machine, mut lcd: L) -> ! {
    lcd.init();
    let mut shown = None;
    let mut last_frame_ms = 0u32;
    let mut drawn = RunPath::default();
    loop {
        let now_ms = super::now_ms();
        let status = machine.status();
        let settings = machine.settings();
        let menu = machine.menu();
        let running = drawn.follow(menu.run(), status.position, PenLift::of(&settings).draws(machine.pen()));
        let live = Live {
            now_ms,
            speed_mm_per_min: machine.speed_mm_per_min(&settings),
            work_offset_mm: machine.work_offset_mm(),
            drawn: Some(&drawn.path),
        };
        let view = screen::view(&menu, &status, &settings, &live);
        let since_frame_ms = now_ms.wrapping_sub(last_frame_ms);
        let mut wait_ms = if running { PREVIEW_SAMPLE_MS } else { LCD_POLL_MS };
        if shown.as_ref() != Some(&view) {
            if u64::from(since_frame_ms) >= LCD_FRAME_MIN_MS || shown.is_none() {
                let _ = screen::render(&view, menu.plan().map(|p| &p.path), Some(&drawn.path), &mut lcd);
                lcd.show();
                shown = Some(view);
                last_frame_ms = now_ms;
            } else {
                // Shown once the frame time has passed.
                wait_ms = wait_ms.min(LCD_FRAME_MIN_MS - u64::from(since_frame_ms));
            }
        }
        select(machine.changed(), Timer::after(Duration::from_millis(wait_ms))).await;
    }
}
