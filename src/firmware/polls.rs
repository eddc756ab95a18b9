//! How long each task's polls take: embassy-executor's `trace` hooks, timed by the board's poll
//! clock. A poll is timed from the executor's call to its return, interrupts that preempt it
//! included, so the figure is what the tasks behind it wait. The longest poll of each task is
//! kept, for the log and for `$I`.

use core::cell::Cell;
use core::sync::atomic::{AtomicU32, Ordering};

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
    began: AtomicU32,
    longest_ticks: AtomicU32,
}

impl Timed {
    const fn new() -> Self {
        Timed {
            id: AtomicU32::new(0),
            name: Mutex::new(Cell::new("")),
            began: AtomicU32::new(0),
            longest_ticks: AtomicU32::new(0),
        }
    }
}

static TASKS: [Timed; TIMED_TASKS_MAX] = [const { Timed::new() }; TIMED_TASKS_MAX];

/// Times the task of id `id` (as `SpawnToken::id` gives it) under `name`; at start-up, in thread
/// mode, before the task is spawned.
pub fn register(id: u32, name: &'static str) {
    if let Some(slot) = TASKS.iter().find(|t| t.id.load(Ordering::Relaxed) == 0) {
        slot.name.lock(|n| n.set(name));
        slot.id.store(id, Ordering::Release);
    }
}

fn timed(task_id: u32) -> Option<&'static Timed> {
    TASKS.iter().find(|t| t.id.load(Ordering::Acquire) == task_id)
}

/// The longest poll of any task, µs of the board's time, and that task's name.
pub fn longest() -> (&'static str, u32) {
    let (mut name, mut ticks) = ("none", 0);
    for task in &TASKS {
        let t = task.longest_ticks.load(Ordering::Relaxed);
        if task.id.load(Ordering::Acquire) != 0 && t > ticks {
            (name, ticks) = (task.name.lock(|n| n.get()), t);
        }
    }
    (name, ticks / poll_clock::PER_US)
}

#[unsafe(no_mangle)]
fn _embassy_trace_task_exec_begin(_executor_id: u32, task_id: u32) {
    if let Some(task) = timed(task_id) {
        task.began.store(poll_clock::now(), Ordering::Relaxed);
    }
}

#[unsafe(no_mangle)]
fn _embassy_trace_task_exec_end(_executor_id: u32, task_id: u32) {
    if let Some(task) = timed(task_id) {
        let ticks = poll_clock::now().wrapping_sub(task.began.load(Ordering::Relaxed));
        task.longest_ticks.fetch_max(ticks, Ordering::Relaxed);
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
