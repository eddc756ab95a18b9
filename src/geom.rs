//! Machine geometry in integer steps: lattice points, single steps and travel directions.
//!
//! Everything inside the machine is counted in steps (`i32`); millimetres appear only at the
//! edges (protocol, menu, display) and are converted there with the per-axis steps/mm settings.

/// One of the two axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Axis {
    X,
    Y,
}

impl Axis {
    pub const ALL: [Axis; 2] = [Axis::X, Axis::Y];

    pub const fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
        }
    }

    /// `X` or `Y`. Out of line: seven places name an axis, none on the motion path.
    #[inline(never)]
    pub const fn name(self) -> &'static str {
        match self {
            Axis::X => "X",
            Axis::Y => "Y",
        }
    }
}

/// A lattice point, in steps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Point {
    pub x: i32,
    pub y: i32,
}

impl Point {
    pub const ORIGIN: Point = Point { x: 0, y: 0 };

    pub const fn new(x: i32, y: i32) -> Self {
        Point { x, y }
    }

    /// The point moved by one step.
    pub const fn stepped(self, step: Step) -> Self {
        Point { x: self.x + step.x as i32, y: self.y + step.y as i32 }
    }

    /// `self - origin`, saturating (points inside the machine never come near the limits).
    pub const fn offset_from(self, origin: Point) -> Point {
        Point { x: self.x.saturating_sub(origin.x), y: self.y.saturating_sub(origin.y) }
    }
}

/// One interpolation step: each axis moves by -1, 0 or +1.
///
/// `classic` interpolation moves one axis per step; `diagonal` may move both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Step {
    pub x: i8,
    pub y: i8,
}

impl Step {
    pub const NONE: Step = Step { x: 0, y: 0 };
    pub const XP: Step = Step { x: 1, y: 0 };
    pub const XN: Step = Step { x: -1, y: 0 };
    pub const YP: Step = Step { x: 0, y: 1 };
    pub const YN: Step = Step { x: 0, y: -1 };

    pub const fn new(x: i8, y: i8) -> Self {
        Step { x, y }
    }

    /// The axes the step moves and which way, as bits: bit 0 X backward, bit 1 Y backward, bit 2
    /// X forward, bit 3 Y forward (the order of the limit switches it runs towards, see
    /// `crate::machine_io::inputs`). A table lookup: a move of -1, 0 or +1 has the low bits 11, 00 or 01.
    pub const fn directions(self) -> u8 {
        const BITS: [u8; 16] = {
            let mut bits = [0; 16];
            let mut i = 0;
            while i < 16 {
                let (x, y) = (i & 3, i >> 2);
                bits[i] = (x == 3) as u8 | ((y == 3) as u8) << 1 | ((x == 1) as u8) << 2 | ((y == 1) as u8) << 3;
                i += 1;
            }
            bits
        };
        BITS[((self.x as u8 & 3) | ((self.y as u8 & 3) << 2)) as usize]
    }

    /// The direction of `v` on one axis: -1, 0 or +1.
    pub const fn sign(v: i32) -> i8 {
        if v > 0 {
            1
        } else if v < 0 {
            -1
        } else {
            0
        }
    }

    /// The component on `axis`.
    pub const fn on(self, axis: Axis) -> i8 {
        match axis {
            Axis::X => self.x,
            Axis::Y => self.y,
        }
    }

    /// True when both axes move.
    pub const fn is_diagonal(self) -> bool {
        self.x != 0 && self.y != 0
    }

    /// True when the step goes to a lattice neighbour (8-neighbourhood, not standing still).
    #[cfg(test)]
    pub const fn is_neighbour(self) -> bool {
        (self.x >= -1 && self.x <= 1 && self.y >= -1 && self.y <= 1) && !(self.x == 0 && self.y == 0)
    }
}

/// Direction of rotation of an arc, seen with X to the right and Y up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Rotation {
    Clockwise,
    CounterClockwise,
}

/// Step ticks per second: the step timer counts these, and `StepCmd` intervals, pulse widths,
/// direction set-up and hold are whole numbers of them. A quarter of a microsecond: a 2.5 µs
/// pulse at 200 kHz is 10 ticks high and 10 low, the step timer's prescaler stays whole on the
/// STM32F407 (TIM1 at 168 MHz, 42 clocks a tick), and its 16-bit counter still spans 16 ms a
/// period. The tasks' clock (embassy-time) is another, coarser one: convert through
/// [`TICKS_PER_US`].
pub const TICK_HZ: u32 = 4_000_000;

/// Step ticks per microsecond.
pub const TICKS_PER_US: u32 = {
    assert!(TICK_HZ.is_multiple_of(1_000_000));
    TICK_HZ / 1_000_000
};

/// `us` microseconds as whole step ticks, rounded up (a timing that must last at least `us`).
pub fn us_to_ticks(us: f32) -> u32 {
    crate::math::ceil(us * TICKS_PER_US as f32) as u32
}

/// One command for the pulse task: which axes step in which direction, and how long after the
/// previous pulse this one is due.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct StepCmd {
    pub step: Step,
    /// Time from the previous pulse to this one, in [`TICK_HZ`] ticks.
    pub interval_ticks: u32,
    /// `step.directions()`, worked out once where the command is made: the pulse engine's
    /// interrupt only loads it (it fits the bytes the step leaves free).
    directions: u8,
}

impl StepCmd {
    /// No step, no interval: a placeholder.
    pub const NONE: StepCmd = StepCmd::new(Step::NONE, 0);

    pub const fn new(step: Step, interval_ticks: u32) -> StepCmd {
        StepCmd { step, interval_ticks, directions: step.directions() }
    }

    /// [`Step::directions`] of the step.
    #[inline(always)]
    pub const fn directions(&self) -> u8 {
        self.directions
    }
}
