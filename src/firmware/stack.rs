//! The stack: where it is, and how deep it has ever been.
//!
//! flip-link places the stack at the bottom of RAM, below the statics, so an overflow runs off
//! the start of RAM into a HardFault instead of writing over them. cortex-m-rt's `paint-stack`
//! fills the whole stack with [`PAINT`] at reset, before anything runs; the deepest the stack has
//! ever been is where the paint stops, counted from the bottom.

/// The hard fault handler's entry, for a board: the stack pointer back to the top of the stack,
/// then `$handler`. A stack that ran off the bottom of RAM faults, and the fault's handler would
/// fault again on its first push and lock the core up (with the step timer still pulsing):
/// this entry gives the handler the whole stack again (what was on it no longer matters: the
/// handler stops the machine for good).
macro_rules! hard_fault_entry {
    ($handler:path) => {
        #[unsafe(naked)]
        #[unsafe(no_mangle)]
        unsafe extern "C" fn HardFault() -> ! {
            core::arch::naked_asm!("ldr r0, =_stack_start", "msr msp, r0", "b {handler}", handler = sym $handler)
        }
    };
}
pub(crate) use hard_fault_entry;

/// What cortex-m-rt paints the stack with (its `STACK_PAINT_VALUE`).
const PAINT: u32 = 0xCCCC_CCCC;

unsafe extern "C" {
    /// The top of the stack (its first push goes below it), from the linker script.
    static _stack_start: u32;
    /// The bottom of the stack: the lowest address it may reach.
    static _stack_end: u32;
}

/// Only the symbols' addresses are taken, never their values.
fn top() -> usize {
    core::ptr::addr_of!(_stack_start) as usize
}

fn bottom() -> usize {
    core::ptr::addr_of!(_stack_end) as usize
}

/// The stack's size, bytes.
pub fn size_bytes() -> u32 {
    (top() - bottom()) as u32
}

/// The most of the stack ever used, bytes: from the top down to the lowest word the paint is
/// gone from. Reads the unused part of the stack, a word at a time (about 4 instructions a word).
pub fn peak_bytes() -> u32 {
    let mut at = bottom();
    while at < top() {
        // SAFETY: `at` is a word-aligned address inside the stack's region of RAM (cortex-m-rt
        // aligns `_stack_end` to 4 bytes); reading it has no side effect.
        if unsafe { core::ptr::read_volatile(at as *const u32) } != PAINT {
            break;
        }
        at += 4;
    }
    (top() - at) as u32
}
