//! The keypad task: scans the 4x4 matrix every `KEYPAD_SCAN_PERIOD_MS`, decodes key events and
//! hands them to the menu (changed in place, in the [`Panel`] it shares with the LCD task), then
//! carries out what the menu asks for. A drawing the menu asks for is built here a slice at a
//! time between the scans (see [`crate::tasks::slices`]), so keys are still read while it is
//! built (`D` drops it).

use embassy_futures::select::{Either, select};
use embassy_time::{Duration, Ticker, Timer};
use embedded_hal::digital::{InputPin, OutputPin};

use crate::card::{CardProgress, CardSlot};
use crate::machine::{Machine, PlanEnd};
use crate::machine_io::pen;
use crate::motion::drawing::BUILD_SLICE_STEPS;
use crate::motion::job::{Control, Job};
use crate::panel::MenuAction;
use crate::panel::keypad::{KEYPAD_SCAN_PERIOD_MS, KeypadDecoder};
use crate::panel::menu::{Building, Menu, UiError};
use crate::tasks::panel::Panel;
use crate::tasks::slices::BetweenSlices;

/// Time for a row input to settle after its column is driven low.
pub const KEYPAD_SETTLE_US: u64 = 10;

/// Scans the keypad forever. Columns are open-drain outputs driven low one at a time and released
/// (`set_high`) after, never driven high, so keys pressed together never join two driven
/// outputs; rows are inputs with pull-ups, read low where a pressed key joins them to the driven
/// column. `between` is the pause between two slices of a build.
pub async fn run<C: OutputPin, R: InputPin>(
    machine: &Machine,
    panel: &Panel,
    card: &CardSlot<'_>,
    mut columns: [C; 4],
    mut rows: [R; 4],
    mut between: impl BetweenSlices,
) -> ! {
    let mut decoder = KeypadDecoder::new();
    let mut ticker = Ticker::every(Duration::from_millis(KEYPAD_SCAN_PERIOD_MS as u64));
    // The drawing the menu asked for, built between the scans, and where the plan ended when it
    // was set up: where it starts.
    let mut building: Option<Building> = None;
    let mut from: Option<PlanEnd> = None;
    loop {
        if let Some(b) = &mut building {
            let slice = async {
                let slice = b.advance(BUILD_SLICE_STEPS);
                between.after(&slice).await;
                slice.done
            };
            // The scan comes first when it is due.
            if let Either::Second(done) = select(ticker.next(), slice).await {
                if done {
                    built(machine, panel, &mut building, &mut from);
                }
                continue;
            }
        } else {
            ticker.next().await;
        }
        let raw = scan(&mut columns, &mut rows).await;
        let now_ms = super::now_ms();
        for event in decoder.update(raw, now_ms) {
            let status = machine.status();
            let settings = machine.settings();
            let action = panel.update(|menu| menu.handle(event, &status, &settings));
            match action {
                MenuAction::ReadCard => panel.update(|menu| menu.card_read(card.files())),
                MenuAction::PlotCard => plot_card(machine, panel, card),
                MenuAction::CardAnswer(plot) => {
                    if !plot {
                        card.abort();
                    }
                    card.answer(plot);
                }
                action => {
                    if action == MenuAction::Control(Control::Abort) {
                        card.abort();
                    }
                    act(machine, panel, action, &mut building, &mut from)
                }
            }
        }
        // The run screen follows the machine and the card plot between keys.
        let status = machine.status();
        panel.update_if(|menu| menu.observe(&status, now_ms));
        let (progress, stop) = (card.progress(), card.take_stop());
        panel.update_if(|menu| menu.observe_card(progress, stop, status.emitted_steps));
    }
}

/// Asks the serial task to check the card file the menu chose, and show it to plot, if the
/// machine is free for it.
fn plot_card(machine: &Machine, panel: &Panel, card: &CardSlot<'_>) {
    if !machine.at_rest() || card.progress() != CardProgress::None {
        return refuse(panel, UiError::Busy);
    }
    if let Some(file) = panel.read(Menu::card_choice) {
        info!("card: chose {}", file.name.as_str());
        card.request_plot(file);
    }
}

