//! The simulated board: the firmware's own tasks on the host, with virtual time.
//!
//! The pulse, motion, keypad, serial and LCD loops are the same code as on target; only their
//! pins and ports are models: step/direction pins record a pulse trace, the keypad is a matrix
//! pressed by a script, the two host links (the board's UART and USB port) read transcripts,
//! standard input or a sender on a pseudo-terminal, and the LCD is a model of the ST7920 fed by
//! the real driver. A run ends when every input is used up and the machine has come to rest, or
//! at the instant the event script cuts the power (`off power`, see [`inputs`]): then nothing
//! runs on, whatever it was doing. In a live session (standard input, a pseudo-terminal) virtual
//! time keeps to the wall clock.
//! [`cli`] is the simulator's command line: what the firmware binary runs when built for the
//! host.
//!
//! As on the board, the tasks run at two levels: the step timer and the motion task at
//! interrupt level, polled whenever they are woken; the others in thread mode, polled only
//! while no work charged there (a slice of a build, see [`cpu::ThreadLevel`]) holds it.

pub mod card;
pub mod card_slot;
pub mod cli;
pub mod clock;
pub mod cpu;
pub mod flash;
pub mod inputs;
pub mod keys;
pub mod lcd;
pub mod picture;
pub mod pins;
pub mod pty;
pub mod serial;
pub mod step_timer;
pub mod stop;

use core::future::Future;
use core::task::{Context, Poll, Waker};
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::task::Wake;
use std::vec::Vec;

use embassy_futures::join::{join, join5};

use crate::card::CardSlot;
use crate::card::keeper::ResumeKeeper;
use crate::geom::{Axis, Point};
use crate::host::GcodeState;
use crate::machine::Machine;
use crate::machine_io::pen::Pen;
use crate::motion::interp::Curve;
use crate::motion::planner::{Limits, PLANNER_SEGMENTS, Planner};
use crate::motion::pulse::{PulseEngine, StepQueue};
use crate::program::check::{CheckPlanner, ProgramCheck};
use crate::settings::Settings;
use crate::store::{Record, STORE_SECTORS, Store, StoreError};
use crate::tasks::serial::CardRoom;
use crate::tasks::{self, lcd::St7920Lcd, panel::Panel};
use cpu::{CpuModel, SimCpu, SimSlices, ThreadLevel};
use embassy_sync::blocking_mutex::raw::NoopRawMutex;
use embassy_sync::signal::Signal;
use flash::SimFlash;
use inputs::{InputScript, SimInputs, Switches};
use keys::{KeyMatrix, KeyScript};
use lcd::{Frame, LcdPin, SIM_LCD_SPI_HZ, SimSpi};
use pins::{LevelPin, PulseTrace, SimPen, SimWatchdog, TracePin};
use serial::SimSerial;
pub use step_timer::LateInterrupt;
use step_timer::SimStepTimer;

/// After the inputs are used up and the machine rests, the run goes on this long so the LCD
/// shows the final state.
pub const SIM_SETTLE_US: u64 = 500_000;
/// A run that has not come to rest after this much virtual time is cut off (not while a person
/// drives it from the terminal: then virtual time is real time).
pub const SIM_MAX_VIRTUAL_US: u64 = 3_600_000_000;

/// When the keypad script begins.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum KeysStart {
    /// At power-on, alongside the serial input.
    #[default]
    AtOnce,
    /// Once every line of the serial input has had its answer and the motion has ended (a
    /// person steps up to the machine after the PC's drawing is done).
    AfterSerial,
}

