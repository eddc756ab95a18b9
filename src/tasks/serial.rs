//! The serial task: GRBL 1.1's line protocol on the host links (on the board, the UART and the
//! USB port), with one G-code parser for all of them.
//!
//! Each link has a receiver, which reads bytes as they arrive and acts on realtime bytes (`?` `!`
//! `~` 0x18 0x84 0x85, the overrides 0x90-0x9D) at once, whatever link they come on, so a status
//! query, a feed hold or an override is never stuck behind a line waiting for room in the job
//! queue; every other byte goes through the
//! link's own pipe to the line loop. Each link also has a writer, which writes the link's answers
//! one by one, each whole.
//!
//! One line loop serves every link. It takes the links' bytes in turn, assembles each link's
//! lines apart, runs them through the one parser and answers `ok` or `error:N` on the link the
//! line came from once its jobs are queued (back-pressure paces a streaming sender). The parser's
//! planned position is the only one: a line starts where the line before it ends, whichever link
//! either came on. A `?` is answered on the link that asked. A reset on a link drops what that
//! link sent before it, resets the parser and greets that link with the banner; the other links
//! are told. A fourth loop pushes the alarm of a curve that stopped early to every link.
//!
//! A file from the card (chosen on the keypad) is the line loop's third line source: checked
//! whole before anything moves, then, once the user says so, its lines go through the same
//! parser, each answered to the plot; meanwhile the links' lines are refused (see `card_plot`).
//!
//! Where a line is parsed from, and what each command of it waits for, is refused on and answers,
//! are [`crate::host::guards`]'s rules: the line loop waits, acts and answers as they say.
//!
//! Status reports carry the work offset (`|WCO:`, the active work coordinate system plus G92, as
//! the parser has it after its last line) and the overrides in force (`|Ov:`) when
//! [`crate::host::refresh`] says, as GRBL's do, so a sender shows work positions and
//! overrides.
//!
//! A line's curve is built a slice at a time ([`crate::motion::drawing::Builder`]), the other tasks and
//! the links' receivers running between slices, so a `?` is answered and the watchdog fed while
//! a long curve is built; the line is kept by the parser, and its jobs queued, only once its
//! curve is built. A reset on the line's link meanwhile abandons it, unanswered.
//!
//! Every line gets exactly one answer, in order, on its own link, whatever the sender does. What
//! happens to a sender that ignores GRBL's flow control and sends more than its pipe holds while
//! the machine is busy depends on the link's port ([`Flow`], [`LINK_FLOWS`]). The USB port holds
//! the host back: the receiver waits for room, reads nothing meanwhile (the host's writes wait),
//! and every line runs; a realtime byte the host sent behind such a paste acts once the bytes
//! before it have found room. The UART cannot hold the host back, so there such a sender loses
//! whole lines, never parts of them: from the byte that found no room up to the end of a line,
//! the receiver drops the lines' bytes and counts their ends, after one `[MSG:Receive buffer
//! full...]`; once the line loop has emptied the pipe it answers each of those lines `error:100`
//! (not processed), and only then does the receiver pass bytes on again, from the start of the
//! next line. Realtime bytes are read meanwhile.
//!
//! The line loop owns the flash store: once a line has changed what a power cycle keeps
//! (settings, G54–G59, G28/G30, startup blocks, build info), it waits for the machine to stop
//! and saves before the line's `ok`, as GRBL writes its EEPROM; settings changed at the keypad
//! wake it too, and are saved once the machine has stopped. At power-on the startup blocks kept
//! there run, answered on every link.
//!
//! A link whose port its host opens and closes (USB: DTR set and cleared) reports each change
//! once, as a read error of kind [`PORT_OPENED`] or [`PORT_CLOSED`]. A closing drops the line the
//! host was sending when it closed the port; an opening greets the link with the banner, as a
//! reset does, and resets nothing: a sender that opens the port learns the version at once.

mod card_plot;
mod card_turns;
mod dropped;
mod link;

