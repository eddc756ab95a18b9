//! The firmware image, the same on every board: the shared state built in place in static
//! storage, the executors and their interrupt priorities, and the task set. A board
//! (`crate::board`) gives the pins, ports and timers behind the tasks; nothing here names one.
//!
//! Priorities ([`priority`]), most urgent first: the step timer's interrupt runs the pulse
//! engine; then embassy-time's timer; the motion task on an interrupt executor, so
//! the step queue stays full while thread-mode work runs; then the host link's port. The
//! thread-mode executor runs the keypad, host link, LCD, servo (which feeds the watchdog),
//! homing and health tasks.

pub mod executor;
pub mod polls;
pub mod priority;
mod slot;
pub mod stack;

use core::convert::Infallible;
use core::future::Future;
use core::mem::MaybeUninit;
use core::pin::Pin;
use core::ptr::addr_of_mut;
use core::sync::atomic::{AtomicBool, Ordering};

use defmt::info;
use embassy_executor::{SendSpawner, SpawnError, SpawnToken, Spawner};
use embassy_time::{Duration, Timer};
use servoplot::card::CardSlot;
use servoplot::card::keeper::ResumeKeeper;
use servoplot::machine::{HomingWriter, HostWriter, Machine, MotionWriter, ServoWriter};
use servoplot::machine_io::health::{self, Health};
use servoplot::motion::interp::Curve;
use servoplot::motion::planner::{Limits, PLANNER_SEGMENTS, Planner};
use servoplot::motion::pulse::{StepProducer, StepQueue};
use servoplot::program::check::{CheckPlanner, ProgramCheck};
use servoplot::settings::Settings;
use servoplot::store::{STORE_FLASH_RANGE, Store, StoreError};
use servoplot::tasks;
use servoplot::tasks::panel::Panel;
use servoplot::tasks::serial::CardRoom;
use static_cell::{ConstStaticCell, StaticCell};

use crate::board::{self, Board};
use polls::Executor;
use slot::FutureSlot;

/// How often the health task measures the stack and the polls.
pub const HEALTH_PERIOD_MS: u64 = 1_000;

/// The shared state, in statics: the planner (50 KB) built where it lies, a field at a time; the
/// step queue in place; the machine (4 KB), the panel (2.5 KB) and the flash store (1 KB) built
/// in frames of their own and moved in. `.ci/run` holds every frame of the image to 4 KiB.
static STEP_QUEUE: ConstStaticCell<StepQueue> = ConstStaticCell::new(StepQueue::new());
static PLANNER: StaticCell<Planner<Curve, PLANNER_SEGMENTS>> = StaticCell::new();
static STORE: StaticCell<Store<board::Flash>> = StaticCell::new();
/// The host link's future, 19 KB (its links' pipes and answers, the parser, the drawing it
/// builds and the card plot with its resume marks): built in its slot, not on the stack (see `slot`).
static HOST_LINK: FutureSlot<HOST_LINK_FUTURE_BYTES> = FutureSlot::new();
/// The host links' ends.
type Links = ((board::HostRx, board::HostTx), (board::LinkRx, board::LinkTx));
static LINKS: StaticCell<Links> = StaticCell::new();
/// Room for it, bytes: a build fails should it outgrow this.
const HOST_LINK_FUTURE_BYTES: usize = 18 * 1024;
/// The board's card slot, shared by the keypad, host link and LCD tasks (all in thread mode).
static CARD_SLOT: StaticCell<CardSlot<'static>> = StaticCell::new();
/// The card file's check (4 KB) and the planner it times the plot with (50 KB), in the
/// core-coupled RAM (`.ccmram`, see the board's memory.x): SRAM has no room for a second
/// planner, and no DMA reaches either. The section is not zeroed at boot, so these are
/// `MaybeUninit`, built in place once ([`card_room`]).
#[unsafe(link_section = ".ccmram")]
static mut CHECK: MaybeUninit<ProgramCheck> = MaybeUninit::uninit();
#[unsafe(link_section = ".ccmram")]
static mut CHECK_PLANNER: MaybeUninit<CheckPlanner> = MaybeUninit::uninit();
/// A card plot's resume bookkeeping (2 KB), beside them.
#[unsafe(link_section = ".ccmram")]
static mut RESUME_KEEPER: MaybeUninit<ResumeKeeper> = MaybeUninit::uninit();
/// The machine (4 KB) and the keypad menu (2.5 KB, shared by the keypad and LCD tasks), in the
/// core-coupled RAM as well: only the core reads them, never a DMA. The stack, below the statics
/// in SRAM (flip-link), has their 6.5 KB more room for it. Built in place once ([`start`]'s
/// [`core_coupled`]).
#[unsafe(link_section = ".ccmram")]
static mut MACHINE: MaybeUninit<Machine> = MaybeUninit::uninit();
#[unsafe(link_section = ".ccmram")]
static mut PANEL: MaybeUninit<Panel> = MaybeUninit::uninit();