/// What a simulation starts from.
#[derive(Default)]
pub struct SimConfig {
    /// The flash store's sectors: the settings, offsets and startup blocks the board powers on
    /// with (erased by default: the compiled-in defaults).
    pub flash: SimFlash,
    /// The host link on the board's UART.
    pub serial: SimSerial,
    /// The host link on the board's USB port; sends nothing unless given input.
    pub usb: SimSerial,
    pub keys: KeyScript,
    pub keys_start: KeysStart,
    /// The board's processor: its work takes time, and the pulses may have to wait for it.
    /// `None`: the firmware's work takes no time.
    pub cpu: Option<CpuModel>,
    /// Limit switches at the ends of the travel; none if `None`.
    pub switches: Option<Switches>,
    /// Driver alarms, e-stops, stuck switches, the card pulled and the power cut at set virtual
    /// times.
    pub events: InputScript,
    /// A step timer interrupt that comes late (none by default).
    pub late_interrupt: Option<LateInterrupt>,
    /// Once set, the run ends at the next instant every task waits (Ctrl-C in a live session).
    pub stop: Option<&'static AtomicBool>,
    /// The card in the slot; none if `None`.
    pub card: Option<card::SimCard>,
}

/// What a simulation produced.
pub struct SimReport {
    pub trace: PulseTrace,
    /// Every frame sent to the LCD, with the virtual time it was sent.
    pub frames: Vec<(u64, Frame)>,
    /// LCD writes that came sooner after the previous one than the controller executes it.
    pub lcd_writes_too_soon: u32,
    /// Everything the firmware answered on the UART link.
    pub serial_out: Vec<u8>,
    /// The same, line by line, each with the virtual time it was written, µs.
    pub serial_lines: Vec<(u64, std::string::String)>,
    /// Everything the firmware answered on the USB link.
    pub usb_out: Vec<u8>,
    /// Position counted by the pulse task.
    pub position: Point,
    /// Settings at the end (the host may have changed them).
    pub settings: Settings,
    /// What power-on read from the flash store.
    pub loaded: Result<(), StoreError>,
    /// The flash at the end: the next power-on's (see [`SimConfig::flash`]).
    pub flash: SimFlash,
    /// Virtual time at the end, and when the last pulse went out.
    pub end_us: u64,
    /// The time the event script cut the power, if it did: the run ended there (`end_us`).
    pub power_off_us: Option<u64>,
    /// The card's image at the end (or at the cut), with what the plotter wrote on it: the next
    /// power-on's card. `None` without a card.
    pub card_image: Option<Vec<u8>>,
    /// True if the run hit `SIM_MAX_VIRTUAL_US` before coming to rest.
    pub timed_out: bool,
    /// Times the pulses had to wait for the motion task.
    pub underruns: u32,
    /// Times the step timer's interrupt came a whole period late.
    pub missed_updates: u32,
    /// Every change of the servo-on output, with its virtual time.
    pub son: Vec<(u64, bool)>,
    /// Every change of the run LED and of the buzzer, with its virtual time.
    pub led: Vec<(u64, bool)>,
    pub buzzer: Vec<(u64, bool)>,
    /// Every change of the pen servo's pulse, µs, with its virtual time.
    pub pen: Vec<(u64, u16)>,
    /// The longest the watchdog went unfed, µs: beyond `WATCHDOG_TIMEOUT_MS` the board would
    /// have been reset.
    pub watchdog_unfed_us: u64,
    /// In a live session, the wall time and the virtual time, µs, that passed while the run held
    /// the one to the other (until the live input ended).
    pub live_kept_us: Option<(u64, u64)>,
}

impl SimReport {
    /// The UART link's answers as text.
    pub fn answers(&self) -> std::string::String {
        std::string::String::from_utf8_lossy(&self.serial_out).into_owned()
    }

    /// The USB link's answers as text.
    pub fn usb_answers(&self) -> std::string::String {
        std::string::String::from_utf8_lossy(&self.usb_out).into_owned()
    }

    /// The pen path rebuilt from the pulses.
    pub fn path(&self) -> Vec<Point> {
        self.trace.path(self.settings.dir_invert_mask)
    }

