//! A keypad drawing being built: [`Building`] walks the curve a slice at a time (the keypad task
//! calls [`Building::advance`] between its scans of the keys) and samples, as the builder walks
//! it, the path the preview shows. Once it is walked, the menu checks it and shows its preview or
//! starts it ([`super::Menu::built`]); the job started is taken from it ([`Building::job`]).

use super::error::UiError;
use crate::geom::Point;
use crate::motion::drawing::{Builder, Request, Slice};
use crate::motion::job::{Feed, Job};
use crate::panel::trail::Trail;
use crate::settings::Settings;
use crate::status::Status;

/// A keypad drawing being built; see the module documentation.
pub struct Building {
    builder: Builder,
    /// The path walked so far, for the preview.
    path: Trail,
}

impl Building {
    /// Sets `request` up from the pen at `start`, into `slot` (emptied first). One shorter than
    /// a step draws nothing, and is refused as a zero.
    #[inline(never)]
    pub fn start(
        slot: &mut Option<Building>,
        request: &Request,
        start: Point,
        settings: &Settings,
    ) -> Result<(), UiError> {
        *slot = None;
        let builder = Builder::new(request, start, settings).map_err(UiError::Drawing)?.ok_or(UiError::Zero)?;
        let building = slot.insert(Building { builder, path: Trail::new() });
        building.path.sample(start, true);
        Ok(())
    }

    /// Walks at most `max_steps` steps' worth more of the curve (see
    /// [`Builder::advance`]).
    pub fn advance(&mut self, max_steps: u32) -> Slice {
        let path = &mut self.path;
        self.builder.advance_with(max_steps, &mut |p| {
            path.sample(p, true);
        })
    }

    /// Fails unless the drawing passed its checks and the pen is still where it was built from
    /// (the host link may have moved it meanwhile). Once walked.
    pub(super) fn check(&self, status: &Status) -> Result<(), UiError> {
        match self.builder.verdict() {
            Some(Ok(())) if self.builder.start() == status.position => Ok(()),
            Some(Err(e)) => Err(UiError::Drawing(e)),
            Some(Ok(())) | None => Err(UiError::Busy),
        }
    }

    /// Steps from start to end, once walked.
    pub(super) fn steps(&self) -> u64 {
        self.builder.steps()
    }

    /// The path walked, for the preview (taken: the building keeps none).
    pub(super) fn take_path(&mut self) -> Trail {
        core::mem::take(&mut self.path)
    }

    /// The job of the drawing at `feed`, once walked and checked (see [`MenuAction::Start`]);
    /// `None` for a drawing refused.
    ///
    /// [`MenuAction::Start`]: super::MenuAction::Start
    pub fn job(&mut self, feed: Feed) -> Option<Job> {
        self.builder.finish().ok().map(|drawing| Job::draw(drawing, feed))
    }
}
