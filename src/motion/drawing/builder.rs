//! The builder's walk, a slice at a time: [`Builder`] sets a request up from the pen, walks a
//! copy of its curve [`advance`](Builder::advance) by advance, and once the copy has reached its
//! end (or failed) checks the lattice path against the ideal box and the travel.
//!
//! The walk is the only long part of a build: a curve of a hundred thousand steps takes a large
//! share of a second on the board. The front ends walk a slice of at most [`BUILD_SLICE_STEPS`]
//! at a time and let the other tasks run between slices, so the watchdog is fed and the host link
//! and the keypad stay live while a drawing is built. A slice is measured in steps' worth of
//! work: a step is worth one, and an X step of a sine or a function, where the curve is
//! evaluated, is worth as much more as the evaluations cost (see [`Builder::advance`]), so a
//! slice takes about the same time whatever it walks. Nothing here waits: a builder is plain
//! data, and what it walked ([`Slice`]) says how much work each slice was.
//!
//! The walk checks a function between its X steps too ([`Curve::check_between_columns`]), which
//! the motion's curve does not: that is its second evaluation per X step.
//!
//! A straight line is not walked: its path ends on its target, stays within the box of its two
//! ends, and takes as many steps as its method gives from the ends alone (`|dx| + |dy|` one axis
//! at a time, `max(|dx|, |dy|)` diagonally), so it is checked as soon as it is set up.

use super::{Bounds, DrawError, Drawing, IdealBox, LATTICE_SLACK_STEPS, Request, shape};
use crate::geom::{Axis, Point, Step};
use crate::motion::interp::{Curve, CurveError, Filled, Interpolator, Method, Shape, ShapeKind};
use crate::settings::Settings;

/// Steps' worth of work one slice of a build does at most (see [`Builder::advance`]). Counted on
/// the board (`cost/`, `--check-budgets` allows 2 ms): a slice of this many steps' worth takes
/// about 0.5 to 1.5 ms of the F407, the longest a function of general powers, which costs three
/// times what its operations weigh here; well within the 10 ms any task may hold the processor.
pub const BUILD_SLICE_STEPS: u32 = 1536;

/// Steps' worth of work an X step of a sine adds: it evaluates a sine, about four steps' walk.
const SINE_EVALUATION_STEPS: u32 = 4;

/// Evaluations of a function's expression per X step of the walk: at the column, and between
/// it and the next for the check between columns ([`Curve::check_between_columns`]).
pub(super) const FUNCTION_EVALUATIONS_PER_X_STEP: u32 = 2;

/// Steps the builder takes from its curve at a time, within a slice.
const TRACE_BATCH_STEPS: usize = 64;

/// Builds `request` from the pen at `start` in one go: `Ok(None)` when it is shorter than a step
/// and draws nothing, an error when it cannot be drawn as asked (nothing moves). A curve is
/// walked whole within the call: the front ends build with [`Builder`], a slice at a time.
pub fn build(request: &Request, start: Point, settings: &Settings) -> Result<Option<Drawing>, DrawError> {
    Builder::new(request, start, settings)?.map(|mut b| b.finish()).transpose()
}

/// A drawing of a shape already in steps (a benchmark's, say), checked as [`build`] checks a
/// request's, but for the ideal box, which a shape does not give.
pub fn from_shape(shape: Shape, start: Point, settings: &Settings) -> Result<Drawing, DrawError> {
    let mut builder = Builder::of_shape(shape, None, start, settings)?;
    builder.finish()
}

/// What one slice of a build walked, for a model of the time it takes, and whether the build is
/// done.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Slice {
    pub kind: ShapeKind,
    /// Operations of a function's expression ([`crate::motion::expr::Expr::op_count`]); 0 for the
    /// other curves.
    pub expr_ops: u8,
    /// Steps walked.
    pub steps: u32,
    /// How far X moved: for a sine or a function, whose X moves one way, its X steps; the walk
    /// evaluates a sine once per X step (a column, see [`crate::motion::interp::explicit`]), a function
    /// [`FUNCTION_EVALUATIONS_PER_X_STEP`] times.
    pub x_steps: u32,
    /// The walk is over: [`Builder::finish`] has the drawing, or why it is refused.
    pub done: bool,
}