use core::cell::{Cell, RefCell};
use core::future::Future;

use embassy_futures::join::{join, join3};
use embassy_futures::select::{Either3, select3};
use embassy_time::{Duration, Timer};
use embedded_io_async::{Error as _, ErrorKind, Read, Write};
use embedded_storage::nor_flash::NorFlash;

use crate::host::framing::{LineAssembler, LineEvent, Realtime, realtime};
use crate::host::gcode::{Offsets, Pending};
use crate::host::guards::{self, Answer, LineStart, Refusal, Reported, Wait};
use crate::host::refresh::Refresh;
use crate::host::report::{Reply, StatusFields};
use crate::host::startup::{STARTUP_LINES, StartupLines};
use crate::host::{Command, GcodeState, GrblError, Report};
use crate::machine::{HostWriter, Machine, MotionFault, PlanEnd, Stale};
use crate::machine_io::inputs::Trip;
use crate::machine_io::pen::{Pen, PenDepth};
use crate::motion::drawing::BUILD_SLICE_STEPS;
use crate::motion::job::{Control, Job};
use crate::motion::overrides::Overrides;
use crate::motion::planner::PLANNER_SEGMENTS;
use crate::settings::Settings;
use crate::status::{RunState, Status};
use crate::store::{Record, Store, StoreError};
use crate::tasks::slices::BetweenSlices;
pub use card_plot::CardRoom;
use card_plot::{CardSession, HOST_LINE_DURING_CARD_PLOT, Unread};
use link::{CLOSED_MARK, Intake, Link, RESET_MARK, intakes, write_answers};
pub use link::{
    Flow, SERIAL_ANSWER_MAX_BYTES, SERIAL_CHUNK_BYTES, SERIAL_OUTBOX_ANSWERS, SERIAL_PIPE_BYTES, SERIAL_PIPE_WAIT_MS,
    SERIAL_RX_WINDOW_BYTES,
};

/// Host links served: the board's UART and USB port, the simulator's two serial links.
pub const SERIAL_LINKS: usize = 2;
/// What each link's receiver does when its pipe is full: the first link is the board's UART, which
/// cannot hold its host back; the second its USB port, which can. The simulator's second link
/// and the QEMU model's second UART stand for the USB port: their hosts' bytes wait until read.
pub const LINK_FLOWS: [Flow; SERIAL_LINKS] = [Flow::Dropping, Flow::Waiting];
/// The kind of read error a port reports once when its host closes it.
pub const PORT_CLOSED: ErrorKind = ErrorKind::NotConnected;
/// The kind of read error a port reports once when its host opens it: the read was interrupted
/// by the news, and the next one reads on.
pub const PORT_OPENED: ErrorKind = ErrorKind::Interrupted;
/// After a read error (noise, overrun), a receiver waits this long before reading on.
pub const SERIAL_ERROR_BACKOFF_MS: u64 = 1;
/// How often waits for the machine to come to rest (G4, M0, M2) look again.
pub const SERIAL_IDLE_POLL_MS: u64 = 5;

/// What the loops of every link share.
struct Host<'m> {
    machine: HostWriter<'m>,
    /// When status reports carry `WCO:` and `Ov:`.
    refresh: RefCell<Refresh>,
    /// The startup blocks, run after every reset.
    startup: RefCell<StartupLines>,
    links: [Link; SERIAL_LINKS],
    /// Where the card plot's lines are answered (see `card_plot`).
    card: Link,
    /// The line of the card plot being carried out (0 before its first), while a card file is
    /// checked or plotted.
    card_line: Cell<Option<u32>>,
    /// A reset came on a host link: the card's check or plot stops before its next line.
    card_abort: Cell<bool>,
}

