//! servoplot: the portable core of a two-axis servo pen plotter.
//!
//! Everything that decides lives here and is `no_std`, free of any HAL, and unit-tested on the
//! host: geometry, interpolators, the expression language, the speed planner, the serial
//! protocol, keypad decoding, the menu and its screen, settings and machine state. The async
//! loops in [`tasks`] only wait and move values between the core and the pins. The STM32 board
//! lives in the firmware binary; the simulated board and its command line (`sim`, host only)
//! live here so tests and benchmarks can drive it.
#![no_std]

#[cfg(not(target_os = "none"))]
extern crate std;

#[macro_use]
mod fmt;

pub mod card;
pub mod crc;
#[cfg(target_os = "none")]
pub mod critical;
pub mod decimal;
pub mod fields;
pub mod geom;
pub mod host;
pub mod machine;
pub mod machine_io;
pub mod math;
pub mod motion;
pub mod panel;
pub mod program;
pub mod settings;
pub mod status;
pub mod store;
pub mod tasks;
pub mod text;
pub mod unit;
pub mod wide;

#[cfg(not(target_os = "none"))]
pub mod sim;
