//! The keypad menu: a state machine from key events to machine actions.
//!
//! [`Menu::handle`] takes one [`KeyEvent`] with the machine's status and settings and returns
//! one [`MenuAction`]; it never reads a clock and never waits. What the screen shows is read
//! back from the menu (see [`crate::panel::screen`]); the menu does not draw.
//!
//! Keys:
//!
//! - Mode list: `1`..`9` enter a mode; `A`/`B` move the cursor up/down (they repeat when held,
//!   stopping at the ends); `#` enters the mode under the cursor.
//! - Everywhere: `D` goes back to the mode list; while the machine moves (run, hold, jog) `D`
//!   aborts instead, and while a keypad jog is held it stops the jog. `C` holds a running job
//!   and resumes a held one. While a job runs or is held, every other key is ignored. An abort
//!   is said until the next key; once the machine is at rest, that key does nothing else.
//! - Number fields: digits; `*` decimal point; `A` sign; `B` deletes the last character (held,
//!   it repeats but stays in the field; pressed on an empty field it goes back to the previous
//!   field); `C` clears the field; `#` checks the value and moves on, and on the last field
//!   builds the drawing and shows its preview. A value that is refused shows why and stays for
//!   correction.
//! - Function field (`6`): `1`..`5` or `A`/`B` pick a preset; `C` types a function, starting
//!   from it ([`ExprEntry`](crate::panel::expr_entry::ExprEntry)): digits and `*` type themselves,
//!   `A`/`B` turn the token wheel back/on, `C` puts its token, `D` deletes the last one (on an
//!   empty text, back to the presets).
//! - Preview: the whole planned path; `#` starts the drawing, `D` goes back to the form.
//! - While a drawing is built (after the last `#` of a form, or `#` on the preview: the keypad
//!   task builds it a slice at a time, see [`MenuAction::Build`]), `D` drops it and the screen
//!   stays as it was; every other key waits for it.
//! - While drawing: `#` steps through the run screen's pages ([`RunPage`]). Once the machine
//!   comes to rest, the run screen stays, with the plot time, until a key is pressed; that key
//!   does nothing else.
//! - Jog: hold `1`-`4`, `6`-`9` to move (see [`JOG_KEYS`]); releasing the key stops.
//! - Home (`8`): runs the homing cycle at once when homing is on (`$22`); `D` aborts it.
//! - Settings (`7`): one `$` setting at a time ([`SettingPage`]): `A`/`B` step through them; a
//!   number key or `#` types a new value (keys as in number fields, but no sign: no setting is
//!   negative), `#` sets it, `C` sets it and moves on to the next setting, `D` drops it.
//! - Speed presets (`9`): the cursor starts on the preset in force; `1`..`3` or `A`/`B` pick
//!   one, `#` writes it into the settings ([`SpeedPreset`]).
//!
//! Every keypad drawing starts at the pen and is typed relative to it: a line is typed as its
//! offset (dX, dY) from the pen; curves are placed as described in [`crate::motion::drawing`]. So
//! that "the pen" is where the job will really start, the menu starts a job only while the
//! machine is idle with nothing queued.
//!
//! The forms of the drawing modes (their fields, the ranges and checks of what is typed, and
//! the job built from it) are [`Form`] and [`Field`]; this module routes the keys to them.

use crate::card::{CardError, CardFile, CardFiles, CardProgress, CardStop};
use crate::geom::Step;
use crate::motion::job::Control;
use crate::panel::keypad::{Key, KeyEvent};
use crate::panel::run::{Plan, Run, RunPage};
use crate::panel::trail::Trail;
use crate::settings::presets::SpeedPreset;
use crate::settings::{LANGUAGE_SETTING, Settings};
use crate::status::{RunState, Status};
use heapless::String;

mod action;
mod building;
mod card_list;
mod error;
mod form;
mod list;
mod mode;
mod setting_page;
#[cfg(test)]
mod tests;

pub use crate::unit::Unit;
pub use action::MenuAction;
pub use building::Building;
pub use card_list::CardList;
pub use error::UiError;
pub use form::{
    ARC_START_RANGE_DEG, ARC_SWEEP_RANGE_DEG, CIRCLE_RADIUS_RANGE_MM, ELLIPSE_SEMI_AXIS_RANGE_MM, FORM_MAX_FIELDS,
    FUNCTION_X_RANGE_MM, Field, Form, LINE_DELTA_RANGE_MM, NumberField, SINE_AMPLITUDE_RANGE_MM, SINE_LENGTH_RANGE_MM,
    SINE_PERIOD_RANGE_MM, SINE_PHASE_RANGE_DEG,
};
pub use mode::Mode;
pub use setting_page::SettingPage;