    /// The pen path split where the pen went up or down: each run with the pen down (`true`) or
    /// up, neighbouring runs sharing their end point. Without a pen lift (no pen servo pulses)
    /// the pen counts as down throughout.
    pub fn strokes(&self) -> Vec<(bool, Vec<Point>)> {
        let up_us = self.settings.pen_up_us;
        let down_at = |t: u64| {
            let pulse = self.pen.iter().take_while(|(at, _)| *at <= t).last().map(|c| u32::from(c.1));
            pulse.is_none_or(|p| p != up_us)
        };
        let mut at = Point::ORIGIN;
        let mut strokes: Vec<(bool, Vec<Point>)> = Vec::new();
        for (t, step) in self.trace.steps(self.settings.dir_invert_mask) {
            let down = down_at(t);
            if strokes.last().is_none_or(|s| s.0 != down) {
                strokes.push((down, std::vec![at]));
            }
            at = at.stepped(step);
            if let Some(s) = strokes.last_mut() {
                s.1.push(at);
            }
        }
        strokes
    }

    /// Time of the last pulse.
    pub fn last_pulse_us(&self) -> u64 {
        self.trace.pulses.last().map_or(0, |p| p.t_us)
    }
}

struct FlagWaker(AtomicBool);

impl Wake for FlagWaker {
    fn wake(self: Arc<Self>) {
        self.0.store(true, Ordering::Release);
    }
}

