//! A run: the steps of one chunk of one block that the step generator times one way, at one
//! speed (a cruise) or by the acceleration rule (a ramp), with the figures it works out once for
//! the run.

/// Steps of one chunk of one block, timed one way.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Run {
    /// Steps in the run, and how many of them are still to emit.
    pub(super) steps: u32,
    pub left: u32,
    pub(super) pace: Pace,
    /// How far each of its steps advances along the ideal curve, mm (its chunk's `δ_mm`).
    pub(super) step_mm: f32,
}

#[derive(Clone, Copy, Debug)]
pub(super) enum Pace {
    /// Every step takes `ticks` and `frac` / 2³² ticks, the fractions carried over.
    Cruise { ticks: u32, frac: u32 },
    /// Each step at the speed the acceleration rule allows.
    Ramp(Ramp),
}

/// The figures of the acceleration rule for the steps of one chunk of one block.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ramp {
    /// A step at speed `w` takes `ticks_mm / w` ticks (its length in mm times the tick rate).
    pub(super) ticks_mm: f32,
    /// `2·a·δ`: what one step adds to (or takes from) `v²`.
    pub(super) gain: f32,
    /// `2·a`, for the distance left to brake.
    pub(super) two_a: f32,
    pub(super) cap2: f32,
    pub(super) exit2: f32,
    /// `v²` from rest, and where braking ends: the start rate for a hold or an abort, the cap
    /// when braking down to a lower cap (an override lowered it; the motion is not at rest then).
    pub(super) start2: f32,
    /// The step's length, nm, and the distance left in the block before the run, nm.
    pub(super) step_nm: u32,
    pub(super) left_nm: u32,
    /// A hold or an abort, or a speed above the cap: decelerate to `start2`.
    pub(super) braking: bool,
    pub(super) min_ticks: u32,
}

impl Run {
    pub const EMPTY: Run = Run { steps: 0, left: 0, pace: Pace::Cruise { ticks: 0, frac: 0 }, step_mm: 0.0 };

    /// Ends the run after the steps emitted so far: the next step is planned afresh.
    pub fn cut(&mut self) {
        self.steps -= self.left;
        self.left = 0;
    }
}
