//! How long each task's polls take: embassy-executor's `trace` hooks, timed by the board's poll
//! clock. A poll is timed two ways, and the longest of each task kept, for the log and for `$I`:
//! - its *own* time: from the executor's call to its return, less the polls of the motion task
//!   that preempted it (the motion task runs on its own interrupt executor, above thread mode).
//!   What a task holds its executor for with its own work: the 10 ms rule is on this figure.
//! - its time *with preemption*: the same, the motion task's polls included: what the tasks
//!   behind it wait. While the motion runs at a high pulse rate, a thread-mode poll of a
//!   millisecond's work can take several, however the work is sliced.
//!
//! The interrupts above the motion task (the pulse interrupt, the host link's, the timer's)
//! count in both.

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

use crate::board::poll_clock;

/// Tasks whose polls are timed; a task spawned beyond them is not.
pub const TIMED_TASKS_MAX: usize = 10;

/// A task slot: free while its id is 0. A task is polled by one executor, one poll at a time,
/// so the poll under way began at `began`.
struct Timed {
    id: AtomicU32,
    name: Mutex<CriticalSectionRawMutex, Cell<&'static str>>,
    /// Its polls preempt the others' (the motion task's).
    preempts: AtomicBool,
    began: AtomicU32,
    /// [`PREEMPTING_TICKS`] when the poll under way began.
    began_preempting: AtomicU32,
    longest_ticks: AtomicU32,
    longest_with_preemption_ticks: AtomicU32,
}

impl Timed {
    const fn new() -> Self {
        Timed {
            id: AtomicU32::new(0),
            name: Mutex::new(Cell::new("")),
            preempts: AtomicBool::new(false),
            began: AtomicU32::new(0),
            began_preempting: AtomicU32::new(0),
            longest_ticks: AtomicU32::new(0),
            longest_with_preemption_ticks: AtomicU32::new(0),
        }
    }
}

static TASKS: [Timed; TIMED_TASKS_MAX] = [const { Timed::new() }; TIMED_TASKS_MAX];

/// The poll clock's ticks spent in the polls of the task that preempts the others, in all
/// (wrapping): a poll it preempted is charged the growth over its own.
static PREEMPTING_TICKS: AtomicU32 = AtomicU32::new(0);

/// Whether a task's polls preempt the other tasks' (it runs on an interrupt executor).
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Executor {
    ThreadMode,
    Interrupt,
}

/// Times the task of id `id` (as `SpawnToken::id` gives it) under `name`, run by `executor`;
/// at start-up, in thread mode, before the task is spawned.
pub fn register(id: u32, name: &'static str, executor: Executor) {
    if let Some(slot) = TASKS.iter().find(|t| t.id.load(Ordering::Relaxed) == 0) {
        slot.name.lock(|n| n.set(name));
        slot.preempts.store(executor == Executor::Interrupt, Ordering::Relaxed);
        slot.id.store(id, Ordering::Release);
    }
}

fn timed(task_id: u32) -> Option<&'static Timed> {
    TASKS.iter().find(|t| t.id.load(Ordering::Acquire) == task_id)
}

/// The longest poll of some task, µs of the board's time, and that task's name.
#[derive(Clone, Copy)]
pub struct Longest {
    pub task: &'static str,
    pub us: u32,
}

/// The longest poll of any task by its own time, and the longest with preemption (see the
/// module documentation).
pub fn longest() -> (Longest, Longest) {
    let longest_of = |ticks_of: fn(&Timed) -> u32| {
        let (mut task, mut ticks) = ("none", 0);
        for t in &TASKS {
            let n = ticks_of(t);
            if t.id.load(Ordering::Acquire) != 0 && n > ticks {
                (task, ticks) = (t.name.lock(|n| n.get()), n);
            }
        }
        Longest { task, us: ticks / poll_clock::PER_US }
    };
    (
        longest_of(|t| t.longest_ticks.load(Ordering::Relaxed)),
        longest_of(|t| t.longest_with_preemption_ticks.load(Ordering::Relaxed)),
    )
}

#[unsafe(no_mangle)]
fn _embassy_trace_task_exec_begin(_executor_id: u32, task_id: u32) {
    if let Some(task) = timed(task_id) {
        task.began_preempting.store(PREEMPTING_TICKS.load(Ordering::Relaxed), Ordering::Relaxed);
        task.began.store(poll_clock::now(), Ordering::Relaxed);
    }
}

#[unsafe(no_mangle)]
fn _embassy_trace_task_exec_end(_executor_id: u32, task_id: u32) {
    if let Some(task) = timed(task_id) {
        let ticks = poll_clock::now().wrapping_sub(task.began.load(Ordering::Relaxed));
        let preempted = if task.preempts.load(Ordering::Relaxed) {
            // Only the one task preempts: the counter is read and written here alone.
            PREEMPTING_TICKS.store(PREEMPTING_TICKS.load(Ordering::Relaxed).wrapping_add(ticks), Ordering::Relaxed);
            0
        } else {
            PREEMPTING_TICKS.load(Ordering::Relaxed).wrapping_sub(task.began_preempting.load(Ordering::Relaxed))
        };
        task.longest_ticks.fetch_max(ticks.saturating_sub(preempted), Ordering::Relaxed);
        task.longest_with_preemption_ticks.fetch_max(ticks, Ordering::Relaxed);
    }
}

#[unsafe(no_mangle)]
fn _embassy_trace_poll_start(_executor_id: u32) {}

#[unsafe(no_mangle)]
fn _embassy_trace_task_new(_executor_id: u32, _task_id: u32) {}

#[unsafe(no_mangle)]
fn _embassy_trace_task_end(_executor_id: u32, _task_id: u32) {}

#[unsafe(no_mangle)]
fn _embassy_trace_task_ready_begin(_executor_id: u32, _task_id: u32) {}

#[unsafe(no_mangle)]
fn _embassy_trace_executor_idle(_executor_id: u32) {}