/// Speaks GRBL on two host links forever, each given as its receiving and its sending end,
/// keeping what a power cycle keeps in `store` (the board's, in static storage); `loaded` says
/// whether power-on read it back; checks and plots the files the keypad chooses from `card`'s
/// slot. `between` is the pause between two slices of a build.
pub async fn run<R1: Read, W1: Write, R2: Read, W2: Write, F: NorFlash>(
    machine: HostWriter<'_>,
    store: &mut Store<F>,
    loaded: Result<(), StoreError>,
    first: (R1, W1),
    second: (R2, W2),
    card: CardRoom<'_, '_>,
    between: impl BetweenSlices,
) -> ! {
    let host = Host {
        machine,
        refresh: RefCell::new(Refresh::new()),
        startup: RefCell::new(store.kept().startup.clone()),
        links: [Link::new(), Link::new()],
        card: Link::new(),
        card_line: Cell::new(None),
        card_abort: Cell::new(false),
    };
    for (link, flow) in host.links.iter().zip(LINK_FLOWS) {
        link.set_flow(flow);
    }
    for link in &host.links {
        // The writers are not running yet: each outbox has room for this first answer.
        link.send(Reply::Welcome(machine.state())).await;
    }
    let [a, b] = &host.links;
    join(
        join3(receive(&host, a, first.0), receive(&host, b, second.0), lines(&host, store, loaded, card, between)),
        join3(
            write_answers(a, first.1),
            write_answers(b, second.1),
            join(faults(&host), write_answers(&host.card, Unread)),
        ),
    )
    .await;
    unreachable!("the serial loops never end")
}

impl Host<'_> {
    async fn status_report(&self, link: &Link) {
        let machine = self.machine;
        // `Run` from the moment a move is queued, as GRBL reports it: a sender that sees `Idle`
        // after its last `ok` takes the job as done.
        let status = Status { state: machine.line_state(), ..machine.status() };
        let settings = machine.settings();
        let work_offset_mm = machine.work_offset_mm();
        let busy = status.state.moving();
        let overrides = status.overrides.percents();
        let occasional = self.refresh.borrow_mut().next(work_offset_mm, overrides, busy);
        let fields = StatusFields {
            speed_mm_per_min: machine.speed_mm_per_min(),
            work_offset_mm,
            wco: occasional.wco,
            overrides: occasional.overrides.then_some(overrides),
            buffer: (machine.plan_free_segments(), link.rx_window_free() as u16),
            card_line: self.card_line.get(),
        };
        link.send(Reply::Status(&status, &settings, &fields)).await;
    }

    /// Acts on bytes that arrived on `link`: realtime bytes now, the rest go to the line loop.
    async fn received(&self, link: &Link, bytes: &[u8]) {
        let machine = self.machine;
        for &byte in bytes {
            match realtime(byte) {
                Some(Realtime::StatusQuery) => self.status_report(link).await,
                // Nothing moves in check mode: a hold there would only stop the check.
                Some(Realtime::FeedHold) => machine.feed_hold(),
                Some(Realtime::SafetyDoor) => machine.open_door(),
                Some(Realtime::CycleStart) => machine.request(Control::Resume),
                Some(Realtime::JogCancel) if machine.run_state() == RunState::Jog => machine.request(Control::Abort),
                Some(Realtime::Override(command)) => machine.change_overrides(command),
                Some(Realtime::Reset) => {
                    machine.request(Control::Abort);
                    // As in GRBL, a reset brings every override back to 100 %.
                    machine.set_overrides(Overrides::NONE);
                    self.card_abort.set(self.card_line.get().is_some());
                    // Like GRBL, everything the link received before the reset is dropped: the
                    // line loop discards its bytes up to the reset and resets the parser there.
                    link.reset_received().await;
                }
                Some(Realtime::JogCancel | Realtime::Unsupported(_)) => {}
                None => link.line_byte(byte).await,
            }
        }
    }

    /// Waits until nothing is queued or moving: idle, or stopped in an alarm.
    fn machine_at_rest(&self) -> Until<'_> {
        Until { machine: self.machine, line_of: None, done: Machine::at_rest, then_pen: None, then_ms: 0, timer: None }
    }

    /// Waits until nothing is queued, planned or moving, held or not, and no homing cycle
    /// runs: the position is final.
    fn machine_stopped(&self) -> Until<'_> {
        Until { done: Machine::at_standstill, ..self.machine_at_rest() }
    }

    /// The wait of a line of `link` the guards ask for: none, or until it is over (a reset on
    /// `link` ends it).
    async fn wait(&self, link: &Link, wait: Wait) -> Result<(), Unfinished> {
        let until = match wait {
            Wait::None => return Ok(()),
            Wait::AtRest => self.machine_at_rest(),
            Wait::Stopped => self.machine_stopped(),
            // Once at rest, the pen goes there and settles.
            Wait::Pen(pen, depth) => Until { then_pen: Some((pen, depth)), ..self.machine_at_rest() },
            // Once at rest, G4's time.
            Wait::Dwell { ms } => Until { then_ms: ms, ..self.machine_at_rest() },
        };
        until.for_line(link).await
    }

    /// Does what `command` does to the machine and the startup blocks, once its wait is over.
    fn act(&self, command: &Command) -> Result<(), Refusal> {
        let machine = self.machine;
        match command {
            Command::Pause => machine.request(Control::Hold),
            Command::SetSetting { id, value } => {
                let pen = machine.position();
                machine
                    .update_settings(|s| s.set_all_around(&[(*id, *value)], pen))
                    .map_err(guards::setting_refused)?;
            }
            Command::RestoreSettings { startup_lines } => {
                machine.update_settings(|s| *s = Settings::default());
                if *startup_lines {
                    self.startup.borrow_mut().clear();
                }
            }
            Command::StoreStartupLine { index, line } => {
                self.startup.borrow_mut().set(usize::from(*index), line.clone())
            }
            Command::StoreBuildInfo(line) => self.startup.borrow_mut().build_info = line.clone(),
            Command::Sleep => machine.sleep(),
            Command::CheckMode { on: true } => machine.set_check_mode(true),
            // The parser restarts once the line is answered.
            Command::CheckMode { on: false } => {}
            Command::Home => {
                machine.request_homing();
            }
            Command::Unlock => machine.unlock(),
            // Queued; done waiting; or only answered.
            Command::Job(_) | Command::Dwell { .. } | Command::Pen(..) | Command::ProgramEnd | Command::Report(_) => {}
        }
        Ok(())
    }
}