/// The eight jog keys, around `5` as they sit on the keypad (`2` is above `5`): `2` is +Y, `8`
/// −Y, `4` −X, `6` +X, and `1`, `3`, `7`, `9` the diagonals.
pub const JOG_KEYS: [(u8, Step); 8] = [
    (2, Step::YP),
    (8, Step::YN),
    (4, Step::XN),
    (6, Step::XP),
    (1, Step::new(-1, 1)),
    (3, Step::new(1, 1)),
    (7, Step::new(-1, -1)),
    (9, Step::new(1, -1)),
];

/// The jog direction of a key; `None` for keys that do not jog.
pub fn jog_step(key: Key) -> Option<Step> {
    match key {
        Key::Digit(d) => JOG_KEYS.iter().find(|(k, _)| *k == d).map(|&(_, s)| s),
        _ => None,
    }
}

/// A keypad jog in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ActiveJog {
    /// The key being held.
    pub key: Key,
    pub step: Step,
}

/// What the menu shows.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Screen {
    /// The mode list.
    /// The mode list as it is at power-up, the splash over it for a while: the first key acts
    /// on the mode list.
    Splash,
    Modes,
    Jog,
    Form(Form),
    /// A drawing built from the form, shown before it starts.
    Preview {
        form: Form,
        plan: Plan,
    },
    /// The `$` settings, one at a time.
    Settings(SettingPage),
    /// The speed presets, the cursor on one.
    Presets(SpeedPreset),
    /// The card's G-code files, the cursor on one.
    Card(CardList),
}

/// The keypad menu; see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct Menu {
    screen: Screen,
    /// Cursor in the mode list.
    selected: Mode,
    message: Option<UiError>,
    jog: Option<ActiveJog>,
    /// The run in progress or just ended, if any.
    run: Option<Run>,
    run_page: RunPage,
    /// How far the card plot has come.
    card_progress: CardProgress,
}

impl Default for Menu {
    fn default() -> Self {
        Self::new()
    }
}

impl Menu {
    /// The mode list, cursor on the first mode.
    pub const fn new() -> Self {
        Menu {
            screen: Screen::Splash,
            selected: Mode::Jog,
            message: None,
            jog: None,
            run: None,
            run_page: RunPage::Numbers,
            card_progress: CardProgress::None,
        }
    }

    pub fn screen(&self) -> &Screen {
        &self.screen
    }

    /// The mode under the cursor of the mode list.
    pub fn selected(&self) -> Mode {
        self.selected
    }

    /// The error to show, if any.
    pub fn message(&self) -> Option<UiError> {
        self.message
    }

    /// The keypad jog in progress, if any.
    pub fn jog(&self) -> Option<ActiveJog> {
        self.jog
    }

    /// The run in progress, or the one just ended until a key is pressed.
    pub fn run(&self) -> Option<&Run> {
        self.run.as_ref()
    }

    /// The plan shown: the preview's, or the run's (a keypad drawing).
    pub fn plan(&self) -> Option<&Plan> {
        match (&self.run, &self.screen) {
            (Some(run), _) => run.plan.as_ref(),
            (None, Screen::Preview { plan, .. }) => Some(plan),
            (None, _) => None,
        }
    }

    /// The run screen's page.
    pub fn run_page(&self) -> RunPage {
        self.run_page
    }

    /// Shows why what was just confirmed did not happen: a job that could not start (the job
    /// queue was full, the curve could not be built), settings that clash.
    pub fn refuse(&mut self, why: UiError) {
        self.message = Some(why);
        self.run = None;
        if let Some(form) = self.form_mut() {
            form.building = false;
        }
        // A setting refused shows again (`C` may have moved on), with why.
        if let (Screen::Settings(page), UiError::Clash { set, .. } | UiError::StrandsPen { set }) =
            (&mut self.screen, why)
        {
            page.show(set);
        }
    }

    /// The card read for the card mode ([`MenuAction::ReadCard`]): its files, or why none.
    pub fn card_read(&mut self, files: Result<CardFiles, CardError>) {
        if let Screen::Card(list) = &mut self.screen {
            list.read(files);
        }
    }

