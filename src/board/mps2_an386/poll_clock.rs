//! The clock task polls are timed by: the model's free-running timer, [`PER_US`] counts a µs of
//! the F407's time (see `clock`).

pub use super::clock::CLOCKS_PER_US as PER_US;
pub use super::clock::poll_clock as now;
