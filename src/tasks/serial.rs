//! The serial task: GRBL 1.1's line protocol on the host link.
//!
//! Two loops share the link. The receiver reads bytes as they arrive and acts on realtime bytes
//! (`?` `!` `~` 0x18 0x84 0x85, the overrides 0x90-0x9D) at once, so a status query, a feed hold
//! or an override is never stuck behind a line waiting for room in the job queue; every other
//! byte goes through a small pipe to the line loop, which assembles lines, runs them through the
//! G-code parser and answers `ok` or `error:N` once their jobs are queued (back-pressure paces a
//! streaming sender). A third loop reports curves that stopped early. Answers are whole lines,
//! never interleaved.
//!
//! Status reports carry the work offset (`|WCO:`, the active work coordinate system plus G92, as
//! the parser has it after its last line) and the overrides in force (`|Ov:`) when
//! [`crate::protocol::refresh`] says, as GRBL's do, so a sender shows work positions and
//! overrides.
//!
//! Every line gets exactly one answer, in order, whatever the sender does. A sender that
//! ignores GRBL's flow control and sends more than the pipe holds while the machine is busy
//! loses whole lines, never parts of them: from the byte that found no room up to the end of a
//! line, the receiver drops the lines' bytes and counts their ends; once the line loop has
//! emptied the pipe it answers each of those lines `error:11` (not processed), and only then
//! does the receiver pass bytes on again, from the start of the next line.

use core::cell::{Cell, RefCell};
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
use crate::overrides::Overrides;
use crate::planner::PLANNER_SEGMENTS;
use crate::protocol::framing::{LineAssembler, LineEvent, Realtime, realtime};
use crate::protocol::refresh::Refresh;
use crate::protocol::report::StatusFields;
use crate::protocol::startup::StartupLines;
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

type Answer = String<SERIAL_ANSWER_MAX_BYTES>;

/// State the three loops share; all run on one executor, so plain cells do.
struct Link<'m, W> {
    machine: &'m Machine,
    tx: Mutex<NoopRawMutex, W>,
    bytes: Pipe<NoopRawMutex, SERIAL_PIPE_BYTES>,
    /// When status reports carry `WCO:` and `Ov:`.
    refresh: Cell<Refresh>,
    /// Lines dropped for want of room in the pipe; see the module documentation.
    dropped: Dropped,
    /// Resets received and not yet met by the line loop: bytes before them are dropped.
    resets_pending: Cell<u32>,
    /// Cancels a line waiting for the machine when a reset arrives.
    reset: Signal<NoopRawMutex, ()>,
    /// The line being answered left check mode: the parser starts over once it is answered.
    restart_after_answer: Cell<bool>,
    /// The startup blocks, run after every reset.
    startup: RefCell<StartupLines>,
}

