//! The serial task: GRBL 1.1's line protocol on the host link.
//!
//! Two loops share the link. The receiver reads bytes as they arrive and acts on realtime bytes
//! (`?` `!` `~` 0x18 0x85) at once, so a status query or a feed hold is never stuck behind a line
//! waiting for room in the job queue; every other byte goes through a small pipe to the line
//! loop, which assembles lines, runs them through the G-code parser and answers `ok` or
//! `error:N` once their jobs are queued (back-pressure paces a streaming sender). A third loop
//! reports curves that stopped early. Answers are whole lines, never interleaved.
//!
//! Status reports carry the work offset (`|WCO:`, the active work coordinate system plus G92, as
//! the parser has it after its last line) as GRBL's do: in the first report after power-on, a
//! reset or a change, then once every [`REPORT_WCO_REFRESH_IDLE_COUNT`] reports
//! ([`REPORT_WCO_REFRESH_BUSY_COUNT`] while moving), so a sender shows work positions.
//!
//! Every line gets exactly one answer, in order, whatever the sender does. A sender that
//! ignores GRBL's flow control and sends more than the pipe holds while the machine is busy
//! loses whole lines, never parts of them: from the byte that found no room up to the end of a
//! line, the receiver drops the lines' bytes and counts their ends; once the line loop has
//! emptied the pipe it answers each of those lines `error:11` (not processed), and only then
//! does the receiver pass bytes on again, from the start of the next line.

use core::cell::Cell;
use core::future::Future;

use embassy_futures::join::join3;
use embassy_futures::select::{Either, select};
use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::mutex::Mutex;
use embassy_sync::pipe::Pipe;
use embassy_sync::signal::Signal;
use embassy_time::{Duration, Timer};
use embedded_io_async::{Read, Write};
use heapless::String;

use crate::job::{Control, Job};
use crate::machine::{Machine, PlanEpoch, Stale};
use crate::planner::PLANNER_SEGMENTS;
use crate::protocol::framing::{LineAssembler, LineEvent, Realtime, realtime};
use crate::protocol::{Command, GcodeState, GrblError, Report, report};
use crate::settings::Settings;
use crate::status::RunState;

/// Bytes between the receiver and the line loop. GRBL senders keep at most 128 unanswered bytes
/// in flight, so this never fills for them; it also holds a terminal paste of about 50 lines
/// beyond what the machine has room for. Beyond that, see the module documentation.
pub const SERIAL_PIPE_BYTES: usize = 1024;
/// What a sender may assume it can have in flight (reported by `$I`).
pub const SERIAL_RX_WINDOW_BYTES: usize = 128;
/// Longest answer to one line: `$$` lists every setting (about 300 bytes).
pub const SERIAL_ANSWER_MAX_BYTES: usize = 512;
/// How long a byte may wait for room in the pipe before it is dropped: the line loop drains
/// the pipe far faster unless it is waiting for the machine.
pub const SERIAL_PIPE_WAIT_MS: u64 = 20;
/// Bytes taken from the UART, or from the pipe, at a time.
pub const SERIAL_CHUNK_BYTES: usize = 32;
/// After a UART read error (noise, overrun), the receiver waits this long before reading on.
pub const SERIAL_ERROR_BACKOFF_MS: u64 = 1;
/// How often waits for the machine to come to rest (G4, M0, M2) look again.
pub const SERIAL_IDLE_POLL_MS: u64 = 5;
/// A status report carries the work offset (`|WCO:`) once every this many reports while the
/// machine moves or holds, GRBL's count...
pub const REPORT_WCO_REFRESH_BUSY_COUNT: u8 = 30;
/// ...and once every this many otherwise; always in the first report after the offset changed,
/// after power-on and after a reset.
pub const REPORT_WCO_REFRESH_IDLE_COUNT: u8 = 10;

type Answer = String<SERIAL_ANSWER_MAX_BYTES>;

/// State the three loops share; all run on one executor, so plain cells do.
struct Link<'m, W> {
    machine: &'m Machine,
    tx: Mutex<NoopRawMutex, W>,
    bytes: Pipe<NoopRawMutex, SERIAL_PIPE_BYTES>,
    /// Feed rate of the motion in progress, for status reports.
    feed_mm_per_min: Cell<f32>,
    /// The parser's work offset (active work coordinate system + G92) as of its last line, for
    /// status reports.
    work_offset_mm: Cell<[f32; 2]>,
    /// Status reports still to go without `|WCO:`; 0: the next one has it.
    reports_until_wco: Cell<u8>,
    /// Lines dropped for want of room in the pipe; see the module documentation.
    dropped: Dropped,
    /// Resets received and not yet met by the line loop: bytes before them are dropped.
    resets_pending: Cell<u32>,
    /// Cancels a line waiting for the machine when a reset arrives.
    reset: Signal<NoopRawMutex, ()>,
}

