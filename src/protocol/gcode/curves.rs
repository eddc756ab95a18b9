//! The plotter curve commands `$E`, `$O`, `$S` and `$F`: their words, their travel checks and
//! the [`Command::Curve`] each hands out, set up as its interpolator will set it up.

use super::motion::Conic;
use super::words::{WordIter, Words, compact, no_unused, positive};
use super::{CURVE_RADIUS_MAX_MM, Command, Commands, FUNCTION_CHECK_SAMPLES, GcodeState, check_travel};
use crate::geom::Point;
use crate::interp::sine::{self, sin_range};
use crate::interp::{RowRange, SineInterp, jump_limit_steps};
use crate::job::{Feed, Shape};
use crate::protocol::GrblError;
use crate::settings::Settings;

impl GcodeState {
    /// `$E`, `$O`, `$S` with their words in `body` (compacted, after the command letter).
    pub(super) fn plotter_curve(&mut self, which: u8, body: &[u8], settings: &Settings) -> Result<Commands, GrblError> {
        let mut words = Words::default();
        for word in WordIter::new(body) {
            let (letter, value) = word?;
            words.insert(letter, value)?;
        }
        let feed = self.curve_feed(&mut words, settings)?;
        let start_deg = words.take(b'S').unwrap_or(0.0);
        let command = match which {
            b'E' => {
                let a = positive(words.take(b'A'))?;
                let b = positive(words.take(b'B'))?;
                let sweep = words.take(b'W');
                no_unused(&words)?;
                self.ellipse([a, b], start_deg, sweep, feed, settings)?
            }
            b'O' => {
                let r = positive(words.take(b'R'))?;
                let sweep = words.take(b'W');
                no_unused(&words)?;
                self.ellipse([r, r], start_deg, sweep, feed, settings)?
            }
            _ => {
                let amplitude = words.take(b'A').ok_or(GrblError::ValueWordMissing)?;
                let omega = words.take(b'W').ok_or(GrblError::ValueWordMissing)?;
                let length = words.take(b'L').ok_or(GrblError::ValueWordMissing)?;
                let phase_deg = words.take(b'P').unwrap_or(0.0);
                // `S` means nothing to a sine; refuse it rather than ignore it.
                if start_deg != 0.0 {
                    return Err(GrblError::UnusedWords);
                }
                no_unused(&words)?;
                self.sine(amplitude, omega, phase_deg.to_radians(), length, feed, settings)?
            }
        };
        Ok(command.map(Commands::one).unwrap_or_default())
    }

    /// The F word of a curve command (mm/min, modal) or the current feed rate.
    fn curve_feed(&mut self, words: &mut Words, settings: &Settings) -> Result<Feed, GrblError> {
        if let Some(f) = words.take(b'F') {
            if f < 0.0 {
                return Err(GrblError::NegativeValue);
            }
            self.feed_mm_per_min = Some(f);
        }
        Ok(Feed::MmPerMin(self.checked_feed(settings)?))
    }

    /// `$E` / `$O`: the pen is at parametric angle `start_deg`; `sweep_deg` omitted is a full turn.
    fn ellipse(
        &mut self,
        semi_axes_mm: [f32; 2],
        start_deg: f32,
        sweep_deg: Option<f32>,
        feed: Feed,
        settings: &Settings,
    ) -> Result<Option<Command>, GrblError> {
        let sweep_deg = sweep_deg.unwrap_or(360.0);
        if !(sweep_deg.abs() <= 360.0) || !start_deg.is_finite() {
            return Err(GrblError::InvalidTarget);
        }
        if sweep_deg == 0.0 {
            return Ok(None);
        }
        let t0 = (start_deg % 360.0).to_radians();
        let sweep = sweep_deg.to_radians();
        let [a, b] = semi_axes_mm;
        let p = self.position_mm;
        let center = [p[0] - a * crate::math::cos(t0), p[1] - b * crate::math::sin(t0)];
        let end = if sweep_deg.abs() == 360.0 {
            p
        } else {
            [center[0] + a * crate::math::cos(t0 + sweep), center[1] + b * crate::math::sin(t0 + sweep)]
        };
        self.conic(Conic { center, semi_axes_mm, start_rad: t0, sweep_rad: sweep, end }, feed, settings)
    }

