//! The machine's own inputs and outputs besides the step pulses: what it senses and what it
//! switches. Pure logic; the tasks sample it and drive the pins.
//!
//! Data flow: limit switches, drivers' alarms and the emergency stop -> [`inputs`] (debounced into
//! trips) -> the machine, and the `$H` cycle ([`homing`]); the machine's state -> [`pen`] (the
//! pen-lift servo), [`son`] (the drivers' servo-on) and [`signals`] (run LED, buzzer); the
//! progress of the pulse engine and the motion task -> [`watchdog`] (when it is fed); [`health`]
//! keeps what the firmware measures of itself (stack, longest poll).

// Limit switches, drivers' alarms, emergency stop: their levels and debounce.
pub mod inputs;

// The homing cycle (`$H`): its moves and where it leaves machine zero.
pub mod homing;

// The pen lift: the servo holding the pen up or down.
pub mod pen;

// The drivers' servo-on (SON): off at rest, and when they count as ready.
pub mod son;

// The run LED and the buzzer.
pub mod signals;

// When the independent watchdog is fed.
pub mod watchdog;

// What the firmware measures of itself: stack used, longest task poll.
pub mod health;