/// Speaks GRBL on the host link forever.
pub async fn run<R: Read, W: Write>(machine: &Machine, rx: R, tx: W) -> ! {
    let link = Link {
        machine,
        tx: Mutex::new(tx),
        bytes: Pipe::new(),
        feed_mm_per_min: Cell::new(0.0),
        work_offset_mm: Cell::new([0.0; 2]),
        reports_until_wco: Cell::new(0),
        dropped: Dropped::default(),
        resets_pending: Cell::new(0),
        reset: Signal::new(),
    };
    link.send(report::welcome).await;
    join3(receive(&link, rx), lines(&link), faults(&link)).await;
    unreachable!("the serial loops never end")
}

impl<W: Write> Link<'_, W> {
    /// Writes one answer, built by `write`, as a whole.
    async fn send(&self, write: impl FnOnce(&mut Answer) -> core::fmt::Result) {
        let mut answer = Answer::new();
        if write(&mut answer).is_err() {
            // Every answer fits by construction; should one not, say so rather than cut it.
            answer.clear();
            let _ = report::message(&mut answer, "answer too long");
        }
        let mut tx = self.tx.lock().await;
        if tx.write_all(answer.as_bytes()).await.is_err() || tx.flush().await.is_err() {
            warn!("host link write failed");
        }
    }

    async fn status_report(&self) {
        let status = self.machine.status();
        let settings = self.machine.settings();
        let feed = if status.state == RunState::Idle { 0.0 } else { self.feed_mm_per_min.get() };
        let work_offset = match self.reports_until_wco.get() {
            0 => {
                let busy = matches!(status.state, RunState::Run | RunState::Hold | RunState::Jog);
                let every = if busy { REPORT_WCO_REFRESH_BUSY_COUNT } else { REPORT_WCO_REFRESH_IDLE_COUNT };
                self.reports_until_wco.set(every - 1);
                Some(self.work_offset_mm.get())
            }
            n => {
                self.reports_until_wco.set(n - 1);
                None
            }
        };
        self.send(|a| report::status(a, &status, &settings, feed, work_offset)).await;
    }

    /// Takes the parser's work offset after a line or a reset; the next status report carries it
    /// if it changed.
    fn note_work_offset(&self, offset_mm: [f32; 2]) {
        if self.work_offset_mm.replace(offset_mm) != offset_mm {
            self.reports_until_wco.set(0);
        }
    }

    /// Runs `work` unless a reset comes first (or is already on its way).
    async fn unless_reset<T>(&self, work: impl Future<Output = T>) -> Result<T, Unfinished> {
        if self.resets_pending.get() > 0 {
            return Err(Unfinished::Reset);
        }
        match select(work, self.reset.wait()).await {
            Either::First(t) => Ok(t),
            Either::Second(()) => Err(Unfinished::Reset),
        }
    }

    /// Waits until nothing is queued or moving.
    async fn machine_at_rest(&self) {
        while !self.machine.is_idle() {
            Timer::after(Duration::from_millis(SERIAL_IDLE_POLL_MS)).await;
        }
    }

    /// Waits until nothing is queued, planned or moving, held or not: the position is final.
    async fn machine_stopped(&self) {
        while !self.machine.stopped() {
            Timer::after(Duration::from_millis(SERIAL_IDLE_POLL_MS)).await;
        }
    }

    /// Passes a byte of a line to the line loop. When the pipe stays full for
    /// `SERIAL_PIPE_WAIT_MS` (a sender ignoring GRBL's flow control while the line loop waits
    /// for the machine) the byte is dropped rather than waited for, so realtime bytes behind it
    /// are still read, and its line with it; see the module documentation.
    async fn line_byte(&self, byte: u8) {
        let d = &self.dropped;
        // An LF right after a CR completes the CRLF pair: no line end of its own.
        let pair = byte == b'\n' && d.after_cr.get();
        let cr_dropped = d.cr_dropped.replace(false);
        d.after_cr.set(byte == b'\r');
        if pair && (cr_dropped || d.active.get()) {
            return;
        }
        if !d.active.get() {
            let wait = Timer::after(Duration::from_millis(SERIAL_PIPE_WAIT_MS));
            if let Either::First(()) = select(self.bytes.write_all(&[byte]), wait).await {
                return;
            }
            if pair {
                // Its CR ended the line already: nothing is lost.
                return;
            }
            d.active.set(true);
            self.send(|a| report::message(a, "Receive buffer full: lines dropped, each answered error:11")).await;
        }
        d.cr_dropped.set(byte == b'\r');
        if byte == b'\n' || byte == b'\r' {
            d.lines.set(d.lines.get() + 1);
            d.mid_line.set(false);
            d.counted.signal(());
        } else {
            d.mid_line.set(true);
        }
    }
}