#[cortex_m_rt::entry]
fn main() -> ! {
    // Pulses off and servos off before anything else, after a watchdog reset too.
    board::safe_outputs();
    executor::run_thread_mode(executor::Irq(board::THREAD_PENDER_IRQ), priority::THREAD_PENDER, start)
}

/// Brings the board up and starts every task; on the thread-mode executor, before its first
/// poll.
#[inline(never)]
fn start(spawner: Spawner) {
    let board: Board = board::init(spawner);
    info!("servoplot {} on {=str}", env!("CARGO_PKG_VERSION"), board::NAME);
    // What the last power cycle kept: the settings the machine starts with, and the offsets and
    // startup blocks the host link starts with.
    let (store, loaded) = open_store(STORE.uninit(), board.flash);
    let settings = store.kept().settings;
    let why = match loaded {
        Ok(()) => "kept in the flash store, or the defaults",
        Err(StoreError::Repaired) => "the newest intact record in the flash store, or the defaults",
        Err(_) => "the defaults",
    };
    info!(
        "settings loaded ({=str}): {} x {} steps/mm, pulses up to {} Hz",
        why, settings.steps_per_mm[0], settings.steps_per_mm[1], settings.max_pulse_rate_hz
    );
    let (machine_slot, panel_slot) = core_coupled();
    let machine: &'static Machine = build_machine(machine_slot, settings);
    let Some(handles) = machine.handles() else { defmt::panic!("the machine's handles taken twice") };
    let planner = Planner::init(PLANNER.uninit(), Limits::from_settings(&settings));

    let (steps, step_consumer) = STEP_QUEUE.take().split();
    board::start_pulses(board.step_timer, step_consumer, handles.pulse);
    let motion_spawner: SendSpawner = board::start_motion_executor();
    motion_spawner.spawn(timed(motion(handles.motion, planner, steps), "motion", Executor::Interrupt));

    let panel: &'static Panel = build_panel(panel_slot);
    let card: &'static CardSlot<'static> = CARD_SLOT.init(CardSlot::new(board.card));
    spawner.spawn(timed(keypad(machine, panel, card, board.columns, board.rows), "keypad", Executor::ThreadMode));
    spawner.spawn(timed(
        servo(handles.servo, board.son, board.pen, board.lights, board.watchdog),
        "servo",
        Executor::ThreadMode,
    ));
    spawner.spawn(timed(homing(handles.homing), "homing", Executor::ThreadMode));
    let links = LINKS.init((board.host, board.second_link));
    let host_link = HOST_LINK.place(|| host_link(handles.host, store, loaded, links, card));
    let Some(host_link) = host_link else { defmt::panic!("the host link's future placed twice") };
    spawner.spawn(timed(serial(host_link), "serial", Executor::ThreadMode));
    spawner.spawn(timed(lcd(machine, panel, card, board.lcd), "lcd", Executor::ThreadMode));
    spawner.spawn(timed(health(), "health", Executor::ThreadMode));
}

/// The machine's and the panel's slots in the core-coupled RAM, once.
fn core_coupled() -> (&'static mut MaybeUninit<Machine>, &'static mut MaybeUninit<Panel>) {
    static TAKEN: AtomicBool = AtomicBool::new(false);
    if TAKEN.swap(true, Ordering::Relaxed) {
        defmt::panic!("the machine's and the panel's slots taken twice");
    }
    // SAFETY: `TAKEN` lets this run once, so these are the only references to the two statics.
    unsafe { (&mut *addr_of_mut!(MACHINE), &mut *addr_of_mut!(PANEL)) }
}

