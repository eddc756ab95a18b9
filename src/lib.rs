//! servoplot: the portable core of a two-axis servo pen plotter.
//!
//! Everything that decides lives here and is `no_std`, free of any HAL, and unit-tested on the
//! host: geometry, interpolators, settings and jobs. The async loops in [`tasks`] only wait and
//! move values between the core and the pins; boards (in the firmware binary) wire them up.
#![no_std]

#[macro_use]
mod fmt;

pub mod geom;
pub mod interp;
pub mod job;
pub mod settings;
pub mod status;