/// The receiver's count of lines dropped for want of room in the pipe.
#[derive(Default)]
struct Dropped {
    /// Bytes of lines are dropped, not passed on, until the line loop has answered the lines
    /// dropped so far and the receiver stands at the start of a line.
    active: Cell<bool>,
    /// Ends of dropped lines, not yet answered.
    lines: Cell<u32>,
    /// The last line byte dropped was not a line end: a dropped line is still under way.
    mid_line: Cell<bool>,
    /// The last line byte, passed on or dropped, was a CR.
    after_cr: Cell<bool>,
    /// The last line byte was a CR, dropped: an LF after it completes a dropped line.
    cr_dropped: Cell<bool>,
    /// Wakes the line loop when a dropped line's end is counted.
    counted: Signal<NoopRawMutex, ()>,
}

impl Dropped {
    /// Forgets every dropped line (a reset: lines before it get no answer).
    fn clear(&self) {
        self.active.set(false);
        self.lines.set(0);
        self.mid_line.set(false);
        self.after_cr.set(false);
        self.cr_dropped.set(false);
    }

    /// The dropped lines to answer now, if the line loop has taken every byte that came before
    /// them; passing bytes on starts again if no dropped line is under way.
    fn take(&self, pipe_empty: bool) -> u32 {
        if !self.active.get() || !pipe_empty {
            return 0;
        }
        let n = self.lines.replace(0);
        if !self.mid_line.get() {
            self.active.set(false);
        }
        n
    }
}

/// Reads the link: realtime bytes act now, the rest go to the line loop in order.
async fn receive<R: Read, W: Write>(link: &Link<'_, W>, mut rx: R) -> ! {
    let mut buf = [0u8; SERIAL_CHUNK_BYTES];
    loop {
        let n = match rx.read(&mut buf).await {
            Ok(n) => n,
            Err(_) => {
                warn!("host link read error");
                Timer::after(Duration::from_millis(SERIAL_ERROR_BACKOFF_MS)).await;
                continue;
            }
        };
        for &byte in &buf[..n] {
            match realtime(byte) {
                Some(Realtime::StatusQuery) => link.status_report().await,
                Some(Realtime::FeedHold) => link.machine.request(Control::Hold),
                Some(Realtime::CycleStart) => link.machine.request(Control::Resume),
                Some(Realtime::JogCancel) if link.machine.run_state() == RunState::Jog => {
                    link.machine.request(Control::Abort)
                }
                Some(Realtime::Reset) => {
                    link.machine.request(Control::Abort);
                    // Like GRBL, everything received before the reset is dropped: the line loop
                    // discards bytes up to this marker and resets the parser when it meets it.
                    link.resets_pending.set(link.resets_pending.get() + 1);
                    link.reset.signal(());
                    link.dropped.clear();
                    link.bytes.write_all(&[byte]).await;
                }
                Some(Realtime::JogCancel | Realtime::Unsupported(_)) => {}
                None => link.line_byte(byte).await,
            }
        }
    }
}

/// Why a line was left unfinished: not all of its commands were carried out.
enum Unfinished {
    /// The line was refused: answer `error:N`.
    Error(GrblError),
    /// A reset came: the line gets no answer (the banner follows).
    Reset,
}

