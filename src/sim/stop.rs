//! Ctrl-C at a live session: the first one asks the run to end, so the pictures of what was
//! drawn are still written; a second one ends the process at once, as Ctrl-C always does.

use std::sync::atomic::{AtomicBool, Ordering};

static ASKED: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    ASKED.store(true, Ordering::Relaxed);
}

/// From now on Ctrl-C (SIGINT) and SIGTERM ask the run to end; returns the flag they set.
pub fn on_ctrl_c() -> &'static AtomicBool {
    // SAFETY: the handler only stores to an atomic, which is async-signal-safe; `SA_RESETHAND`
    // puts the default action back for the next signal.
    unsafe {
        let mut action: libc::sigaction = core::mem::zeroed();
        action.sa_sigaction = on_signal as *const () as libc::sighandler_t;
        action.sa_flags = libc::SA_RESETHAND;
        libc::sigemptyset(&mut action.sa_mask);
        for signal in [libc::SIGINT, libc::SIGTERM] {
            libc::sigaction(signal, &action, core::ptr::null_mut());
        }
    }
    &ASKED
}