/// The machine, built and moved into `slot` in a frame of its own (4 KB), out of the caller's.
#[inline(never)]
fn build_machine(slot: &'static mut MaybeUninit<Machine>, settings: Settings) -> &'static Machine {
    slot.write(Machine::new(settings))
}

/// The panel, built and moved into `slot` in a frame of its own (2.5 KB), out of the caller's.
#[inline(never)]
fn build_panel(slot: &'static mut MaybeUninit<Panel>) -> &'static Panel {
    slot.write(Panel::new())
}

/// The card's slot, with the check of its files and that check's planner, built in place in the
/// core-coupled RAM, once (on the host link's first poll).
fn card_room(slot: &'static CardSlot<'static>, settings: &Settings) -> CardRoom<'static, 'static> {
    static TAKEN: AtomicBool = AtomicBool::new(false);
    if TAKEN.swap(true, Ordering::Relaxed) {
        defmt::panic!("the card check's room taken twice");
    }
    // SAFETY: `TAKEN` lets this run once, so these are the only references to the three statics.
    let (check, planner, keeper) =
        unsafe { (&mut *addr_of_mut!(CHECK), &mut *addr_of_mut!(CHECK_PLANNER), &mut *addr_of_mut!(RESUME_KEEPER)) };
    let planner = Planner::init(planner, Limits::from_settings(settings));
    CardRoom { slot, check: ProgramCheck::init(check, settings), planner, keeper: keeper.write(ResumeKeeper::new()) }
}

/// The flash store, opened into `slot` (out of line: its buffers are a temporary of this
/// frame only), and whether it gave back what was kept.
#[inline(never)]
fn open_store(
    slot: &'static mut MaybeUninit<Store<board::Flash>>,
    flash: board::Flash,
) -> (&'static mut Store<board::Flash>, Result<(), StoreError>) {
    let (store, loaded) = Store::open(flash, STORE_FLASH_RANGE);
    (slot.write(store), loaded)
}

// Every log line carries the time since reset, µs.
defmt::timestamp!("{=u64:us}", embassy_time::Instant::now().as_micros());

/// A task's token, its polls timed under `name`. Each task is spawned once, at start-up, so its
/// pool always has room: a second spawn is a bug, said plainly.
fn timed<S>(token: Result<SpawnToken<S>, SpawnError>, name: &'static str, executor: Executor) -> SpawnToken<S> {
    match token {
        Ok(token) => {
            polls::register(token.id(), name, executor);
            token
        }
        Err(_) => defmt::panic!("task {=str} spawned twice", name),
    }
}

#[embassy_executor::task]
async fn motion(
    machine: MotionWriter<'static>,
    planner: &'static mut Planner<Curve, PLANNER_SEGMENTS>,
    steps: StepProducer<'static>,
) -> ! {
    tasks::motion::run(machine, planner, steps, board::kick_pulses, tasks::motion::RealTime).await
}

#[embassy_executor::task]
async fn keypad(
    machine: &'static Machine,
    panel: &'static Panel,
    card: &'static CardSlot<'static>,
    columns: [board::Column; 4],
    rows: [board::Row; 4],
) -> ! {
    tasks::keypad::run(machine, panel, card, columns, rows, tasks::slices::Yield).await
}

/// The host link's future, on the two links' ends (by reference: what the future holds at first
/// is then a few words, and it is built straight into its slot). The card's check room is made
/// on its first poll, not handed in: with pointers to the core-coupled RAM among its arguments,
/// the compiler no longer proved the slot apart from them, and built the 17 KB future on the
/// stack to copy it (`.ci/run`'s frame check caught it).
fn host_link(
    machine: HostWriter<'static>,
    store: &'static mut Store<board::Flash>,
    loaded: Result<(), StoreError>,
    links: &'static mut Links,
    card: &'static CardSlot<'static>,
) -> impl Future<Output = Infallible> + 'static {
    let ((host_rx, host_tx), (link_rx, link_tx)) = links;
    #[allow(unreachable_code)]
    async move {
        let (host, link) = ((host_rx, host_tx), (link_rx, link_tx));
        let card = card_room(card, &machine.settings());
        tasks::serial::run(machine, store, loaded, host, link, card, tasks::slices::Yield).await
    }
}

#[embassy_executor::task]
async fn serial(host_link: Pin<&'static mut dyn Future<Output = Infallible>>) -> ! {
    match host_link.await {}
}

#[embassy_executor::task]
async fn servo(
    machine: ServoWriter<'static>,
    son: board::Output,
    pen: board::PenPwm,
    lights: [board::Output; 2],
    mut watchdog: board::Watchdog,
) -> ! {
    tasks::servo::run(machine, son, board::read_inputs, pen, lights, || watchdog.feed()).await
}

#[embassy_executor::task]
async fn homing(machine: HomingWriter<'static>) -> ! {
    tasks::homing::run(machine).await
}

#[embassy_executor::task]
async fn lcd(machine: &'static Machine, panel: &'static Panel, card: &'static CardSlot<'static>, lcd: board::Lcd) -> ! {
    tasks::lcd::run(machine, panel, card, lcd).await
}

/// Measures the stack's peak and the longest task poll every [`HEALTH_PERIOD_MS`], publishes
/// them for `$I`, and logs them whenever one has grown.
#[embassy_executor::task]
async fn health() -> ! {
    let mut logged = Health::default();
    loop {
        let (own, with_preemption) = polls::longest();
        let now = Health {
            stack_peak_bytes: stack::peak_bytes(),
            stack_size_bytes: stack::size_bytes(),
            longest_poll_us: own.us,
            longest_poll_with_preemption_us: with_preemption.us,
        };
        health::publish(&now);
        if now.stack_peak_bytes > logged.stack_peak_bytes
            || now.longest_poll_us > logged.longest_poll_us
            || now.longest_poll_with_preemption_us > logged.longest_poll_with_preemption_us
        {
            info!(
                "stack: {} of {} bytes at most; longest poll: {} us ({=str}), {} us with preemption ({=str})",
                now.stack_peak_bytes,
                now.stack_size_bytes,
                now.longest_poll_us,
                own.task,
                now.longest_poll_with_preemption_us,
                with_preemption.task
            );
            logged = now;
        }
        Timer::after(Duration::from_millis(HEALTH_PERIOD_MS)).await;
    }
}