    /// The file under the card mode's cursor: the one [`MenuAction::PlotCard`] plots.
    pub fn card_choice(&self) -> Option<CardFile> {
        match &self.screen {
            Screen::Card(list) => list.files()?.get(list.at()).cloned(),
            _ => None,
        }
    }

    /// Follows the card's file between keys: its check and plot, and why either stopped early
    /// (said until the next key); `emitted_steps` is the machine's count. A plot starting from
    /// its check is a run with the check's plan, so the run screen gives its progress and time
    /// left. Returns true when what the screen shows changed.
    pub fn observe_card(&mut self, progress: CardProgress, stop: Option<CardStop>, emitted_steps: u32) -> bool {
        let changed = progress != self.card_progress || stop.is_some();
        if let (CardProgress::Checked(facts), CardProgress::Plotting { .. }) = (self.card_progress, progress) {
            let mut name = String::new();
            for c in self.card_choice().iter().flat_map(|f| f.name.chars()) {
                if name.push(c).is_err() {
                    break;
                }
            }
            let (steps, estimate_ms) = (facts.steps, facts.plot_time_ms);
            let plan = Plan { name, path: Trail::default(), steps, estimate_ms, first_step: emitted_steps };
            self.run = Some(Run { plan: Some(plan), started_ms: None, ended_ms: None });
            self.run_page = RunPage::Numbers;
        }
        if let (CardProgress::Offer(_), CardProgress::Plotting { .. }) = (self.card_progress, progress) {
            // A plot resumed: its run from here, without the check's plan.
            self.run = Some(Run { plan: None, started_ms: None, ended_ms: None });
            self.run_page = RunPage::Numbers;
        }
        self.card_progress = progress;
        self.message = match stop {
            Some(CardStop::Refused { line, error }) => Some(UiError::CardLine { line, error }),
            Some(CardStop::Card(e)) => Some(UiError::Card(e)),
            None => self.message,
        };
        changed
    }

    /// How far the card plot has come.
    pub fn card_progress(&self) -> CardProgress {
        self.card_progress
    }

    /// True while the menu waits for a drawing it asked to be built: the form's (its last `#`)
    /// or the preview's (`#` there).
    pub fn building(&self) -> bool {
        match &self.screen {
            Screen::Form(form) | Screen::Preview { form, .. } => form.building,
            _ => false,
        }
    }

    /// The form on the screen, itself or under its preview.
    fn form_mut(&mut self) -> Option<&mut Form> {
        match &mut self.screen {
            Screen::Form(form) | Screen::Preview { form, .. } => Some(form),
            _ => None,
        }
    }

    /// The drawing asked for with [`MenuAction::Build`] is walked (`built`): shows its preview,
    /// or starts it, if the machine is still free for it and the pen where it was built from.
    /// A drawing the menu no longer waits for is dropped.
    #[inline(never)]
    pub fn built(&mut self, built: &mut Building, status: &Status, settings: &Settings) -> MenuAction {
        if !self.building() {
            return MenuAction::None;
        }
        let result = match &mut self.screen {
            Screen::Form(form) => match form.plan(built, status, settings) {
                Ok(plan) => {
                    self.screen = Screen::Preview { form: form.clone(), plan };
                    Ok(MenuAction::None)
                }
                Err(e) => Err(e),
            },
            Screen::Preview { form, plan } => match form.started(built, status, settings) {
                Ok(feed) => {
                    let plan = Plan { first_step: status.emitted_steps, ..core::mem::take(plan) };
                    self.run = Some(Run { plan: Some(plan), started_ms: None, ended_ms: None });
                    self.run_page = RunPage::Numbers;
                    self.screen = Screen::Form(form.clone());
                    Ok(MenuAction::Start(feed))
                }
                Err(e) => Err(e),
            },
            _ => Ok(MenuAction::None),
        };
        result.unwrap_or_else(|e| {
            self.message = Some(e);
            MenuAction::None
        })
    }

    /// Follows the machine between keys: a run starts when the machine draws (a keypad drawing's
    /// at once when confirmed) and ends when it stops, at `now_ms`. Returns true when the run
    /// changed.
    pub fn observe(&mut self, status: &Status, now_ms: u32) -> bool {
        let drawing = matches!(status.state, RunState::Run | RunState::Hold);
        match &mut self.run {
            Some(run) if run.ended_ms.is_none() => {
                if run.started_ms.is_none() {
                    run.started_ms = Some(now_ms);
                } else if !status.work_left && !drawing && !self.card_progress.plotting() {
                    // A card plot's run lasts until its last line, through the rests between
                    // its strokes (a pen lift, a dwell).
                    run.ended_ms = Some(now_ms);
                } else {
                    return false;
                }
            }
            _ if drawing => {
                self.run = Some(Run { plan: None, started_ms: Some(now_ms), ended_ms: None });
                self.run_page = RunPage::Numbers;
            }
            _ => return false,
        }
        true
    }

