extern crate std;
use super::*;
use crate::geom::{Point, Step};
use crate::machine::Machine;
use proptest::prelude::*;
use std::vec::Vec;

/// The mock timer's SIGN latency: the F407's 2 µs.
const LATENCY_TICKS: u32 = 2 * TICKS_PER_US;

/// What a mock timer saw: every period in the order the hardware counted them, with the SIGN
/// levels in force while it counted.
#[derive(Default)]
struct MockTimer {
    preload: (u32, u8),
    running: bool,
    started: bool,
    sign: [bool; 2],
    /// (ticks, axes pulsed at the end, SIGN levels).
    periods: Vec<(u32, u8, [bool; 2])>,
    /// The input levels read, and from which read on (counting from 1) they change to what.
    levels: InputLevels,
    then: Option<(usize, InputLevels)>,
    reads: usize,
    halts: usize,
    updates: u16,
    /// Update events (counting from 0 after the start's) whose interrupt comes one period late.
    late: Vec<usize>,
    /// Times the engine asked for its news to be handed on.
    news: usize,
}

impl StepTimer for MockTimer {
    const MAX_PERIOD_TICKS: u32 = 65_535;
    const SIGN_LATENCY_TICKS: u32 = LATENCY_TICKS;
    fn set_sign(&mut self, axis: Axis, high: bool) {
        self.sign[axis.index()] = high;
    }
    fn preload(&mut self, ticks: u32, axes: u8) {
        self.preload = (ticks, axes);
    }
    fn start(&mut self, _width_ticks: u32) {
        self.running = true;
        self.started = true;
    }
    fn stop(&mut self) {
        self.running = false;
    }
    fn halt(&mut self) {
        self.running = false;
        self.halts += 1;
    }
    fn input_levels(&mut self) -> InputLevels {
        self.reads += 1;
        match self.then {
            Some((from, levels)) if self.reads >= from => levels,
            _ => self.levels,
        }
    }
    fn update_count(&mut self) -> u16 {
        self.updates
    }
    fn pend_news(&mut self) {
        self.news += 1;
    }
}

/// Runs the engine as the hardware would until it stops (or `max` periods): at each update
/// event the preloaded period becomes active, the update counter counts, and the interrupt
/// runs, unless the timer says it comes late (then the period repeats). `between` runs after
/// each period, as the motion task could.
fn run(engine: &mut PulseEngine<'_, MockTimer>, machine: PulseWriter<'_>, max: usize, mut between: impl FnMut(usize)) {
    engine.kick(machine);
    machine.deliver_pulse_news();
    if !core::mem::take(&mut engine.timer_mut().started) {
        return;
    }
    for k in 0..max {
        let timer = engine.timer_mut();
        timer.updates = timer.updates.wrapping_add(1);
        let (ticks, axes) = timer.preload;
        if !timer.late.contains(&k) {
            engine.on_period(machine);
            // The news interrupt, right after.
            machine.deliver_pulse_news();
            if !engine.timer().running {
                return;
            }
        }
        let sign = engine.timer().sign;
        engine.timer_mut().periods.push((ticks, axes, sign));
        between(k);
    }
}

fn step(x: i8, y: i8, interval_ticks: u32) -> StepCmd {
    StepCmd::new(Step::new(x, y), interval_ticks)
}

/// `n` microseconds in ticks.
const fn us(n: u32) -> u32 {
    n * TICKS_PER_US
}

/// Publishes `cmds`, then a rest if `rest`.
fn queue(p: &mut StepProducer<'_>, cmds: &[StepCmd], rest: bool) {
    let slots = p.free_slots();
    slots[..cmds.len()].copy_from_slice(cmds);
    p.publish(cmds.len());
    if rest {
        p.rest();
    }
}

/// The engine with `settings` run over `cmds` to the end: its timer, the machine, and the trip
/// the motion task would take then.
fn emit(settings: Settings, cmds: &[StepCmd], late: &[usize]) -> (MockTimer, Machine, Option<Trip>) {
    let machine = Machine::new(settings);
    let handles = machine.handles().unwrap();
    let pulses = handles.pulse;
    let mut q = StepQueue::new();
    let (mut p, c) = q.split();
    queue(&mut p, cmds, true);
    let timer = MockTimer { late: late.to_vec(), ..MockTimer::default() };
    let mut engine = PulseEngine::new(timer, c);
    run(&mut engine, pulses, 10_000, |_| {});
    let PulseEngine { timer, .. } = engine;
    let trip = handles.motion.take_trip();
    (timer, machine, trip)
}

