//! The chip's and the Discovery board's fixed settings that no driver makes: the flash
//! accelerator, the timers frozen while a debugger halts the core, and the USB host power switch
//! held off. Each register written here is backed by the reference manual (RM0090 Rev 19), the
//! datasheet (DS8626) or the Discovery board's user manual (UM1472).

use embassy_stm32::Peri;
use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_stm32::pac;
use embassy_stm32::peripherals::PC0;

/// Turns on the flash accelerator: instruction prefetch, instruction cache and data cache.
///
/// embassy-stm32's clock setup writes FLASH_ACR with the wait states only (five at 168 MHz and
/// 2.7-3.6 V, RM0090 §3.5.1), so every fetch from flash would wait for them. The ART
/// accelerator (RM0090 §3.5.2) hides them: PRFTEN prefetches the next 128-bit line while the
/// current one executes, ICEN keeps 64 lines of instructions, DCEN 8 lines of literal pools.
/// RM0090 §3.9.1 (FLASH_ACR): ICRST and DCRST reset a cache and may be written only while that
/// cache is disabled, so the caches are reset first, while still off (as at reset), and then
/// turned on. Called after the clock setup, which set the latency these bits work with.
pub fn flash_accelerator_on() {
    let acr = pac::FLASH.acr();
    acr.modify(|w| {
        w.set_icen(false);
        w.set_dcen(false);
    });
    acr.modify(|w| {
        w.set_icrst(true);
        w.set_dcrst(true);
    });
    acr.modify(|w| {
        w.set_icrst(false);
        w.set_dcrst(false);
    });
    acr.modify(|w| {
        w.set_prften(true);
        w.set_icen(true);
        w.set_dcen(true);
    });
}

/// Stops, while a debugger holds the core halted (a breakpoint, or probe-rs catching a fault),
/// the timers that move the machine and the watchdog.
///
/// RM0090 §38.16.4 (DBGMCU_APB1_FZ) and §38.16.5 (DBGMCU_APB2_FZ): with DBG_TIMx_STOP set, the
/// timer's counter clock stops while the core is halted; without it a timer in PWM mode keeps
/// running its last period. So TIM1 (the step timer, whose periods end in PULS pulses) emits no
/// pulse and TIM3 (the pen servo's 50 Hz frame) holds its frame while halted; TIM4, which
/// counts TIM1's update events (to tell missed updates), stops with it. DBG_IWDG_STOP
/// stops the independent watchdog's counter: the board is not reset under a debugger.
pub fn timers_stop_on_debug_halt() {
    pac::DBGMCU.apb2fzr().modify(|w| w.set_tim1(true));
    pac::DBGMCU.apb1fzr().modify(|w| {
        w.set_tim3(true);
        w.set_tim4(true);
        w.set_iwdg(true);
    });
}

/// Keeps the Discovery board's USB host power switch off: the board is a USB device, and its
/// micro-USB socket must never feed 5 V to the cable.
///
/// UM1472 ("USB OTG supported", and the board's schematic): PC0 (OTG_FS_PowerSwitchOn) drives
/// the EN input of the STMPS2141 power switch that feeds 5 V to the socket's VBUS, and the
/// STMPS2141's enable is active low (its datasheet; the STMPS2151's is active high). PC0 is
/// therefore driven high, and stays so for as long as the firmware runs (the pin is never
/// released).
pub fn usb_host_power_off(pc0: Peri<'static, PC0>) {
    core::mem::forget(Output::new(pc0, Level::High, Speed::Low));
}
