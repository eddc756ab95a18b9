//! The servoplot firmware. On the STM32F407 it runs the plotter; built for the host it is the
//! simulator: the same tasks on a simulated board with virtual time.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(target_os = "none")]
#[path = "board/stm32f407/mod.rs"]
mod board;
#[cfg(target_os = "none")]
mod firmware;

#[cfg(not(target_os = "none"))]
fn main() -> std::process::ExitCode {
    servoplot::sim::cli::main()
}