/// One pass over the matrix: bit `row * 4 + column` set for every key read as pressed.
async fn scan<C: OutputPin, R: InputPin>(columns: &mut [C; 4], rows: &mut [R; 4]) -> u16 {
    let mut raw = 0u16;
    for (c, column) in columns.iter_mut().enumerate() {
        let _ = column.set_low();
        Timer::after(Duration::from_micros(KEYPAD_SETTLE_US)).await;
        for (r, row) in rows.iter_mut().enumerate() {
            if row.is_low().unwrap_or(false) {
                raw |= 1 << (r * 4 + c);
            }
        }
        let _ = column.set_high();
    }
    raw
}

/// Hands the menu the drawing it asked for, walked to its end, and carries out what it asks
/// for then; the building is spent unless the menu starts it.
fn built(machine: &Machine, panel: &Panel, building: &mut Option<Building>, from: &mut Option<PlanEnd>) {
    let Some(b) = building.as_mut() else { return };
    let status = machine.status();
    let settings = machine.settings();
    let action = panel.update(|menu| menu.built(b, &status, &settings));
    if !matches!(action, MenuAction::Start(_)) {
        // Shown, or refused.
        *building = None;
    }
    act(machine, panel, action, building, from);
}

/// Carries out a menu action: start or drop a build, queue a job, or pass a control to the
/// motion task. A drawing or a jog starts where the plan ends (see [`Machine::plan_end`]), and
/// `from` keeps that end for the drawing being built.
fn act(
    machine: &Machine,
    panel: &Panel,
    action: MenuAction,
    building: &mut Option<Building>,
    from: &mut Option<PlanEnd>,
) {
    match action {
        MenuAction::None => {}
        MenuAction::Build(request) => {
            *from = machine.plan_end();
            // The menu asks only at rest, when the plan's end is known.
            let start = from
                .map_or(Err(UiError::Busy), |end| Building::start(building, &request, end.at(), &machine.settings()));
            if let Err(why) = start {
                refuse(panel, why);
            }
        }
        MenuAction::DropBuild => *building = None,
        MenuAction::Start(feed) => {
            if let Some(mut job) = building.as_mut().and_then(|b| b.job(feed))
                && let Some(from) = *from
            {
                // A pen lift lowers the pen for a keypad drawing and raises it once it is drawn.
                if let Some(pen) = pen::for_keypad_drawing(&machine.settings()) {
                    job.pen = Some(pen);
                    job.raise_after = true;
                }
                queue(machine, panel, job, from);
            }
            *building = None;
        }
        MenuAction::JogStart(direction) => {
            // At the edge already, a jog outwards goes nowhere.
            let Some(from) = machine.plan_end() else { return refuse(panel, UiError::Busy) };
            if let Some(job) = Job::jog(direction, from.at(), &machine.settings()) {
                queue(machine, panel, job, from);
            }
        }
        MenuAction::JogStop => machine.request(Control::Abort),
        MenuAction::Control(control) => machine.request(control),
        MenuAction::Home => {
            machine.request_homing();
        }
        MenuAction::SetSetting { id, value } => change_settings(machine, panel, &[(id, value)]),
        MenuAction::Preset(preset) => change_settings(machine, panel, &preset.changes()),
        // The card's, carried out by the loop, which holds the card.
        MenuAction::ReadCard | MenuAction::PlotCard | MenuAction::CardAnswer(_) => {}
    }
}

/// Changes settings as one: all of `changes`, or, if they would leave the settings disagreeing
/// or the pen outside the travel, none, and the menu says why. The serial task keeps them in
/// flash.
fn change_settings(machine: &Machine, panel: &Panel, changes: &[(u16, f32)]) {
    let pen = machine.position();
    let before = machine.settings();
    if let Err(e) = machine.update_settings(|s| s.set_all_around(changes, pen)) {
        refuse(panel, UiError::settings_refused(&before, changes, e));
    }
}

/// Hands `job`, planned from `from`, to the motion task. The menu starts jobs only while the
/// machine is idle, so a refusal is the host link's doing: it filled the queue, or handed a job
/// over since `from` (the keypad's would start where the pen will not be). The keypad job is
/// refused, visibly, rather than waiting unseen.
fn queue(machine: &Machine, panel: &Panel, job: Job, from: PlanEnd) {
    if let Err(why) = machine.try_submit(job, from) {
        refuse(panel, UiError::Busy);
        warn!("keypad job refused: {:?}", why);
    }
}

/// Shows on the menu why what was just confirmed did not happen.
fn refuse(panel: &Panel, why: UiError) {
    panel.update(|menu| menu.refuse(why));
}
