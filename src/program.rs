//! A G-code program checked whole before the first move, and its picture: the pure parts of
//! plotting a file from a card.
//!
//! - [`check`]: a program, a line at a time, through the host link's own parser and drawing
//!   builder in check mode; the first refused line, the number of lines, the boxes of the motion
//!   and of the pen-down strokes against the travel, and the plot's time by the planner's own
//!   model. Resumable, each call's work bounded.
//! - [`preview`]: the drawing on the 122x32 LCD, the travel's outline and the strokes, kept in a
//!   bitmap of the screen's size (never the path); during a plot, the drawn part solid, the rest
//!   dotted, and the pen's place.
//!
//! It owns no card, file, task or pin: its caller reads the lines and draws the picture.

pub mod check;
pub mod preview;

pub use check::{CheckPlanner, PLAN_SLICE_STEPS, ProgramCheck, Progress, Refusal, Summary};

#[cfg(test)]
mod tests;