    /// True while a run is under way (a keypad drawing confirmed counts from then on).
    fn running(&self) -> bool {
        self.run.as_ref().is_some_and(|r| r.ended_ms.is_none()) || self.card_progress.plotting()
    }

    /// True while the machine's motion takes the keypad: only `C`, `D` and `#` act. A jog counts
    /// only outside the jog screen (inside it, the jog keys steer it).
    pub fn is_busy(&self, status: &Status) -> bool {
        if self.running() {
            return true;
        }
        match status.state {
            RunState::Run | RunState::Hold | RunState::Check | RunState::Sleep | RunState::Home => true,
            RunState::Jog => self.screen != Screen::Jog,
            RunState::Idle | RunState::Alarm => false,
        }
    }

    /// Handles one key event.
    pub fn handle(&mut self, event: KeyEvent, status: &Status, settings: &Settings) -> MenuAction {
        let action = match event {
            KeyEvent::Press(key) => self.press(key, false, status, settings),
            KeyEvent::Repeat(key) if self.repeats(key, status) => self.press(key, true, status, settings),
            KeyEvent::Repeat(_) => MenuAction::None,
            KeyEvent::Release(key) => match self.jog {
                Some(jog) if jog.key == key => {
                    self.jog = None;
                    MenuAction::JogStop
                }
                _ => MenuAction::None,
            },
        };
        if !matches!(action, MenuAction::None) {
            debug!("menu: {:?}", action);
        }
        action
    }

    /// True when a held `key` repeats on the current screen: only moves through lists and
    /// deleting characters, never anything that starts motion or leaves a screen (a held `D`
    /// deleting a typed function stops at its empty text).
    fn repeats(&self, key: Key, status: &Status) -> bool {
        if self.is_busy(status) || self.building() {
            return false;
        }
        match &self.screen {
            Screen::Splash | Screen::Modes | Screen::Presets(_) | Screen::Card(_) => matches!(key, Key::A | Key::B),
            Screen::Settings(page) if page.edit().is_some() => key == Key::B,
            Screen::Settings(_) => matches!(key, Key::A | Key::B),
            Screen::Form(form) => match form.field() {
                Some(Field::Preset) if form.typing() => matches!(key, Key::A | Key::B | Key::D),
                Some(Field::Preset) => matches!(key, Key::A | Key::B),
                Some(Field::Number(_)) => key == Key::B,
                None => false,
            },
            Screen::Jog | Screen::Preview { .. } => false,
        }
    }