/// Waits until `done` holds for the machine, then for the pen and the time it is given,
/// looking again every `SERIAL_IDLE_POLL_MS`. A wait for a line of a link ([`Until::for_line`])
/// gives up when a reset comes on that link. One type, its poll out of line, serves every wait
/// of the line loop for the machine.
struct Until<'m> {
    machine: HostWriter<'m>,
    /// The link whose line waits: a reset there ends the wait with [`Unfinished::Reset`].
    line_of: Option<&'m Link>,
    done: fn(&Machine) -> bool,
    /// Once `done` holds: send the pen here, then wait until it has settled.
    then_pen: Option<(Pen, PenDepth)>,
    /// Then wait this long.
    then_ms: u32,
    timer: Option<Timer>,
}

impl<'m> Until<'m> {
    /// The wait of a line of `link`: a reset on `link` ends it.
    fn for_line(self, link: &'m Link) -> Self {
        Until { line_of: Some(link), ..self }
    }
}

impl Future for Until<'_> {
    type Output = Result<(), Unfinished>;

    #[inline(never)]
    fn poll(mut self: core::pin::Pin<&mut Self>, cx: &mut core::task::Context<'_>) -> core::task::Poll<Self::Output> {
        use core::task::Poll;
        loop {
            if self.line_of.is_some_and(Link::resetting) {
                return Poll::Ready(Err(Unfinished::Reset));
            }
            if let Some(timer) = &mut self.timer {
                if core::pin::Pin::new(timer).poll(cx).is_pending() {
                    return Poll::Pending;
                }
                self.timer = None;
            }
            let wait_ms = if !(self.done)(&self.machine) {
                SERIAL_IDLE_POLL_MS
            } else if let Some((pen, depth)) = self.then_pen.take() {
                self.machine.set_pen_depth(depth);
                self.machine.set_pen(pen);
                self.done = Machine::pen_settled;
                continue;
            } else if self.then_ms > 0 {
                // In slices, so that a reset is seen as soon as in the other waits.
                let slice = self.then_ms.min(SERIAL_IDLE_POLL_MS as u32);
                self.then_ms -= slice;
                u64::from(slice)
            } else {
                return Poll::Ready(Ok(()));
            };
            self.timer = Some(Timer::after(Duration::from_millis(wait_ms)));
        }
    }
}

