//! What the menu asks the machine to do: the one [`MenuAction`] each key event gives.

use crate::geom::Step;
use crate::motion::drawing::Request;
use crate::motion::job::{Control, Feed};
use crate::settings::presets::SpeedPreset;

/// What the menu asks the machine to do.
// A drawing to build carries its expression by value (no heap).
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum MenuAction {
    None,
    /// Build this drawing from the pen, a slice at a time, and hand it to [`Menu::built`]
    /// (or, refused, to [`Menu::refuse`]).
    ///
    /// [`Menu::built`]: super::Menu::built
    /// [`Menu::refuse`]: super::Menu::refuse
    Build(Request),
    /// Drop the drawing being built: the menu no longer waits for it.
    DropBuild,
    /// Queue the job of the drawing just built ([`Building::job`](super::Building::job)), at
    /// this feed: only [`Menu::built`](super::Menu::built) asks for it.
    Start(Feed),
    /// Hold, resume or abort the motion in progress.
    Control(Control),
    /// Start jogging in one of the 8 step directions until [`MenuAction::JogStop`].
    JogStart(Step),
    JogStop,
    /// Run the homing cycle.
    Home,
    /// Set setting `$id` to `value` (checked against its range).
    SetSetting {
        id: u16,
        value: f32,
    },
    /// Write a speed preset into the settings.
    Preset(SpeedPreset),
    /// Read the card's G-code files and hand them to [`Menu::card_read`](super::Menu::card_read).
    ReadCard,
    /// Check the card file under the cursor ([`Menu::card_choice`](super::Menu::card_choice))
    /// and show it, to plot.
    PlotCard,
    /// The answer to the card file's check: plot it (`true`), or leave it (a check under way
    /// stops).
    CardAnswer(bool),
}