/// Runs the firmware on the simulated board until its inputs are used up and it rests.
pub fn run(config: SimConfig) -> SimReport {
    clock::reset();
    let flash = config.flash.clone();
    let (mut store, loaded) = Store::open(config.flash, STORE_RANGE);
    let machine = Machine::new(store.kept().settings);
    let Some(handles) = machine.handles() else { unreachable!("a new machine has its handles") };
    let panel = Panel::new();
    let trace = Rc::new(RefCell::new(PulseTrace::default()));
    let power_off_us = config.events.power_off_us();
    if let Some(off) = power_off_us {
        trace.borrow_mut().power_off_at(off * u64::from(crate::geom::TICKS_PER_US));
    }
    let inputs = SimInputs::new(trace.clone(), config.switches, config.events, &machine.settings());
    let mut sim_slot = card_slot::SimSlot::new(config.card, inputs.clone());
    let slot = CardSlot::new(&mut sim_slot);
    let mut step_queue = StepQueue::new();
    // On the heap: the host's stack need not hold its 50 KB.
    let mut planner: std::boxed::Box<Planner<Curve, PLANNER_SEGMENTS>> =
        std::boxed::Box::new(Planner::new(Limits::from_settings(&machine.settings())));
    // The card file's check and its planner, on the heap as well.
    let mut check_planner: std::boxed::Box<CheckPlanner> =
        std::boxed::Box::new(Planner::new(Limits::from_settings(&machine.settings())));
    let mut check = std::boxed::Box::new(ProgramCheck::new(GcodeState::new(), &machine.settings(), Pen::Up));
    let mut keeper = std::boxed::Box::new(ResumeKeeper::new());
    let room = CardRoom { slot: &slot, check: &mut check, planner: &mut check_planner, keeper: &mut keeper };
    let (steps, step_consumer) = step_queue.split();
    let pins = Axis::ALL.map(|axis| TracePin::pair(&trace, axis));
    let timer = SimStepTimer::new(pins, inputs.clone()).with_late_interrupt(config.late_interrupt);
    let mut engine = PulseEngine::new(timer, step_consumer);
    let son = LevelPin::default();
    let watchdog = SimWatchdog::default();
    let pen = SimPen::default();
    let (led, buzzer) = (LevelPin::default(), LevelPin::default());
    let kicks = Signal::<NoopRawMutex, ()>::new();
    let matrix = match config.keys_start {
        KeysStart::AtOnce => KeyMatrix::new(config.keys),
        KeysStart::AfterSerial => KeyMatrix::waiting(config.keys),
    };
    let columns = [0, 1, 2, 3].map(|c| matrix.column(c));
    let rows = [0, 1, 2, 3].map(|r| matrix.row(r));
    let serial = config.serial;
    let usb = config.usb;
    let links = [&serial, &usb];
    let cpu = config.cpu;
    let stop = config.stop;
    let spi = SimSpi::default();
    let lcd =
        St7920Lcd::new(spi.clone(), LcdPin::Reset, LcdPin::ChipSelect(spi.model.clone()), spi.delay(), SIM_LCD_SPI_HZ);

    // The board's interrupts: the step timer, and the motion task on its interrupt executor.
    let interrupts = join(
        step_timer::run(handles.pulse, &mut engine, &kicks),
        tasks::motion::run(
            handles.motion,
            &mut planner,
            steps,
            || kicks.signal(()),
            SimCpu::new(cpu.clone(), &machine),
        ),
    );
    // Thread mode: polled only while no work charged there takes it (see `cpu::ThreadLevel`).
    let thread = ThreadLevel::default();
    let threads = join5(
        tasks::keypad::run(&machine, &panel, &slot, columns, rows, SimSlices::new(cpu.clone(), &machine, &thread)),
        tasks::serial::run(
            handles.host,
            &mut store,
            loaded,
            (serial.clone(), serial.clone()),
            (usb.clone(), usb.clone()),
            room,
            SimSlices::new(cpu, &machine, &thread),
        ),
        tasks::lcd::run(&machine, &panel, &slot, lcd),
        tasks::servo::run(
            handles.servo,
            son.clone(),
            || inputs.levels(),
            pen.clone(),
            [led.clone(), buzzer.clone()],
            || watchdog.feed(),
        ),
        tasks::homing::run(handles.homing),
    );
    // On the heap, so that they can be dropped when the run ends and the card be taken out.
    let (mut interrupts, mut threads) = (std::boxed::Box::pin(interrupts), std::boxed::Box::pin(threads));
    let (irq_flag, thread_flag) =
        (Arc::new(FlagWaker(AtomicBool::new(true))), Arc::new(FlagWaker(AtomicBool::new(true))));
    let (irq_waker, thread_waker) = (Waker::from(irq_flag.clone()), Waker::from(thread_flag.clone()));
    let (mut irq_cx, mut thread_cx) = (Context::from_waker(&irq_waker), Context::from_waker(&thread_waker));
    let mut rest_since: Option<u64> = None;
    let mut wall_pace: Option<clock::WallPace> = None;
    let mut live_kept_us = None;
    let mut timed_out = false;
    let mut powered_off = false;
    loop {
        // The power cut: nothing runs from then on.
        if power_off_us.is_some_and(|off| clock::now_ticks() >= off) {
            powered_off = true;
            break;
        }
        // The interrupts first, whenever they are woken, as their priority has them on the board.
        if irq_flag.0.swap(false, Ordering::AcqRel) {
            if let Poll::Ready(never) = interrupts.as_mut().poll(&mut irq_cx) {
                match never {}
            }
            continue;
        }
        if !thread.busy() && thread_flag.0.swap(false, Ordering::AcqRel) {
            if let Poll::Ready((never, ..)) = threads.as_mut().poll(&mut thread_cx) {
                match never {}
            }
            continue;
        }
        // Every task waits (or thread mode is taken): the run may end, take live input, or jump
        // to the next deadline.
        serial.pump_live(std::time::Duration::ZERO);
        let woken = |flag: &FlagWaker| flag.0.load(Ordering::Acquire);
        let runnable = || woken(&irq_flag) || (woken(&thread_flag) && !thread.busy());
        if runnable() {
            continue;
        }
        if stop.is_some_and(|stop| stop.load(Ordering::Relaxed)) {
            break;
        }
        let now = clock::now_ticks();
        // Thread mode taken: nothing there is at rest, and it takes its tasks up again once free.
        let thread_free_at = thread.busy().then(|| thread.busy_until_us());
        let input_done = links.iter().all(|l| l.input_done());
        if !matrix.started() && input_done && thread_free_at.is_none() && machine.at_rest() {
            matrix.start();
        }
        let at_rest = input_done && matrix.script_done() && thread_free_at.is_none() && machine.at_rest();
        // A power cut to come ends the run, not the rest before it.
        if at_rest && power_off_us.is_none() {
            let since = *rest_since.get_or_insert(now);
            if now >= since + SIM_SETTLE_US {
                break;
            }
        } else {
            rest_since = None;
        }
        // Thread mode taken with a task of it woken: it is polled once free.
        // Time never passes the power cut: it is the last deadline.
        let next_deadline =
            earliest(earliest(clock::next_deadline(), thread_free_at.filter(|_| woken(&thread_flag))), power_off_us);
        if serial.is_live() {
            // A person or a sender is at the link: let time pass as it does for them (so a `!`
            // typed mid-move lands mid-move), waiting for their input until the wall clock
            // reaches the next deadline.
            let pace = wall_pace.get_or_insert_with(clock::WallPace::start);
            if let Some(wait) = next_deadline.map_or(Some(std::time::Duration::MAX), |d| pace.wait_for(d)) {
                serial.pump_live(wait);
            }
            live_kept_us = Some(pace.kept_us());
            if runnable() {
                // Input came: it arrives at the wall clock's time, never past the next deadline.
                clock::jump_to(next_deadline.map_or(pace.wall_us(), |d| d.min(pace.wall_us())));
                continue;
            }
        } else if now >= SIM_MAX_VIRTUAL_US && !at_rest {
            timed_out = true;
            break;
        }
        // A timed input byte due before the next timer deadline comes first.
        let next_timed = links.iter().filter_map(|l| l.next_timed_us()).min();
        match (next_timed, next_deadline) {
            (Some(t), deadline) if deadline.is_none_or(|d| t < d) => {
                clock::jump_to(t);
                links.iter().for_each(|l| l.deliver_due());
            }
            (_, Some(d)) if clock::next_deadline() != Some(d) => clock::jump_to(d),
            _ => {
                if !clock::jump_to_next_deadline() {
                    break;
                }
            }
        }
    }
    let position = machine.position();
    let underruns = machine.underruns();
    let missed_updates = machine.missed_updates();
    let settings = machine.settings();
    let end_us = clock::now_ticks();
    // The tasks are gone (at a cut, wherever they were): the card comes out of its slot.
    drop((interrupts, threads));
    drop(slot);
    let card_image = sim_slot.into_card().map(|card| card.image());
    let trace =
        Rc::try_unwrap(trace).map(RefCell::into_inner).unwrap_or_else(|rc| core::mem::take(&mut *rc.borrow_mut()));
    let frames = core::mem::take(&mut spi.model.borrow_mut().frames);
    let lcd_writes_too_soon = spi.model.borrow().writes_too_soon;
    SimReport {
        trace,
        frames,
        lcd_writes_too_soon,
        serial_out: serial.output(),
        serial_lines: serial.timed_lines(),
        usb_out: usb.output(),
        position,
        settings,
        loaded,
        flash,
        end_us,
        power_off_us: powered_off.then_some(end_us),
        card_image,
        timed_out,
        underruns,
        missed_updates,
        son: son.changes(),
        watchdog_unfed_us: watchdog.longest_unfed_us(end_us),
        pen: pen.changes(),
        led: led.changes(),
        buzzer: buzzer.changes(),
        live_kept_us,
    }
}

/// The earlier of two times, either of which may be none.
fn earliest(a: Option<u64>, b: Option<u64>) -> Option<u64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// The flash store's range of [`SimFlash`]: all of it.
const STORE_RANGE: core::ops::Range<u32> = 0..(STORE_SECTORS * crate::store::STORE_SECTOR_BYTES) as u32;

/// Flash keeping `record`, as a power cycle after saving it leaves it.
pub fn flash_keeping(record: Record) -> SimFlash {
    let flash = SimFlash::default();
    let (mut store, _) = Store::open(flash.clone(), STORE_RANGE);
    store.save(&record).expect("erased flash takes a record");
    flash
}

/// Runs a serial transcript (and nothing on the keypad) with default settings.
pub fn run_serial(input: &str) -> SimReport {
    run(SimConfig { serial: SimSerial::with_input(input.as_bytes()), ..SimConfig::default() })
}

/// Runs a keypad script (and nothing on the serial link) with default settings.
pub fn run_keys(script: &str) -> Result<SimReport, std::string::String> {
    Ok(run(SimConfig { keys: KeyScript::parse(script)?, ..SimConfig::default() }))
}
