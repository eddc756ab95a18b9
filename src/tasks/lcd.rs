//! The LCD task: redraws the 122x32 screen when what it shows changes, at most every
//! `LCD_FRAME_MIN_MS`, at the lowest priority, and keeps the path drawn for the preview.
//!
//! Every frame is drawn whole from the menu and machine state (no stale digits), into the
//! driver's picture, and sent to the controller a slice at a time with a yield between slices
//! (the ST7920's paced writes take ~43 ms a picture: [`St7920Lcd`]). The menu is read in place,
//! in the [`Panel`] the keypad task changes: only while a frame is worked out and drawn into the
//! picture, never while the task waits or sends.
//! While a run is under way the task reads the pen's position every `PREVIEW_SAMPLE_MS` into
//! the run's [`Trail`](crate::panel::trail::Trail): the path of the steps emitted, read from the position the pulse engine
//! counts, which costs the motion and the pulses nothing.

pub mod st7920;

use embassy_futures::select::select3;
use embassy_futures::yield_now;
use embassy_time::{Duration, Timer};
use embedded_graphics::draw_target::DrawTarget;
use embedded_graphics::pixelcolor::BinaryColor;

use crate::card::CardSlot;
use crate::machine::Machine;
use crate::machine_io::pen::PenLift;
use crate::panel::run::RunPath;
use crate::panel::screen::{self, Live};
use crate::tasks::panel::Panel;

pub use st7920::St7920Lcd;

/// Shortest time between two frames (10 Hz at most).
pub const LCD_FRAME_MIN_MS: u64 = 100;
/// While the pen moves, the position is redrawn this often even without other changes.
pub const LCD_POLL_MS: u64 = 200;
/// While a run is under way, the pen's position is read into the path this often: at 3000
/// mm/min, a point every millimetre.
pub const PREVIEW_SAMPLE_MS: u64 = 20;

/// A display the LCD task can draw on and show.
pub trait Lcd: DrawTarget<Color = BinaryColor> {
    /// Takes the controller's start-up up to its next long wait and says how long that is, µs;
    /// `None` once the controller is ready for pictures.
    fn start(&mut self) -> Option<u32>;
    /// Sends the next slice of what was drawn to the glass (the first call begins a picture):
    /// `true` while slices of it remain to send.
    fn show_slice(&mut self) -> bool;
}

/// Draws the screen forever.
pub async fn run<L: Lcd>(machine: &Machine, panel: &Panel, card: &CardSlot<'_>, mut lcd: L) -> ! {
    while let Some(wait_us) = lcd.start() {
        Timer::after(Duration::from_micros(u64::from(wait_us))).await;
    }
    let mut shown = None;
    let mut last_frame_ms = 0u32;
    let mut drawn = RunPath::default();
    loop {
        let now_ms = super::now_ms();
        let status = machine.status();
        let settings = machine.settings();
        let since_frame_ms = now_ms.wrapping_sub(last_frame_ms);
        let frame_due = u64::from(since_frame_ms) >= LCD_FRAME_MIN_MS || shown.is_none();
        // The frame is worked out, and drawn into the picture if it is new and due, in one borrow.
        let draws = PenLift::of(&settings).draws(machine.pen());
        // The card file's picture follows the pen, and is read, in this one borrow.
        let (running, new_frame) = {
            let mut picture = card.picture_mut();
            if let Some(progress) = picture.as_mut().and_then(|p| p.progress.as_mut()) {
                progress.pen_at(status.position, draws);
            }
            panel.read(|menu| {
                let running = drawn.follow(menu.run(), status.position, draws);
                let live = Live {
                    now_ms,
                    speed_mm_per_min: machine.speed_mm_per_min(),
                    work_offset_mm: machine.work_offset_mm(),
                    drawn: Some(&drawn.path),
                    picture: picture.as_ref(),
                };
                let view = screen::view(menu, &status, &settings, &live);
                let new_frame = shown.as_ref() != Some(&view);
                if new_frame && frame_due {
                    let _ = screen::render(&view, menu.plan().map(|p| &p.path), live.drawn, live.picture, &mut lcd);
                    shown = Some(view);
                }
                (running, new_frame)
            })
        };
        let mut wait_ms = if running { PREVIEW_SAMPLE_MS } else { LCD_POLL_MS };
        if new_frame {
            if frame_due {
                show(&mut lcd).await;
                last_frame_ms = now_ms;
            } else {
                // Shown once the frame time has passed.
                wait_ms = wait_ms.min(LCD_FRAME_MIN_MS - u64::from(since_frame_ms));
            }
        }
        select3(machine.changed(), panel.changed(), Timer::after(Duration::from_millis(wait_ms))).await;
    }
}

/// Sends the picture drawn to the glass a slice at a time, letting every other task run before
/// each slice: no poll of this task both draws a picture and sends, nor sends more than a slice.
async fn show<L: Lcd>(lcd: &mut L) {
    loop {
        yield_now().await;
        if !lcd.show_slice() {
            break;
        }
    }
}
