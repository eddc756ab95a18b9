//! The host link's handle, [`HostWriter`]: the writes of the host side of the machine
//! ([`host_side`](super::host_side)), the host link's share of the run state and the pen's
//! orders, the signals it alone waits on, and the machine's reads of its part.

use core::sync::atomic::Ordering;

use super::Machine;
use crate::machine_io::pen::{Pen, PenDepth};
use crate::motion::overrides::{OverrideCommand, Overrides};
use crate::status::MotionFault;

writer_handle!(
    /// The host link's handle: the overrides, the work offset, check mode, sleep, the pen's
    /// depth and orders, and `$X`. Reads go through the machine it derefs to.
    HostWriter
);

impl HostWriter<'_> {
    /// Changes the overrides by `command` (an override byte from the host link); the motion task
    /// applies them to the motion in progress at its next refill.
    pub fn change_overrides(self, command: OverrideCommand) {
        self.set_overrides(self.machine.overrides().after(command));
    }

    /// Sets the overrides: [`Overrides::NONE`] after a reset.
    pub fn set_overrides(self, overrides: Overrides) {
        if self.machine.host_side.set_overrides(overrides) {
            self.machine.control_requested.signal(());
            self.machine.changed.signal(());
        }
    }

    /// Sets the work coordinate offset the parser plans with.
    pub fn set_work_offset_mm(self, offset_mm: [f32; 2]) {
        if self.machine.host_side.set_work_offset_mm(offset_mm) {
            self.machine.changed.signal(());
        }
    }

    /// Enters or leaves check mode (`$C`).
    pub fn set_check_mode(self, on: bool) {
        if self.machine.host_side.set_check_mode(on) {
            self.machine.changed.signal(());
        }
    }

    /// `$SLP` at rest: the servos go off (the board drops SON, see
    /// [`servos_on`](Machine::servos_on)) until [`wake`](Self::wake).
    pub fn sleep(self) {
        self.machine.host_side.set_asleep(true);
        // The axes are free until the reset.
        self.machine.position_lost.store(true, Ordering::Relaxed);
        self.machine.changed.signal(());
    }

    /// A reset after `$SLP`: the servos come back on and the machine is in alarm, since the free
    /// axes may have been moved (one of the [`alarm`](super::alarm)'s posters). Nothing when not
    /// asleep.
    pub fn wake(self) {
        if self.machine.host_side.set_asleep(false) {
            self.machine.raise_alarm(None);
        }
    }

    /// The card was lost while a file of it was plotted, and the machine has stopped: the alarm,
    /// until `$X` (one of the [`alarm`](super::alarm)'s posters).
    pub fn card_lost(self) {
        self.machine.raise_alarm(Some(MotionFault::CardLost));
    }

    /// `$X`: leaves the alarm, and lets pulses out again after a trip (handled by the motion
    /// task by now: the machine has stopped). One of the [`alarm`](super::alarm)'s posters.
    pub fn unlock(self) {
        self.machine.unlock();
    }

    /// Sends the pen to `pen` (`M3`, `M5`), only at rest, as the motion task does (see
    /// [`MotionWriter::set_pen`](super::MotionWriter::set_pen)).
    pub fn set_pen(self, pen: Pen) {
        self.machine.send_pen(pen);
    }

    /// How deep the pen goes down from now on (`M3 S…`); a pen down now goes there. Only at
    /// rest, as [`set_pen`](Self::set_pen).
    pub fn set_pen_depth(self, depth: PenDepth) {
        self.machine.host_side.set_pen_depth(depth);
        if self.machine.pen() == Pen::Down {
            self.machine.send_pen(Pen::Down);
        }
    }

    /// Waits until the settings may have changed since the last wait (to keep them in flash).
    pub async fn settings_changed(self) {
        self.machine.settings_changed.wait().await
    }

    /// Waits for the next fault (a curve stopped part way), to report it.
    pub async fn next_fault(self) -> MotionFault {
        self.machine.faults.wait().await
    }
}

impl Machine {
    /// The feed, rapid and spindle overrides in force.
    pub fn overrides(&self) -> Overrides {
        self.host_side.overrides()
    }

    /// The work coordinate offset the host link's parser plans with (machine = work + offset),
    /// mm.
    pub fn work_offset_mm(&self) -> [f32; 2] {
        self.host_side.work_offset_mm()
    }
}