/// Where the pulses of `periods` take the pen as the drivers count them: each by the SIGN level
/// in force at its edge (`invert` is `$3`).
fn driven(periods: &[(u32, u8, [bool; 2])], invert: u8) -> Point {
    let mut at = Point::ORIGIN;
    for &(_, axes, sign) in periods {
        let along = |axis: usize| {
            let forward = sign[axis] != (invert & (1 << axis) != 0);
            i32::from(axes & (1 << axis) != 0) * if forward { 1 } else { -1 }
        };
        at = Point::new(at.x + along(0), at.y + along(1));
    }
    at
}

#[test]
fn steps_become_periods_ending_in_their_pulses_and_the_timer_stops_after_the_rest() {
    // 5 µs pulses, set-up and hold, 20 kHz: no period ending in a pulse under 50 µs.
    let machine = Machine::new(Settings::default());
    let handles = machine.handles().unwrap();
    let pulses = handles.pulse;
    let mut q = StepQueue::new();
    let (mut p, c) = q.split();
    queue(&mut p, &[step(1, 0, us(100)), step(1, 1, us(60)), step(0, 1, us(60))], true);
    handles.motion.set_queued(3, us(220));
    let mut engine = PulseEngine::new(MockTimer::default(), c);
    run(&mut engine, pulses, 100, |_| {});
    let periods: Vec<(u32, u8)> = engine.timer().periods.iter().map(|&(t, a, _)| (t, a)).collect();
    // SIGN is set for the first step of each axis: the hold first, then the rest of the
    // interval; a step in a known direction is one period.
    assert_eq!(periods, [(us(5), 0), (us(95), 1), (us(5), 0), (us(55), 3), (us(60), 2)]);
    // SIGN high (forward) on each moving axis for its pulse.
    assert_eq!(engine.timer().periods[3].2, [true, true]);
    assert!(!engine.is_running());
    assert_eq!(machine.position(), Point::new(2, 2));
    assert!(machine.pulses_idle());
    assert_eq!(machine.underruns(), 0);
    assert_eq!(machine.missed_updates(), 0);
    assert_eq!(machine.queued_ticks(), 0);
}

#[test]
fn a_direction_change_holds_sign_after_the_last_pulse_and_sets_it_up_before_the_next() {
    // At 100 kHz a reversal 10 µs after the last pulse: 5 µs hold, then a period of the
    // latency (2 µs), the set-up (5 µs) and the pulse (5 µs); the steps after it keep their
    // 10 µs.
    let fast = Settings { max_pulse_rate_hz: 100_000.0, ..Settings::default() };
    let cmds = [step(1, 0, us(50)), step(-1, 0, us(10)), step(-1, 0, us(10)), step(-1, 1, us(10))];
    let (timer, machine, _) = emit(fast, &cmds, &[]);
    let ticks: Vec<u32> = timer.periods.iter().map(|p| p.0).collect();
    assert_eq!(ticks, [us(5), us(45), us(5), us(12), us(10), us(5), us(12)]);
    // SIGN changes at the start of the period that ends with the reversed pulse, never under
    // one.
    let signs: Vec<[bool; 2]> = timer.periods.iter().map(|p| p.2).collect();
    assert_eq!(signs[2..], [[true, false], [false, false], [false, false], [false, false], [false, true]]);
    assert_eq!(machine.position(), Point::new(-2, 1));
    // At 20 kHz the 50 µs floor of `$205` leaves the set-up room: the pulse's period is the
    // rest of the interval.
    let (timer, _, _) = emit(Settings::default(), &cmds, &[]);
    let ticks: Vec<u32> = timer.periods.iter().map(|p| p.0).collect();
    assert_eq!(ticks, [us(5), us(45), us(5), us(45), us(50), us(5), us(45)]);
}