/// A drawing being built; see the module documentation.
#[derive(Clone, Debug)]
pub struct Builder {
    shape: Shape,
    start: Point,
    /// The settings it is built with: the drawing's curve is set up from them once the walk is
    /// over, so a change of settings meanwhile does not reach it.
    settings: Settings,
    /// The ideal curve's box, where it is known.
    ideal: Option<IdealBox>,
    /// The copy of the curve being walked: the same steps as the curve kept.
    copy: Curve,
    /// The last lattice point walked, the box of those walked, and the steps walked.
    at: Point,
    bounds: Bounds,
    steps: u64,
    /// Once the walk is over: whether the path passed the checks.
    outcome: Option<Result<(), DrawError>>,
    /// The steps of the curve as the walk takes them (kept, rather than set up at every slice).
    batch: [Step; TRACE_BATCH_STEPS],
}

impl Builder {
    /// Sets `request` up from the pen at `start`: `Ok(None)` when it is shorter than a step and
    /// draws nothing, an error when it cannot be drawn as asked (nothing moves).
    pub fn new(request: &Request, start: Point, settings: &Settings) -> Result<Option<Builder>, DrawError> {
        let Some((shape, ideal)) = shape(request, start, settings)? else { return Ok(None) };
        if let Some(ideal) = ideal
            && !ideal.within(settings.travel_steps(), LATTICE_SLACK_STEPS)
        {
            // Beyond the travel by more than the lattice's slack: refused before any walk.
            return Err(DrawError::Travel);
        }
        Builder::of_shape(shape, ideal, start, settings).map(Some)
    }

    /// Sets `shape` up from the pen at `start`, `ideal` its box where known.
    fn of_shape(
        shape: Shape,
        ideal: Option<IdealBox>,
        start: Point,
        settings: &Settings,
    ) -> Result<Builder, DrawError> {
        let copy = Curve::new(&shape, start, settings)?.check_between_columns();
        let mut builder = Builder {
            shape,
            start,
            settings: *settings,
            ideal,
            copy,
            at: start,
            bounds: Bounds::at(start),
            steps: 0,
            outcome: None,
            batch: [Step::NONE; TRACE_BATCH_STEPS],
        };
        if let Shape::Straight { to } = builder.shape {
            // See the module documentation: a line is known from its ends, and checked as soon
            // as it is advanced.
            let d = to.offset_from(start);
            let (dx, dy) = (u64::from(d.x.unsigned_abs()), u64::from(d.y.unsigned_abs()));
            builder.steps = match settings.method {
                Method::Classic => dx + dy,
                Method::Diagonal => dx.max(dy),
            };
            builder.at = to;
            builder.bounds.add(to);
        }
        Ok(builder)
    }

    pub fn kind(&self) -> ShapeKind {
        self.shape.kind()
    }

    /// Where the drawing starts.
    pub fn start(&self) -> Point {
        self.start
    }

    /// Steps walked so far: all of the drawing's once the walk is over.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Once the walk is over: `Ok` when the path passed the checks, or why it is refused.
    pub fn verdict(&self) -> Option<Result<(), DrawError>> {
        self.outcome
    }

    /// Walks at most `max_steps` steps' worth more of the curve: a step is worth one, and an X
    /// step of a sine or a function, where the curve is evaluated, is worth as many more as the
    /// evaluations cost: [`SINE_EVALUATION_STEPS`] for a sine, one per operation of a
    /// function's expression and evaluation ([`FUNCTION_EVALUATIONS_PER_X_STEP`]). At least one
    /// step, whatever it is worth.
    pub fn advance(&mut self, max_steps: u32) -> Slice {
        self.walk(max_steps, None)
    }

    /// [`advance`](Self::advance), handing `at` every lattice point walked.
    pub fn advance_with(&mut self, max_steps: u32, at: &mut dyn FnMut(Point)) -> Slice {
        self.walk(max_steps, Some(at))
    }