/// Reads a link's port and hands what arrives to [`Host::received`].
async fn receive<R: Read>(host: &Host<'_>, link: &Link, mut rx: R) -> ! {
    let mut buf = [0u8; SERIAL_CHUNK_BYTES];
    loop {
        match rx.read(&mut buf).await {
            Ok(n) => host.received(link, &buf[..n]).await,
            Err(e) if e.kind() == PORT_CLOSED => link.closed().await,
            Err(e) if e.kind() == PORT_OPENED => link.send(Reply::Welcome(host.machine.state())).await,
            Err(_) => {
                warn!("host link read error");
                Timer::after(Duration::from_millis(SERIAL_ERROR_BACKOFF_MS)).await;
            }
        }
    }
}

/// Why a line was left unfinished: not all of its commands were carried out.
enum Unfinished {
    /// The line was refused: answer `error:N`.
    Error(GrblError),
    /// A reset came on the line's link: the line gets no answer (the banner follows).
    Reset,
}

/// Says why a command of a line of `link` was refused, if the guards give a reason; the line is
/// then answered `error:N`.
async fn refuse(link: &Link, refusal: Refusal) -> Unfinished {
    if let Some(text) = refusal.message {
        link.send(Reply::Message(text)).await;
    }
    Unfinished::Error(refusal.error)
}

/// Says why the flash store gave the defaults, if it did, and runs the startup blocks; then
/// takes the links' bytes in turn and carries out their lines, answering each on its own link.
async fn lines<F: NorFlash>(
    host: &Host<'_>,
    store: &mut Store<F>,
    loaded: Result<(), StoreError>,
    mut room: CardRoom<'_, '_>,
    between: impl BetweenSlices,
) -> ! {
    let card = room.slot;
    let gcode = GcodeState::with_offsets(Offsets::from_kept_mm(store.kept().offsets_mm));
    let mut parser = Parser { host, gcode, store, plan: None, restart_after_answer: false, between, handed_steps: 0 };
    let links = [&host.links[0], &host.links[1]];
    if let Err(e) = loaded {
        for link in links {
            link.send(Reply::Message(e.message())).await;
        }
    }
    parser.startup_blocks(&links).await;
    let mut assemblers = [LineAssembler::new(), LineAssembler::new()];
    let mut bufs = [[0u8; SERIAL_CHUNK_BYTES]; SERIAL_LINKS];
    // The link looked at first: the other after each turn, so a link streaming without pause
    // never holds the other up.
    let mut first = 0;
    // At power-on, a card plot a power cut stopped is looked for first.
    let mut session = CardSession::PowerOn;
    loop {
        let card_turn = session.turn(host, card);
        let (intake, k) =
            match select3(intakes(&host.links, &mut bufs, first), host.machine.settings_changed(), card_turn).await {
                Either3::First(intake) => intake,
                Either3::Second(()) => {
                    // Changed on the keypad (a line's changes are kept before its answer).
                    parser.keep_changed(&links).await;
                    continue;
                }
                Either3::Third(turn) => {
                    parser.card_turn(turn, card, &mut room, &mut session).await;
                    continue;
                }
            };
        first = 1 - k;
        let (link, assembler) = (&host.links[k], &mut assemblers[k]);
        match intake {
            Intake::Dropped(n) => {
                // Lines whose bytes found no room: the partial one in the assembler is the first.
                assembler.clear();
                for _ in 0..n {
                    link.send(Reply::Error(GrblError::ReceiveBufferFull)).await;
                }
            }
            Intake::Bytes(n) => {
                for &byte in &bufs[k][..n] {
                    parser.byte(link, assembler, byte).await;
                }
            }
        }
    }
}

