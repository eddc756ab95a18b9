//! What a panic does on the board: interrupts off, so no pulse timer or task runs on, a line in
//! the log, and the core stops on an undefined instruction; `probe-rs run` reports the stop with
//! a backtrace, which says where the panic came from.
//!
//! The panic's message and location are not read: reading them keeps every panic message's
//! formatting in the image, about 6 KB of flash.

#[panic_handler]
fn panic(_info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    defmt::error!("panicked: see the backtrace");
    cortex_m::asm::udf()
}