/// Assembles, parses and carries out lines, answering each.
async fn lines<W: Write>(link: &Link<'_, W>) -> ! {
    let machine = link.machine;
    let mut assembler = LineAssembler::new();
    let mut gcode = GcodeState::new();
    let mut buf = [0u8; SERIAL_CHUNK_BYTES];
    // The epoch the parser plans in: after an abort, its planned position is stale until the
    // machine stops.
    let mut epoch = machine.plan_epoch();
    loop {
        let dropped = link.dropped.take(link.bytes.is_empty());
        if dropped > 0 {
            // Lines whose bytes found no room: the partial one in the assembler is the first.
            assembler.clear();
            for _ in 0..dropped {
                link.send(|a| report::error(a, GrblError::LineOverflow)).await;
            }
            continue;
        }
        let n = match select(link.bytes.read(&mut buf), link.dropped.counted.wait()).await {
            Either::First(n) => n,
            Either::Second(()) => continue,
        };
        for &byte in &buf[..n] {
            if byte == 0x18 {
                link.resets_pending.set(link.resets_pending.get().saturating_sub(1));
                assembler.clear();
                link.machine_stopped().await;
                link.reset.reset();
                gcode.reset(machine.position(), &machine.settings());
                link.note_work_offset(gcode.work_offset_mm());
                link.reports_until_wco.set(0);
                epoch = machine.plan_epoch();
                link.send(report::welcome).await;
                continue;
            }
            if link.resets_pending.get() > 0 {
                continue;
            }
            let result = match assembler.push(byte) {
                None => continue,
                Some(LineEvent::Line(line)) => {
                    if machine.plan_epoch() != epoch {
                        // An abort (keypad, jog cancel, a curve stopped part way) dropped what
                        // was planned: plan on from where the pen stops.
                        if link.unless_reset(link.machine_stopped()).await.is_err() {
                            continue;
                        }
                        epoch = machine.plan_epoch();
                        gcode.sync_position(machine.position(), &machine.settings());
                    }
                    let settings = machine.settings();
                    if machine.is_idle() {
                        // The keypad, an abort or a curve that stopped early may have moved the
                        // pen elsewhere than the parser planned.
                        gcode.sync_position(machine.position(), &settings);
                    }
                    match gcode.execute(line, &settings, machine.run_state()) {
                        Ok(commands) => {
                            // A refused line changed no offset.
                            link.note_work_offset(gcode.work_offset_mm());
                            let mut r = Ok(());
                            for command in commands {
                                r = carry_out(link, &gcode, &settings, command, epoch).await;
                                if r.is_err() {
                                    break;
                                }
                            }
                            r
                        }
                        Err(e) => Err(Unfinished::Error(e)),
                    }
                }
                Some(other) => Err(Unfinished::Error(other.error().unwrap_or(GrblError::ExpectedCommandLetter))),
            };
            match result {
                Ok(()) => link.send(report::ok).await,
                Err(Unfinished::Error(e)) => link.send(|a| report::error(a, e)).await,
                Err(Unfinished::Reset) => {}
            }
        }
    }
}

/// Carries out one command of a parsed line.
async fn carry_out<W: Write>(
    link: &Link<'_, W>,
    gcode: &GcodeState,
    settings: &Settings,
    command: Command,
    epoch: PlanEpoch,
) -> Result<(), Unfinished> {
    let machine = link.machine;
    match command {
        Command::Job(job) => queue(link, job, epoch).await?,
        Command::Dwell { ms } => {
            link.unless_reset(async {
                link.machine_at_rest().await;
                Timer::after(Duration::from_millis(u64::from(ms))).await;
            })
            .await?
        }
        Command::Pause => {
            link.unless_reset(link.machine_at_rest()).await?;
            machine.request(Control::Hold);
        }
        Command::ProgramEnd => {
            link.unless_reset(link.machine_at_rest()).await?;
            link.send(|a| report::message(a, "Pgm End")).await;
        }
        Command::SetSetting { id, value } => {
            machine
                .update_settings(|s| s.set(id, value))
                .map_err(|_| Unfinished::Error(GrblError::InvalidStatement))?;
        }
        Command::RestoreSettings => machine.update_settings(|s| *s = Settings::default()),
        Command::Report(kind) => {
            link.send(|a| match kind {
                Report::Help => report::help(a),
                Report::Settings => report::settings(a, settings),
                Report::ParserState => report::parser_state(a, gcode, settings),
                Report::Parameters => report::parameters(a, gcode),
                Report::BuildInfo => report::build_info(a, PLANNER_SEGMENTS, SERIAL_RX_WINDOW_BYTES),
            })
            .await
        }
        Command::Unlock => {
            if machine.run_state() == RunState::Alarm {
                machine.set_run_state(RunState::Idle);
            }
            link.send(|a| report::message(a, "Caution: Unlocked")).await;
        }
    }
    Ok(())
}

/// Hands a job, planned in `epoch`, to the motion task, waiting for room: the `ok` goes out
/// once it is queued. A reset while it waits drops the job silently (the banner follows); an
/// abort before it is queued drops it with `error:9`, since it was planned from a point the pen
/// will not reach.
async fn queue<W: Write>(link: &Link<'_, W>, job: Job, epoch: PlanEpoch) -> Result<(), Unfinished> {
    let feed = job.feed;
    link.unless_reset(link.machine.submit(job, epoch)).await?.map_err(|Stale| Unfinished::Error(GrblError::Locked))?;
    if let crate::job::Feed::MmPerMin(f) = feed {
        link.feed_mm_per_min.set(f);
    }
    Ok(())
}

/// Pushes an alarm to the host when a curve stops part way.
async fn faults<W: Write>(link: &Link<'_, W>) -> ! {
    loop {
        let fault = link.machine.next_fault().await;
        link.send(|a| report::alarm(a, fault)).await;
    }
}