/// The one parser every link's lines go through, and where the plan ended when it took the line
/// it carries out: its jobs are handed over as planned from there.
struct Parser<'h, 'm, F: NorFlash, B: BetweenSlices> {
    host: &'h Host<'m>,
    gcode: GcodeState,
    store: &'h mut Store<F>,
    /// Where the plan ends as the parser planned (`None` before the first line).
    plan: Option<PlanEnd>,
    /// The line being answered left check mode: the parser starts over once it is answered.
    restart_after_answer: bool,
    /// The pause between two slices of a line's curve.
    between: B,
    /// Steps of the jobs handed to the motion so far (wrapping), as the motion counts them.
    handed_steps: u32,
}

impl<F: NorFlash, B: BetweenSlices> Parser<'_, '_, F, B> {
    /// Takes one byte of `link`'s lines, assembled by `assembler`; answers the line it ends.
    async fn byte(&mut self, link: &Link, assembler: &mut LineAssembler, byte: u8) {
        match byte {
            RESET_MARK => {
                assembler.clear();
                self.reset(link).await;
                return;
            }
            CLOSED_MARK => {
                assembler.clear();
                return;
            }
            _ if link.resetting() => return,
            _ => {}
        }
        let result = match assembler.push(byte) {
            None => return,
            // A card plot runs: the host's lines wait for its end.
            Some(LineEvent::Line(_)) if self.host.card_line.get().is_some() => {
                Err(Unfinished::Error(HOST_LINE_DURING_CARD_PLOT))
            }
            Some(LineEvent::Line(line)) => match self.line(link, line).await {
                Ok(()) => self.keep(link).await,
                refused => refused,
            },
            Some(other) => Err(Unfinished::Error(other.error().unwrap_or(GrblError::ExpectedCommandLetter))),
        };
        match result {
            Ok(()) => link.send(Reply::Ok).await,
            Err(Unfinished::Error(e)) => link.send(Reply::Error(e)).await,
            Err(Unfinished::Reset) => {}
        }
        if core::mem::take(&mut self.restart_after_answer) {
            self.restart(link).await;
        }
    }

    /// A reset on `link`: once the machine has stopped, the parser starts over from where the
    /// pen is and the link gets the banner; the other links are told.
    async fn reset(&mut self, link: &Link) {
        // Not the wait of a line: the reset under way does not end it.
        let _stopped = self.host.machine_stopped().await;
        link.reset_met();
        self.restart(link).await;
        // A link resetting too (after an e-stop, all are) hears of its own reset.
        for other in self.host.links.iter().filter(|l| !core::ptr::eq(*l, link) && !l.resetting()) {
            other.send(Reply::Message("Reset from another host link")).await;
        }
    }

    /// After a soft reset, or on leaving check mode: the parser starts over from the pen, `link`
    /// gets the banner, and the startup blocks run (not in an alarm, as GRBL does), each answered
    /// there `>line:ok` or `>line:error:N`.
    async fn restart(&mut self, link: &Link) {
        let machine = self.host.machine;
        machine.set_check_mode(false);
        // After `$SLP` the servos come back on, in alarm (the free axes may have been moved).
        machine.wake();
        // As after power-on, the next reports carry `WCO:` and `Ov:`.
        *self.host.refresh.borrow_mut() = Refresh::new();
        let settings = machine.settings();
        self.gcode.reset(machine.position(), &settings);
        link.send(Reply::Welcome(machine.state())).await;
        self.startup_blocks(&[link]).await;
    }

