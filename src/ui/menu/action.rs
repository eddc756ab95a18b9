//! What the menu asks the machine to do: the one [`MenuAction`] each key event gives.

use crate::geom::Step;
use crate::job::{Control, Job};
use crate::settings::presets::SpeedPreset;

/// What the menu asks the machine to do.
// A started job carries its curve by value (no heap).
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum MenuAction {
    None,
    /// Queue a job.
    Start(Job),
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
}