    /// [`advance`](Self::advance), handing `at` (if any) every lattice point walked. One copy
    /// serves both: no call per step when there is no `at`.
    fn walk(&mut self, max_steps: u32, mut at: Option<&mut dyn FnMut(Point)>) -> Slice {
        let (expr_ops, evaluation) = match &self.shape {
            Shape::Function { expr, .. } => {
                let ops = u8::try_from(expr.op_count()).unwrap_or(u8::MAX);
                (ops, u32::from(ops) * FUNCTION_EVALUATIONS_PER_X_STEP)
            }
            Shape::Sine { .. } => (0, SINE_EVALUATION_STEPS),
            _ => (0, 0),
        };
        // A line is known from its ends: nothing to walk, it ends at once.
        let mut ended = matches!(self.shape, Shape::Straight { .. }).then_some(Ok(()));
        let steps_before = self.steps;
        let mut x_steps = 0u32;
        let mut left = max_steps;
        while self.outcome.is_none() && ended.is_none() && left > 0 {
            // No more steps than the work left allows, should every one move X.
            let most = (left / (1 + evaluation)).clamp(1, TRACE_BATCH_STEPS as u32);
            let batch = &mut self.batch[..most as usize];
            let Filled { steps, end, .. } = self.copy.fill(batch);
            // In locals: the loop runs once per step.
            let (mut p, mut min, mut max) = (self.at, self.bounds.min, self.bounds.max);
            let walked = &batch[..steps.min(batch.len())];
            let mut take = |step: &Step| {
                p = p.stepped(*step);
                (min.x, min.y, max.x, max.y) = (min.x.min(p.x), min.y.min(p.y), max.x.max(p.x), max.y.max(p.y));
                p
            };
            match &mut at {
                None => walked.iter().for_each(|step| {
                    take(step);
                }),
                Some(at) => walked.iter().for_each(|step| at(take(step))),
            }
            // A sine's or a function's X only moves one way: its X steps are how far it moved.
            let moved_x = p.x.abs_diff(self.at.x);
            (self.at, self.bounds) = (p, Bounds { min, max });
            self.steps += steps as u64;
            x_steps += moved_x;
            left = left.saturating_sub(steps as u32 + moved_x * evaluation);
            ended = end;
            if steps == 0 && ended.is_none() {
                // Every curve takes a step or ends on every fill: one that does neither cannot
                // be drawn.
                self.outcome = Some(Err(DrawError::BadParameter));
            }
        }
        if let Some(end) = ended
            && self.outcome.is_none()
        {
            self.outcome = Some(self.check(end));
        }
        Slice {
            kind: self.shape.kind(),
            expr_ops,
            steps: self.steps.wrapping_sub(steps_before) as u32,
            x_steps,
            done: self.outcome.is_some(),
        }
    }

    /// The drawing, checked; or why it is refused. Walks what is left of the curve first, in
    /// one go: after the slices have walked it all, nothing. The builder stays where it is (a
    /// big value is not moved to be finished), spent: its shape is the drawing's, and finishing
    /// it again is refused.
    pub fn finish(&mut self) -> Result<Drawing, DrawError> {
        while !self.advance(u32::MAX).done {}
        if let Some(Err(e)) = self.outcome {
            return Err(e);
        }
        let curve = Curve::new(&self.shape, self.start, &self.settings)?;
        self.outcome = Some(Err(DrawError::BadParameter));
        let shape = core::mem::replace(&mut self.shape, Shape::Straight { to: self.start });
        Ok(Drawing { curve, shape, start: self.start, end: self.at, bounds: self.bounds, steps: self.steps })
    }

    /// The checks once the walk has ended (`end`, as the curve said): the path did not fail,
    /// follows the ideal box and stays inside the travel.
    fn check(&self, end: Result<(), CurveError>) -> Result<(), DrawError> {
        let travel = self.settings.travel_steps();
        if let Err(error) = end {
            return Err(match error {
                // The ideal curve is inside the travel, its lattice path is not: it strays from
                // the curve.
                CurveError::Travel if self.ideal.is_some_and(|i| i.within(travel, 0.0)) => DrawError::TooFine,
                CurveError::Travel => DrawError::Travel,
                // Between two X steps the function strays further than they show.
                CurveError::Aliased => DrawError::TooFine,
                _ => {
                    // Where a function's x starts, for the x where it fails.
                    let x0_mm = match &self.shape {
                        Shape::Function { x0_mm, .. } => *x0_mm,
                        _ => 0.0,
                    };
                    let x_mm = x0_mm + self.settings.steps_to_mm(Axis::X, self.at.x - self.start.x);
                    DrawError::Fails { x_mm, error }
                }
            });
        }
        if let Some(ideal) = self.ideal
            && !ideal.follows(&self.bounds)
        {
            return Err(DrawError::TooFine);
        }
        if !self.bounds.within_travel(&self.settings) {
            return Err(DrawError::Travel);
        }
        Ok(())
    }
}