#[test]
fn at_200_khz_a_pulse_of_2_5_us_is_as_long_low_as_high() {
    let fastest = Settings { pulse_width_us: 2.5, max_pulse_rate_hz: 200_000.0, ..Settings::default() };
    let timing = Timing::new(&fastest, LATENCY_TICKS);
    assert_eq!((timing.width_ticks, timing.min_period_ticks), (10, 20));
    // Commands asking for less get the period of `$205`.
    let (timer, machine, _) = emit(fastest, &[step(1, 0, 1); 20], &[]);
    assert!(timer.periods.iter().skip(2).all(|p| p.0 == 20 && p.1 == 1));
    assert_eq!(machine.position(), Point::new(20, 0));
    // A 2.6 µs pulse does not fit twice in 5 µs in whole ticks (11 + 11 > 20): refused.
    let mut s = fastest;
    assert_eq!(s.set(0, 2.6), Err(crate::settings::SettingError::OutOfRange));
    assert_eq!(s.set(205, 190_000.0), Ok(()));
    assert_eq!(s.set(0, 2.6), Ok(()));
}

/// Times of a pulse train from the periods a mock timer counted: each pulse's rising and
/// falling edge, and each SIGN change, ticks.
struct Timeline {
    /// Per axis: (rise, fall, SIGN level).
    pulses: [Vec<(u64, u64, bool)>; 2],
    /// Per axis: the update event at whose interrupt SIGN changed.
    sign_changes: [Vec<u64>; 2],
}

fn timeline(periods: &[(u32, u8, [bool; 2])], width: u32) -> Timeline {
    let mut t = 0u64;
    let mut line = Timeline { pulses: [Vec::new(), Vec::new()], sign_changes: [Vec::new(), Vec::new()] };
    let mut sign: Option<[bool; 2]> = None;
    for &(ticks, axes, levels) in periods {
        for axis in 0..2 {
            if sign.is_some_and(|s| s[axis] != levels[axis]) {
                line.sign_changes[axis].push(t);
            }
            let end = t + u64::from(ticks);
            if axes & (1 << axis) != 0 {
                line.pulses[axis].push((end - u64::from(width), end, levels[axis]));
            }
        }
        sign = Some(levels);
        t += u64::from(ticks);
    }
    line
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Whatever the steps, rates and timings: every pulse is `$0` wide and PULS is low at
    /// least as long between two; SIGN changes only after the hold since the last pulse and
    /// the set-up (and the interrupt's latency) before the next; no two pulses come closer
    /// than one period of `$205`, nor sooner than their command's interval; and the position
    /// is where the pulses took the drivers.
    #[test]
    fn pulse_and_sign_timing_hold_for_any_steps(
        moves in proptest::collection::vec((-1i8..=1, -1i8..=1, 1u32..400), 1..60),
        width_quarters in 10u32..40,
        setup_us in 5u32..30,
        hold_us in 5u32..30,
        rate_hz in 2_000u32..200_000,
        invert in 0u8..4,
    ) {
        let width_us = width_quarters as f32 / 4.0;
        let mut settings = Settings::default();
        let fits = settings
            .set_all(&[(0, width_us), (200, setup_us as f32), (29, hold_us as f32), (205, rate_hz as f32), (3, f32::from(invert))])
            .is_ok();
        prop_assume!(fits);
        let cmds: Vec<StepCmd> = moves
            .iter()
            .filter(|m| m.0 != 0 || m.1 != 0)
            .map(|&(x, y, interval)| step(x, y, interval))
            .collect();
        prop_assume!(!cmds.is_empty());
        let (timer, machine, _) = emit(settings, &cmds, &[]);
        let timing = Timing::new(&settings, LATENCY_TICKS);
        let line = timeline(&timer.periods, timing.width_ticks);
        for axis in 0..2 {
            let pulses = &line.pulses[axis];
            for w in pulses.windows(2) {
                prop_assert!(w[1].0 - w[0].1 >= u64::from(timing.width_ticks), "PULS low too short: {w:?}");
            }
            for &at in &line.sign_changes[axis] {
                let before = pulses.iter().rev().find(|p| p.1 <= at);
                if let Some(p) = before {
                    prop_assert!(at - p.1 >= u64::from(timing.hold_ticks), "hold {} < {}", at - p.1, timing.hold_ticks);
                }
                let after = pulses.iter().find(|p| p.0 > at).map(|p| p.0);
                if let Some(rise) = after {
                    let written = at + u64::from(LATENCY_TICKS);
                    prop_assert!(rise - written >= u64::from(us(setup_us)), "set-up {} < {}", rise - written, us(setup_us));
                }
            }
        }
        // Pulse to pulse, of any axis: at least the period of `$205` and the interval asked.
        let mut rises: Vec<u64> = line.pulses.iter().flatten().map(|p| p.0).collect();
        rises.sort_unstable();
        rises.dedup();
        for (w, cmd) in rises.windows(2).zip(&cmds[1..]) {
            prop_assert!(w[1] - w[0] >= u64::from(timing.min_period_ticks.max(cmd.interval_ticks)));
        }
        let expected = cmds.iter().fold(Point::ORIGIN, |p, c| p.stepped(c.step));
        prop_assert_eq!(machine.position(), expected);
        prop_assert_eq!(driven(&timer.periods, invert), expected);
        prop_assert_eq!(machine.missed_updates(), 0);
    }
}