    /// `$S`: see [`Shape::Sine`].
    fn sine(
        &mut self,
        amplitude_mm: f32,
        omega_rad_per_mm: f32,
        phase_rad: f32,
        length_mm: f32,
        feed: Feed,
        settings: &Settings,
    ) -> Result<Option<Command>, GrblError> {
        let p = self.position_mm;
        let t1 = phase_rad + omega_rad_per_mm * length_mm;
        if !(t1.is_finite() && amplitude_mm.abs() <= CURVE_RADIUS_MAX_MM) {
            return Err(GrblError::InvalidTarget);
        }
        let s0 = crate::math::sin(phase_rad);
        let (lo, hi) = sin_range(phase_rad, t1);
        check_travel(settings, [p[0] + length_mm, p[1] + amplitude_mm * (lo - s0)])?;
        check_travel(settings, [p[0], p[1] + amplitude_mm * (hi - s0)])?;
        let spm = settings.steps_per_mm;
        let dx = crate::math::round(length_mm * spm[0]);
        if dx == 0.0 {
            return Ok(None);
        }
        let amplitude_steps = amplitude_mm * spm[1];
        let omega_rad_per_step = omega_rad_per_mm / spm[0];
        // The sine rises by at most |A·ω| steps from one X step to the next; above the jump
        // limit its interpolator would stop at the first chord that steep (as a function does
        // at a jump), so refuse it before anything moves.
        if !sine::fits_jump_limit(amplitude_steps, omega_rad_per_step, settings) {
            return Err(GrblError::InvalidTarget);
        }
        let max_jump_steps = jump_limit_steps(settings.max_jump_mm, spm[1]);
        let length_steps = dx as i32;
        // Set up as the motion will set it up (the travel is checked above, in millimetres);
        // its end is where the parser plans the pen.
        let sine = SineInterp::new(
            amplitude_steps,
            omega_rad_per_step,
            phase_rad,
            length_steps,
            max_jump_steps,
            RowRange::ANY,
            settings.method,
        )
        .map_err(|_| GrblError::InvalidTarget)?;
        let d = sine.end();
        // Within the travel checked above (±500 mm at 200 steps/mm at most).
        let to = Point::new(self.position.x + d.x, self.position.y + d.y);
        self.land_on(to, settings);
        let shape = Shape::Sine { amplitude_steps, omega_rad_per_step, phase_rad, length_steps };
        Ok(Some(Command::Curve { shape, feed, end: to }))
    }

    /// `$F X<x0> U<x1> [F] Y=<expr>`; `rest` follows the `$` and is a suffix of `line`.
    pub(super) fn function(&mut self, line: &str, rest: &str, settings: &Settings) -> Result<Commands, GrblError> {
        // The expression starts after the first `Y=` (spaces allowed around the `=`); a `Y` with
        // no `=` after it is a malformed value.
        let equals_after = |at: usize| {
            let after = &rest[at + 1..];
            let spaces = after.len() - after.trim_start().len();
            (after.as_bytes().get(spaces) == Some(&b'=')).then_some(at + 1 + spaces + 1)
        };
        let mut seen_y = false;
        let found = rest.bytes().enumerate().filter(|&(_, b)| b == b'Y' || b == b'y').find_map(|(at, _)| {
            seen_y = true;
            equals_after(at).map(|expr_at| (at, expr_at))
        });
        let (y_at, expr_at) =
            found.ok_or(if seen_y { GrblError::BadNumberFormat } else { GrblError::ValueWordMissing })?;
        let expr_text = rest[expr_at..].split(';').next().unwrap_or("");
        let head = compact(&rest[..y_at], true)?;
        let mut words = Words::default();
        // `head` starts with the command letter F.
        for word in WordIter::new(head.get(1..).unwrap_or(&[])) {
            let (letter, value) = word?;
            words.insert(letter, value)?;
        }
        let feed = self.curve_feed(&mut words, settings)?;
        let x0_mm = words.take(b'X').ok_or(GrblError::ValueWordMissing)?;
        let x1_mm = words.take(b'U').ok_or(GrblError::ValueWordMissing)?;
        no_unused(&words)?;
        let expr = crate::expr::parse(expr_text).map_err(|e| {
            let column = line.len() - rest.len() + expr_at + e.pos + 1;
            GrblError::Expression { column: u16::try_from(column).unwrap_or(u16::MAX), kind: e.kind }
        })?;

        let p = self.position_mm;
        check_travel(settings, [p[0] + (x1_mm - x0_mm), p[1]])?;
        let spm = settings.steps_per_mm;
        let dx = crate::math::round((x1_mm - x0_mm) * spm[0]);
        if dx == 0.0 {
            return Ok(Commands::default());
        }
        let f = |x: f32| expr.eval(x).map_err(|error| GrblError::FunctionUndefined { x_mm: x, error });
        let (x0, x1) = (x0_mm, x1_mm);
        let y0 = f(x0)?;
        let y_at_pen = |y: f32| [p[0], p[1] + (y - y0)];
        for k in 0..=FUNCTION_CHECK_SAMPLES {
            let x = x0 + (x1 - x0) * k as f32 / FUNCTION_CHECK_SAMPLES as f32;
            check_travel(settings, y_at_pen(f(x)?))?;
        }
        // The x the curve really ends at, on the step lattice.
        let x_end = x0 + dx / spm[0];
        let y_end = f(x_end)?;
        check_travel(settings, y_at_pen(y_end))?;
        let dy = crate::math::floor((y_end - y0) * spm[1] + 0.5);
        let to = Point::new(self.position.x + dx as i32, self.position.y + dy as i32);
        self.land_on(to, settings);
        let shape = Shape::Function { expr, x0_mm, x1_mm };
        Ok(Commands::one(Command::Curve { shape, feed, end: to }))
    }

    /// Ends a curve on the lattice point `to`.
    fn land_on(&mut self, to: Point, settings: &Settings) {
        self.sync_position(to, settings);
    }
}