    /// Runs the startup blocks (not in an alarm, as GRBL does), each answered on `links`
    /// `>line:ok` or `>line:error:N`.
    async fn startup_blocks(&mut self, links: &[&Link]) {
        let machine = self.host.machine;
        let settings = machine.settings();
        if guards::startup_blocks_run(machine.state()) {
            let startup = self.host.startup.borrow().clone();
            for index in 0..STARTUP_LINES {
                let line = startup.line(index);
                if line.is_empty() {
                    continue;
                }
                // Checked when stored: a startup block changes modes and offsets, and moves
                // nothing.
                let result = self.gcode.run_startup_block(line, &settings);
                for link in links {
                    link.send(Reply::StartupResult(line, result)).await;
                }
            }
        }
        machine.set_work_offset_mm(self.gcode.work_offset_mm());
    }

    /// After a line: if it changed what a power cycle keeps, saves it once the machine has
    /// stopped (a flash write stalls the pulses), so the line's `ok` means it is kept. A store
    /// that fails is reported; the line stands.
    async fn keep(&mut self, link: &Link) -> Result<(), Unfinished> {
        if !self.kept() {
            self.host.machine_stopped().for_line(link).await?;
            self.save(&[link]).await;
        }
        Ok(())
    }

    /// After the settings changed outside a line (on the keypad): as [`Parser::keep`], a
    /// failure told on every link.
    async fn keep_changed(&mut self, links: &[&Link]) {
        if !self.kept() {
            // Not the wait of a line: no reset ends it.
            let _stopped = self.host.machine_stopped().await;
            self.save(links).await;
        }
    }

    /// Whether the flash holds what a power cycle keeps.
    fn kept(&self) -> bool {
        self.store.holds(&self.host.machine.settings(), self.gcode.offsets(), &self.host.startup.borrow())
    }

    /// Saves what a power cycle keeps; a store that fails is reported on `links`.
    async fn save(&mut self, links: &[&Link]) {
        let record = Record::of(&self.host.machine.settings(), self.gcode.offsets(), &self.host.startup.borrow());
        if let Err(e) = self.store.save(&record) {
            for link in links {
                link.send(Reply::Message(e.message())).await;
            }
        }
    }

    /// Parses one line of `link` and carries it out.
    async fn line(&mut self, link: &Link, line: &str) -> Result<(), Unfinished> {
        let machine = self.host.machine;
        loop {
            // The line starts where the plan ends, whoever handed the last job over (either
            // link, the keypad, the homing cycle). After an abort (keypad, jog cancel, a curve
            // stopped part way, a reset on another link), that is where the pen stops.
            let plan_end = machine.plan_end();
            let settings = machine.settings();
            let state = machine.line_state();
            let LineStart::Parse { end, from_end } = guards::line_start(plan_end, state) else {
                self.host.machine_stopped().for_line(link).await?;
                continue;
            };
            self.plan = Some(end);
            if from_end {
                self.gcode.plan_from(end.at(), &settings);
            }
            let mut pending = Pending::new();
            self.gcode.parse(line, &settings, state, &mut pending).map_err(Unfinished::Error)?;
            self.build(link, &mut pending).await?;
            if guards::kept_change_waits(pending.changes_kept(&self.gcode), machine.stopped()) {
                // It runs with the machine stopped, from where the pen stands: a reset meanwhile
                // drops it unrun, and it is parsed again once the motion before it has ended.
                self.host.machine_stopped().for_line(link).await?;
                continue;
            }
            let commands = self.gcode.commit(&mut pending, &settings).map_err(Unfinished::Error)?;
            // A refused line changed no offset.
            machine.set_work_offset_mm(self.gcode.work_offset_mm());
            for command in commands {
                self.carry_out(link, &settings, command).await?;
            }
            return Ok(());
        }
    }

    /// Builds the curve of a line of `link` a slice at a time; the other tasks and the links'
    /// receivers run between slices. A reset on the link drops the line unanswered, the parser
    /// unchanged.
    async fn build(&mut self, link: &Link, pending: &mut Pending) -> Result<(), Unfinished> {
        loop {
            let slice = pending.advance(BUILD_SLICE_STEPS);
            if slice.steps > 0 {
                self.between.after(&slice).await;
            }
            if link.resetting() {
                return Err(Unfinished::Reset);
            }
            if slice.done {
                return Ok(());
            }
        }
    }