/// Speaks GRBL on the host link forever.
pub async fn run<R: Read, W: Write>(machine: &Machine, rx: R, tx: W) -> ! {
    let link = Link {
        machine,
        tx: Mutex::new(tx),
        bytes: Pipe::new(),
        refresh: Cell::new(Refresh::new()),
        dropped: Dropped::default(),
        resets_pending: Cell::new(0),
        reset: Signal::new(),
        restart_after_answer: Cell::new(false),
        startup: RefCell::new(StartupLines::new()),
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
        let machine = self.machine;
        let status = machine.status();
        let settings = machine.settings();
        let work_offset_mm = machine.work_offset_mm();
        let busy = !matches!(status.state, RunState::Idle | RunState::Alarm | RunState::Check);
        let mut refresh = self.refresh.get();
        let overrides = status.overrides.percents();
        let occasional = refresh.next(work_offset_mm, overrides, busy);
        self.refresh.set(refresh);
        let rx_free = SERIAL_RX_WINDOW_BYTES.saturating_sub(self.bytes.len());
        let fields = StatusFields {
            speed_mm_per_min: machine.speed_mm_per_min(&settings),
            work_offset_mm,
            wco: occasional.wco,
            overrides: occasional.overrides.then_some(overrides),
            buffer: (machine.plan_free_segments(), rx_free as u16),
        };
        self.send(|a| report::status(a, &status, &settings, &fields)).await;
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
        if !d.active.get() {
            let wait = Timer::after(Duration::from_millis(SERIAL_PIPE_WAIT_MS));
            if let Either::First(()) = select(self.bytes.write_all(&[byte]), wait).await {
                return;
            }
            d.active.set(true);
            self.send(|a| report::message(a, "Receive buffer full: lines dropped, each answered error:11")).await;
        }
        // CR and LF each end a line, as they do for the line assembler.
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
    /// Wakes the line loop when a dropped line's end is counted.
    counted: Signal<NoopRawMutex, ()>,
}

impl Dropped {
    /// Forgets every dropped line (a reset: lines before it get no answer).
    fn clear(&self) {
        self.active.set(false);
        self.lines.set(0);
        self.mid_line.set(false);
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
                // Nothing moves in check mode: a hold there would only stop the check.
                Some(Realtime::FeedHold) if link.machine.state() != RunState::Check => {
                    link.machine.request(Control::Hold)
                }
                Some(Realtime::FeedHold) => {}
                Some(Realtime::CycleStart) => link.machine.request(Control::Resume),
                Some(Realtime::JogCancel) if link.machine.run_state() == RunState::Jog => {
                    link.machine.request(Control::Abort)
                }
                Some(Realtime::Override(command)) => link.machine.change_overrides(command),
                Some(Realtime::Reset) => {
                    link.machine.request(Control::Abort);
                    // As in GRBL, a reset brings every override back to 100 %.
                    link.machine.set_overrides(Overrides::NONE);
                    // Like GRBL, everything received before the reset is dropped: the line loop
                    // discards bytes up to this marker and resets the parser when it meets it.
                    link.resets_pending.set(link.resets_pending.get() + 1);
                    link.reset.signal(());
                    link.dropped.clear();
                    link.bytes.write_all(&[byte]).await;
                }
                Some(Realtime::SafetyDoor) => link.machine.open_door(),
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
                restart(link, &mut gcode, &mut epoch).await;
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
                    let state = machine.state();
                    if state == RunState::Idle && machine.is_idle() {
                        // The keypad, an abort or a curve that stopped early may have moved the
                        // pen elsewhere than the parser planned. (In check mode the parser
                        // plans on from the lines it checked.)
                        gcode.sync_position(machine.position(), &settings);
                    }
                    match gcode.execute(line, &settings, state) {
                        Ok(commands) => {
                            // A refused line changed no offset.
                            machine.set_work_offset_mm(gcode.work_offset_mm());
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
            if link.restart_after_answer.take() {
                restart(link, &mut gcode, &mut epoch).await;
            }
        }
    }
}

/// After a soft reset, or on leaving check mode: the parser starts over from the pen, the host
/// gets the banner, and the startup blocks run (not in an alarm, as GRBL does), each answered
/// `>line:ok` or `>line:error:N`.
async fn restart<W: Write>(link: &Link<'_, W>, gcode: &mut GcodeState, epoch: &mut PlanEpoch) {
    let machine = link.machine;
    machine.set_check_mode(false);
    // As after power-on, the next reports carry `WCO:` and `Ov:`.
    link.refresh.set(Refresh::new());
    let settings = machine.settings();
    gcode.reset(machine.position(), &settings);
    *epoch = machine.plan_epoch();
    link.send(report::welcome).await;
    if machine.state() != RunState::Alarm {
        let startup = link.startup.borrow().clone();
        for line in startup.to_run() {
            // Checked when stored: a startup block changes modes and offsets, and moves nothing.
            let result = gcode.execute(line, &settings, RunState::Idle).map(|_| ());
            link.send(|a| report::startup_result(a, line, result)).await;
        }
    }
    machine.set_work_offset_mm(gcode.work_offset_mm());
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
    let checking = machine.state() == RunState::Check;
    match command {
        // Check mode: the line was parsed and its drawing built and checked; nothing runs.
        Command::Job(_) | Command::Dwell { .. } | Command::Pause if checking => {}
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
        Command::RestoreSettings { startup_lines } => {
            machine.update_settings(|s| *s = Settings::default());
            if startup_lines {
                link.startup.borrow_mut().clear();
            }
        }
        Command::StoreStartupLine { index, line } => link.startup.borrow_mut().set(usize::from(index), line),
        Command::Report(kind) => {
            link.send(|a| match kind {
                Report::Help => report::help(a),
                Report::Settings => report::settings(a, settings),
                Report::ParserState => report::parser_state(a, gcode, settings),
                Report::Parameters => report::parameters(a, gcode),
                Report::BuildInfo => report::build_info(a, PLANNER_SEGMENTS, SERIAL_RX_WINDOW_BYTES),
                Report::StartupLines => report::startup_lines(a, &link.startup.borrow()),
            })
            .await
        }
        Command::CheckMode { on: true } => {
            machine.set_check_mode(true);
            link.send(|a| report::message(a, "Enabled")).await;
        }
        Command::CheckMode { on: false } => {
            link.send(|a| report::message(a, "Disabled")).await;
            link.restart_after_answer.set(true);
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
    link.unless_reset(link.machine.submit(job, epoch)).await?.map_err(|Stale| Unfinished::Error(GrblError::Locked))
}

/// Pushes an alarm to the host when a curve stops part way.
async fn faults<W: Write>(link: &Link<'_, W>) -> ! {
    loop {
        let fault = link.machine.next_fault().await;
        link.send(|a| report::alarm(a, fault)).await;
    }
}
