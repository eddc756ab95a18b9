//! The simulator's animated picture of a session: every distinct LCD frame, in order, each
//! shown for the virtual time until the next, with the LCD's pixels where the frame has them.

use servoplot::sim;
use servoplot::sim::picture::{GIF_MAX_DELAY_CS, GIF_MIN_DELAY_CS, LCD_PNG_BORDER, LCD_PNG_SCALE, write_session_gif};

#[test]
fn the_session_gif_shows_every_frame_in_order_for_its_time() {
    let report = sim::run_keys("2 1 0 # 5 # #").unwrap();
    let frames = report.frames.clone();
    assert!(frames.len() > 3);
    let path = std::env::temp_dir().join(format!("servoplot-session-{}.gif", std::process::id()));
    write_session_gif(&frames, &path).unwrap();

    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options.read_info(std::fs::File::open(&path).unwrap()).unwrap();
    let mut decoded = 0;
    while let Some(image) = decoder.read_next_frame().unwrap() {
        let (t, frame) = &frames[decoded];
        let shown_cs = frames.get(decoded + 1).map_or(u64::MAX, |next| (next.0 - t) / 10_000);
        assert_eq!(u64::from(image.delay), shown_cs.clamp(GIF_MIN_DELAY_CS, GIF_MAX_DELAY_CS));
        // Every LCD pixel, sampled inside its square (past the border).
        let width = usize::from(image.width);
        for (y, row) in frame.pixels.iter().enumerate() {
            for (x, &lit) in row.iter().enumerate() {
                let (gx, gy) = ((x + LCD_PNG_BORDER) * LCD_PNG_SCALE + 1, (y + LCD_PNG_BORDER) * LCD_PNG_SCALE + 1);
                assert_eq!(image.buffer[gy * width + gx] == 1, lit, "frame {decoded} pixel ({x}, {y})");
            }
        }
        decoded += 1;
    }
    assert_eq!(decoded, frames.len());
    std::fs::remove_file(&path).unwrap();
}
