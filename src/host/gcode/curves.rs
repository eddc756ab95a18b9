//! The plotter curve commands `$E`, `$O`, `$S` and `$F`: their words, turned into a drawing
//! [`Request`] for the builder.

use super::words::{WordIter, Words, compact, no_unused, positive};
use super::{Commands, GcodeState};
use crate::host::GrblError;
use crate::motion::drawing::{EllipseParams, Request, SineParams};
use crate::motion::job::Feed;
use crate::settings::Settings;

impl GcodeState {
    /// `$E`, `$O`, `$S` with their words in `body` (compacted, after the command letter): the
    /// line's curve, into `out`.
    pub(super) fn plotter_curve(
        &mut self,
        which: u8,
        body: &[u8],
        settings: &Settings,
        out: &mut Commands,
    ) -> Result<(), GrblError> {
        let (mut words, feed) = self.curve_words(body, settings)?;
        let start_deg = words.take(b'S').unwrap_or(0.0);
        match which {
            b'E' => {
                let a = positive(words.take(b'A'))?;
                let b = positive(words.take(b'B'))?;
                let sweep = words.take(b'W');
                no_unused(&words)?;
                self.ellipse([a, b], start_deg, sweep, feed, settings, out)
            }
            b'O' => {
                let r = positive(words.take(b'R'))?;
                let sweep = words.take(b'W');
                no_unused(&words)?;
                self.ellipse([r, r], start_deg, sweep, feed, settings, out)
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
                let sine =
                    SineParams { amplitude_mm: amplitude, omega_rad_per_mm: omega, phase_deg, length_mm: length };
                self.curve(Request::Sine(sine), feed, None, settings, out);
                Ok(())
            }
        }
    }

    /// The words of a curve command in `body` (compacted, after the command letter) but its F
    /// word, and its feed: the F word (mm/min, modal) or the current feed rate. Out of line: one
    /// copy for every curve command.
    #[inline(never)]
    fn curve_words(&mut self, body: &[u8], settings: &Settings) -> Result<(Words, Feed), GrblError> {
        let mut words = Words::default();
        for word in WordIter::new(body) {
            let (letter, value) = word?;
            words.insert(letter, value)?;
        }
        if let Some(f) = words.take(b'F') {
            if f < 0.0 {
                return Err(GrblError::NegativeValue);
            }
            self.feed_mm_per_min = Some(f);
        }
        Ok((words, Feed::MmPerMin(self.checked_feed(settings)?)))
    }

    /// `$E` / `$O`: the pen is at parametric angle `start_deg`; `sweep_deg` omitted is a full turn.
    fn ellipse(
        &self,
        semi_axes_mm: [f32; 2],
        start_deg: f32,
        sweep_deg: Option<f32>,
        feed: Feed,
        settings: &Settings,
        out: &mut Commands,
    ) -> Result<(), GrblError> {
        let sweep_deg = sweep_deg.unwrap_or(360.0);
        if !(sweep_deg.abs() <= 360.0) || !start_deg.is_finite() {
            return Err(GrblError::InvalidTarget);
        }
        if sweep_deg == 0.0 {
            return Ok(());
        }
        let [a_mm, b_mm] = semi_axes_mm;
        // Whole turns off (a start angle names a direction). Not `%`: f32 remainder links 650 B
        // of soft-float code for this one use.
        let start_deg = start_deg - 360.0 * crate::math::trunc(start_deg / 360.0);
        let ellipse = EllipseParams { a_mm, b_mm, start_deg, sweep_deg };
        self.curve(Request::Ellipse(ellipse), feed, None, settings, out);
        Ok(())
    }

    /// `$F X<x0> U<x1> [F] Y=<expr>`, the line's curve, into `out`; `rest` follows the `$` and
    /// is a suffix of `line`.
    pub(super) fn function(
        &mut self,
        line: &str,
        rest: &str,
        settings: &Settings,
        out: &mut Commands,
    ) -> Result<(), GrblError> {
        // The expression starts after the first `Y=` (spaces allowed around the `=`); a `Y` with
        // no `=` after it is a malformed value.
        // Indices below fall on ASCII bytes, so on char boundaries; `get` says so without a
        // panic path (and the string formatting a panic message would link).
        let equals_after = |at: usize| {
            let after = rest.get(at + 1..).unwrap_or("");
            let spaces = after.len() - after.trim_ascii_start().len();
            (after.as_bytes().get(spaces) == Some(&b'=')).then_some(at + 1 + spaces + 1)
        };
        let mut seen_y = false;
        let found = rest.bytes().enumerate().filter(|&(_, b)| b == b'Y' || b == b'y').find_map(|(at, _)| {
            seen_y = true;
            equals_after(at).map(|expr_at| (at, expr_at))
        });
        let (y_at, expr_at) =
            found.ok_or(if seen_y { GrblError::BadNumberFormat } else { GrblError::ValueWordMissing })?;
        // Up to a `;` comment.
        let expr_text = rest.get(expr_at..).unwrap_or("");
        let comment_at = expr_text.bytes().position(|b| b == b';').unwrap_or(expr_text.len());
        let expr_text = expr_text.get(..comment_at).unwrap_or(expr_text);
        let head = compact(rest.get(..y_at).unwrap_or(""), true)?;
        // `head` starts with the command letter F.
        let (mut words, feed) = self.curve_words(head.get(1..).unwrap_or(&[]), settings)?;
        let x0_mm = words.take(b'X').ok_or(GrblError::ValueWordMissing)?;
        let x1_mm = words.take(b'U').ok_or(GrblError::ValueWordMissing)?;
        no_unused(&words)?;
        let expr = crate::motion::expr::parse(expr_text).map_err(|e| {
            let column = line.len() - rest.len() + expr_at + e.pos + 1;
            GrblError::Expression { column: u16::try_from(column).unwrap_or(u16::MAX), kind: e.kind }
        })?;

        // Undefined at its first point: say why, with the x.
        expr.eval(x0_mm).map_err(|error| GrblError::FunctionUndefined { x_mm: x0_mm, error })?;
        let request = Request::Function { expr, x0_mm, x1_mm };
        self.curve(request, feed, None, settings, out);
        Ok(())
    }
}