#[test]
fn an_interval_longer_than_the_timer_counts_waits_in_pulseless_periods() {
    let (timer, machine, _) = emit(Settings::default(), &[step(0, -1, 600_000), step(0, -1, 400)], &[]);
    let periods = &timer.periods;
    let until_first: u32 = periods.iter().take_while(|p| p.1 == 0).map(|p| p.0).sum::<u32>();
    let first = periods.iter().position(|p| p.1 != 0).unwrap();
    assert_eq!(until_first + periods[first].0, 600_000);
    assert!(periods.iter().all(|p| p.0 <= 65_535));
    assert_eq!(periods[first + 1], (400, 2, [false, false]));
    assert_eq!(machine.position(), Point::new(0, -2));
}

#[test]
fn a_queue_run_dry_before_the_rest_is_one_underrun_and_never_a_burst() {
    let machine = Machine::new(Settings::default());
    let pulses = machine.handles().unwrap().pulse;
    let mut q = StepQueue::new();
    let (mut p, c) = q.split();
    queue(&mut p, &[step(1, 0, us(100)); 3], false);
    let mut engine = PulseEngine::new(MockTimer::default(), c);
    // The motion task catches up only after the 10th period, then finishes.
    run(&mut engine, pulses, 1_000, |k| {
        if k == 10 {
            queue(&mut p, &[step(1, 0, us(100)); 2], true);
        }
    });
    let periods = &engine.timer().periods;
    assert_eq!(machine.underruns(), 1);
    assert_eq!(machine.position(), Point::new(5, 0));
    // Every pulse comes at least its interval after the one before.
    let mut since = 0;
    let mut gaps = Vec::new();
    for &(t, a, _) in periods.iter() {
        since += t;
        if a != 0 {
            gaps.push(since);
            since = 0;
        }
    }
    assert!(gaps[1..].iter().all(|&g| g >= us(100)), "{gaps:?}");
    assert!(periods.iter().any(|p| p.1 == 0 && p.0 == UNDERRUN_WAIT_TICKS));
}

#[test]
fn a_limit_switch_ahead_halts_the_timer_before_the_next_pulse_and_nothing_starts_until_unlocked() {
    use crate::machine_io::inputs::{LIMIT_X_MAX, LIMIT_X_MIN, LIMITS};
    // Hard limits, no debounce; normally open switches read low when pressed.
    let settings = Settings { hard_limits: true, input_debounce_ms: 0, ..Settings::default() };
    let machine = Machine::new(settings);
    let handles = machine.handles().unwrap();
    let pulses = handles.pulse;
    let mut q = StepQueue::new();
    let (mut p, c) = q.split();
    queue(&mut p, &[step(1, 0, us(100)); 10], true);
    // The X min switch, behind the pen, is pressed from the start and never stops it; the X
    // max switch closes at the sixth period (the first is SIGN's hold).
    let timer = MockTimer {
        levels: LIMITS & !LIMIT_X_MIN,
        then: Some((6, LIMITS & !LIMIT_X_MIN & !LIMIT_X_MAX)),
        ..MockTimer::default()
    };
    let mut engine = PulseEngine::new(timer, c);
    run(&mut engine, pulses, 100, |_| {});
    assert_eq!(engine.timer().halts, 1);
    assert!(machine.halted());
    assert_eq!(machine.position(), Point::new(4, 0), "the pulses of the periods before");
    assert_eq!(handles.motion.take_trip(), Some(Trip::Limit { axis: Axis::X, max: true }));
    engine.kick(pulses);
    assert!(!engine.is_running(), "halted: no kick starts the timer");
    handles.host.unlock();
    engine.kick(pulses);
    assert!(engine.is_running(), "unlocked, the queued steps go on");
}

