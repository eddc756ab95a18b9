//! The pulse interrupt's handle, [`PulseWriter`]: the writes of the pulses' part of the machine
//! ([`pulse_side`](super::pulse_side)), and the machine's reads of that part.

use super::Machine;
use crate::geom::StepCmd;
use crate::machine_io::inputs::Trip;

writer_handle!(
    /// The pulse interrupt's handle: the writes of the pulses' part of the machine. Reads go
    /// through the machine it derefs to.
    PulseWriter
);

impl PulseWriter<'_> {
    /// Counts the pulses of `cmd`, emitted.
    #[inline(always)]
    pub fn emitted(self, cmd: StepCmd) {
        self.machine.pulse_side.emitted(cmd);
    }

    /// The step timer starts or stops.
    pub fn set_pulsing(self, on: bool) {
        self.machine.pulse_side.set_pulsing(on);
    }

    /// The pulse interrupt saw `trip`: as [`Machine::trip`], the pulse engine halted at once, the
    /// rest in the news.
    pub fn pulse_trip(self, trip: Trip) {
        if self.machine.halt(trip) {
            self.machine.pulse_side.tripped(trip);
        }
    }

    /// The pulse engine emitted everything queued and stopped.
    pub fn pulses_stopped(self) {
        self.machine.pulse_side.stopped();
    }

    /// The pulse engine found the queue empty while the motion was not at rest.
    pub fn count_underrun(self) {
        self.machine.pulse_side.count_underrun();
    }

    /// The step timer's interrupt came a whole period late or later: the timer repeated a
    /// period the engine then counted (see [`crate::motion::pulse`]).
    pub fn count_missed_update(self) {
        self.machine.pulse_side.count_missed_update();
    }
}

impl Machine {
    /// Hands the pulse interrupt's news on: below it (the board's interrupt for it, or the
    /// simulator's step timer after each period), never in it. It takes the news and posts what
    /// it says to the trips' mailbox and the signals, so any context below the pulse interrupt
    /// may call it; only the news interrupt does.
    pub fn deliver_pulse_news(&self) {
        let news = self.pulse_side.take_news();
        if let Some(trip) = news.trip {
            self.post_trip(trip);
        }
        if news.stopped {
            self.pulses_done.signal(());
            self.changed.signal(());
        }
        if news.underrun {
            warn!("step queue underrun: the motion task fell behind the pulses");
        }
        if news.missed_update {
            warn!("missed step timer update: the pulse interrupt came a whole period late");
        }
    }

    /// Steps emitted so far and the sum of their intervals (both wrap): after a trip, all there
    /// will be of what was queued.
    pub fn emitted_totals(&self) -> (u32, u32) {
        (self.pulse_side.emitted_steps(), self.pulse_side.emitted_ticks())
    }

    /// Step-queue underruns since power-on.
    pub fn underruns(&self) -> u32 {
        self.pulse_side.underruns()
    }

    /// Missed step timer updates since power-on.
    pub fn missed_updates(&self) -> u32 {
        self.pulse_side.missed_updates()
    }

    /// True while the step timer runs.
    pub fn pulsing(&self) -> bool {
        self.pulse_side.pulsing()
    }
}
