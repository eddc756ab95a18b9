//! The servoplot firmware on QEMU's mps2-an386, a Cortex-M4F with the STM32F407's 128 KiB of
//! RAM: the same image as the board's (`crate::firmware`: its tasks, executors, priorities,
//! stack and statics), with the model's UART, timers and memory behind it
//! (`board/mps2_an386`). CI runs it to see the whole firmware on the chip's instruction set.
#![no_std]
#![no_main]

#[path = "board/mps2_an386/mod.rs"]
mod board;
mod firmware;