#[test]
fn steps_queued_behind_a_rest_before_the_timer_stops_go_on_from_rest() {
    let machine = Machine::new(Settings::default());
    let pulses = machine.handles().unwrap().pulse;
    let mut q = StepQueue::new();
    let (mut p, c) = q.split();
    queue(&mut p, &[step(1, 0, us(100))], true);
    let mut engine = PulseEngine::new(MockTimer::default(), c);
    let mut more = Some(step(0, 1, us(2_000)));
    run(&mut engine, pulses, 100, |_| {
        if let Some(cmd) = more.take() {
            queue(&mut p, &[cmd], true);
        }
    });
    assert_eq!(machine.position(), Point::new(1, 1));
    assert_eq!(machine.underruns(), 0);
    assert!(!engine.is_running());
    // A kick with nothing queued does not start the timer.
    let mut q = StepQueue::new();
    let (mut p, c) = q.split();
    p.rest();
    let mut engine = PulseEngine::new(MockTimer::default(), c);
    engine.kick(pulses);
    assert!(!engine.is_running());
}

#[test]
fn an_interrupt_a_period_late_counts_the_repeated_pulse_and_stops_in_an_alarm() {
    let cmds = [step(1, 1, us(100)); 10];
    // Update events: 0 the start's hold (both axes' SIGN at once), 1 the first step, 2 the
    // second, 3 the third (its interrupt one period late).
    let (timer, machine, trip) = emit(Settings::default(), &cmds, &[3]);
    // The timer repeated the step it had preloaded, pulse and all, then ran it once more and
    // stopped: two pulses more than the steps emitted by then.
    let pulses = timer.periods.iter().filter(|p| p.1 != 0).count();
    assert_eq!(machine.position(), Point::new(pulses as i32, pulses as i32));
    assert_eq!(machine.position(), driven(&timer.periods, 0), "the position is the pulses the drivers took");
    assert_eq!(machine.missed_updates(), 1);
    assert!(machine.halted());
    assert_eq!(trip, Some(Trip::MissedUpdate));
    assert!(!timer.running);
    assert_eq!(timer.halts, 1, "halted at the end of the repeat, between pulses");
    // Every pulse whole: the repeat ran to its end.
    let (last_ticks, last_axes, _) = *timer.periods.last().unwrap();
    assert_eq!((last_ticks, last_axes), (us(100), 3));

    // Two periods late: two repeats and the one under way, all counted; one fault.
    let (timer, machine, _) = emit(Settings::default(), &cmds, &[3, 4]);
    let pulses = timer.periods.iter().filter(|p| p.1 != 0).count();
    assert_eq!(pulses, 5);
    assert_eq!(machine.position(), Point::new(5, 5));
    assert_eq!(machine.missed_updates(), 1);
}

#[test]
fn a_late_interrupt_where_sign_was_to_change_counts_the_pulses_by_the_sign_they_had() {
    // Forward, then back: the reversal's SIGN write is in the interrupt that comes late, so the
    // reversed step's pulses go out forward, and count forward.
    let cmds = [step(1, 0, us(100)), step(1, 0, us(100)), step(-1, 0, us(100)), step(-1, 0, us(100))];
    // Update events: 0 the start's hold, 1 the first step, 2 the second, 3 the hold before the
    // reversal, 4 the reversed step (its interrupt late).
    let (timer, machine, trip) = emit(Settings::default(), &cmds, &[4]);
    assert_eq!(machine.position(), driven(&timer.periods, 0));
    assert_eq!(machine.position(), Point::new(4, 0), "two forward steps and the late one twice, all forward");
    assert_eq!(machine.missed_updates(), 1);
    assert_eq!(trip, Some(Trip::MissedUpdate));
}