    fn press(&mut self, key: Key, repeated: bool, status: &Status, settings: &Settings) -> MenuAction {
        let shown = self.message.take();
        // A card file being checked, or shown checked: `#` plots it, `D` leaves it. A plot a
        // power cut stopped, offered at power-on: `#` resumes it, `D` drops it.
        match (self.card_progress, key) {
            (CardProgress::Checked(_) | CardProgress::Offer(_), Key::Hash) => return MenuAction::CardAnswer(true),
            (CardProgress::Checking { .. } | CardProgress::Checked(_) | CardProgress::Offer(_), Key::D) => {
                return MenuAction::CardAnswer(false);
            }
            (CardProgress::Checking { .. } | CardProgress::Checked(_) | CardProgress::Offer(_), _) => {
                return MenuAction::None;
            }
            _ => {}
        }
        if let Some(form) = self.form_mut().filter(|f| f.building) {
            // A drawing is being built: `D` drops it, the rest waits for it.
            if key != Key::D {
                return MenuAction::None;
            }
            form.building = false;
            return MenuAction::DropBuild;
        }
        if self.run.as_ref().is_some_and(|r| r.ended_ms.is_some()) {
            // The end screen: the key only puts it away.
            self.run = None;
            return MenuAction::None;
        }
        if shown == Some(UiError::Aborted) && !self.running() && !status.state.moving() {
            // The abort, said at rest: the key only acknowledges it (a `#` after an aborted
            // homing does not run the cycle again).
            return MenuAction::None;
        }
        if key == Key::D {
            if self.jog.take().is_some() {
                return MenuAction::JogStop;
            }
            if self.running() || matches!(status.state, RunState::Run | RunState::Hold | RunState::Jog | RunState::Home)
            {
                // Said on screen until the next key, so an abort is never silent.
                self.message = Some(UiError::Aborted);
                return MenuAction::Control(Control::Abort);
            }
            self.screen = match &mut self.screen {
                // Back from the preview to the form, as typed.
                Screen::Preview { form, .. } => Screen::Form(form.clone()),
                // Back from a value being typed to the setting, from a function to the presets.
                Screen::Settings(page) if page.edit().is_some() => {
                    page.cancel();
                    return MenuAction::None;
                }
                Screen::Form(form) if form.typing() => {
                    form.delete_typed(repeated);
                    return MenuAction::None;
                }
                _ => Screen::Modes,
            };
            return MenuAction::None;
        }
        match (key, status.state) {
            (Key::C, RunState::Run) => return MenuAction::Control(Control::Hold),
            (Key::C, RunState::Hold) => return MenuAction::Control(Control::Resume),
            (Key::Hash, _) if self.running() => {
                self.run_page = self.run_page.next();
                return MenuAction::None;
            }
            _ if self.is_busy(status) => return MenuAction::None,
            _ => {}
        }
        let result = match &mut self.screen {
            Screen::Splash | Screen::Modes => self.press_modes(key, settings),
            Screen::Settings(page) => page.press(key, repeated, settings),
            Screen::Presets(preset) => {
                if key == Key::Hash {
                    return MenuAction::Preset(*preset);
                }
                *preset = SpeedPreset::ALL[list::moved(preset.index(), SpeedPreset::ALL.len(), key)];
                Ok(MenuAction::None)
            }
            Screen::Jog => match jog_step(key) {
                Some(_) if status.state == RunState::Alarm => Err(UiError::Alarm),
                Some(step) => {
                    self.jog = Some(ActiveJog { key, step });
                    Ok(MenuAction::JogStart(step))
                }
                None => Ok(MenuAction::None),
            },
            Screen::Form(form) => match form.press(key, repeated, status, settings) {
                Ok(Some(request)) => Ok(MenuAction::Build(request)),
                Ok(None) => Ok(MenuAction::None),
                Err(e) => Err(e),
            },
            Screen::Preview { form, .. } => match key {
                Key::Hash => form.start(status, settings).map(MenuAction::Build),
                _ => Ok(MenuAction::None),
            },
            Screen::Card(list) => Ok(match list.press(key) {
                Some(_) => MenuAction::PlotCard,
                None => MenuAction::None,
            }),
        };
        result.unwrap_or_else(|e| {
            self.message = Some(e);
            MenuAction::None
        })
    }

    /// The mode list: a digit enters its mode at once.
    const _EVERY_DIGIT_HAS_A_MODE: () = assert!(Mode::ALL.len() >= 10);
    fn press_modes(&mut self, key: Key, settings: &Settings) -> Result<MenuAction, UiError> {
        self.screen = Screen::Modes;
        let at = list::moved(self.selected.index(), Mode::ALL.len(), key);
        self.selected = Mode::ALL[at];
        match key {
            Key::Hash => self.enter(self.selected, settings),
            // Every digit has its mode: 1 the first, 0 the tenth.
            Key::Digit(_) => self.enter(self.selected, settings),
            _ => Ok(MenuAction::None),
        }
    }

    /// Enters `mode`'s screen; homing starts at once, from the mode list.
    fn enter(&mut self, mode: Mode, settings: &Settings) -> Result<MenuAction, UiError> {
        self.selected = mode;
        self.screen = match mode {
            Mode::Jog => Screen::Jog,
            Mode::Settings => Screen::Settings(SettingPage::new()),
            // On the preset in force, if one is.
            Mode::Presets => Screen::Presets(
                SpeedPreset::ALL.into_iter().find(|p| p.is_set(settings)).unwrap_or(SpeedPreset::FinePen),
            ),
            Mode::Home if !settings.homing => return Err(UiError::HomingOff),
            Mode::Home => return Ok(MenuAction::Home),
            Mode::Language => {
                let value = f32::from(settings.language.other() as u8);
                return Ok(MenuAction::SetSetting { id: LANGUAGE_SETTING, value });
            }
            Mode::Card => {
                self.screen = Screen::Card(CardList::reading());
                return Ok(MenuAction::ReadCard);
            }
            _ => Screen::Form(Form::new(mode)),
        };
        Ok(MenuAction::None)
    }
}
