//! The LCD task: redraws the 122x32 screen when what it shows changes, at most every
//! `LCD_FRAME_MIN_MS`, at the lowest priority.
//!
//! Every frame is drawn whole from the menu and machine state (no stale digits), into the
//! driver's buffer, and only the visible region is sent to the controller (~14 ms at 600 kHz).

use embassy_futures::select::select;
use embassy_time::{Duration, Timer};
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::pixelcolor::BinaryColor;
use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::SpiDevice;

use crate::machine::Machine;
use crate::ui::layout::{SCREEN_HEIGHT_PX, SCREEN_WIDTH_PX};
use crate::ui::screen;

/// Shortest time between two frames (10 Hz at most).
pub const LCD_FRAME_MIN_MS: u64 = 100;
/// While the pen moves, the position is redrawn this often even without other changes.
pub const LCD_POLL_MS: u64 = 200;

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
    loop {
        let status = machine.status();
        let settings = machine.settings();
        let view = screen::view(&machine.menu(), &status, &settings);
        if shown.as_ref() != Some(&view) {
            let _ = screen::render(&view, &mut lcd);
            lcd.show();
            shown = Some(view);
            Timer::after(Duration::from_millis(LCD_FRAME_MIN_MS)).await;
        }
        select(machine.changed(), Timer::after(Duration::from_millis(LCD_POLL_MS))).await;
    }
}