    /// Carries out one command of a line of `link` as the guards say: refused, or waited for,
    /// done, waited on, and answered.
    async fn carry_out(&mut self, link: &Link, settings: &Settings, command: Command) -> Result<(), Unfinished> {
        let (host, machine) = (self.host, self.host.machine);
        if let Command::Job(job) = command {
            return self.queue(link, job).await;
        }
        let reported = Reported { input_levels: machine.input_levels(), halted: machine.halted() };
        let course = match guards::course(&command, reported, settings) {
            Ok(course) => course,
            Err(refusal) => return Err(refuse(link, refusal).await),
        };
        host.wait(link, course.before).await?;
        if let Err(refusal) = host.act(&command) {
            return Err(refuse(link, refusal).await);
        }
        host.wait(link, course.after).await?;
        match course.answer(machine.run_state()) {
            Ok(Answer::None) => {}
            Ok(Answer::Message(text)) => link.send(Reply::Message(text)).await,
            Ok(Answer::Report(kind)) => self.report(link, settings, kind).await,
            Err(refusal) => return Err(refuse(link, refusal).await),
        }
        self.restart_after_answer |= course.restart_after_answer;
        Ok(())
    }

    /// Answers `$`, `$$`, `$G`, `$#`, `$I` or `$N` on `link`.
    async fn report(&self, link: &Link, settings: &Settings, kind: Report) {
        // The startup blocks may change while the report waits for room: a copy.
        let startup = self.host.startup.borrow().clone();
        let gcode = &self.gcode;
        let reply = match kind {
            Report::Help => Reply::Help,
            Report::Settings => Reply::Settings(settings),
            Report::ParserState => Reply::ParserState(gcode, settings),
            Report::Parameters => Reply::Parameters(gcode, settings),
            Report::BuildInfo => Reply::BuildInfo {
                info: &startup.build_info,
                planner_blocks: PLANNER_SEGMENTS,
                rx_buffer_bytes: SERIAL_RX_WINDOW_BYTES,
            },
            Report::StartupLines => Reply::StartupLines(&startup),
        };
        link.send(reply).await;
    }

    /// Hands a job, planned from where the plan ended as the line was taken, to the motion
    /// task, waiting for room: the `ok` goes out once it is queued. A reset on the line's link
    /// while it waits drops the job silently (the banner follows). A job the plan no longer
    /// ends where it starts (an abort came, or the keypad handed a job over, since the line was
    /// taken) is refused with `error:9`: it was planned from a point the pen will not reach.
    async fn queue(&mut self, link: &Link, job: Job) -> Result<(), Unfinished> {
        let stale = || Unfinished::Error(GrblError::Locked);
        let from = self.plan.ok_or_else(stale)?;
        // A drawing's steps fit the count: the travel is far shorter than 2^32 steps.
        let steps = job.drawing.steps() as u32;
        let queued = link.unless_reset(self.host.machine.submit(job, from)).await.ok_or(Unfinished::Reset)?;
        self.plan = Some(queued.map_err(|Stale| stale())?);
        self.handed_steps = self.handed_steps.wrapping_add(steps);
        Ok(())
    }
}

/// Pushes an alarm to every link when a curve stops part way or an input trips the machine. The
/// emergency stop also resets every link, as Ctrl-X does: what they sent before it is dropped.
async fn faults(host: &Host<'_>) -> ! {
    loop {
        let fault = host.machine.next_fault().await;
        for link in &host.links {
            link.send(Reply::Alarm(fault)).await;
        }
        if fault == MotionFault::Tripped(Trip::EStop) {
            host.machine.set_overrides(Overrides::NONE);
            for link in &host.links {
                link.reset_received().await;
            }
        }
    }
}
