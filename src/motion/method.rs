//! The interpolation method: how every interpolator chooses its steps (setting `$202`).
//!
//! It lives apart from the interpolators ([`crate::motion::interp`], which re-exports it) because the
//! settings hold it too, and the settings must not depend on the interpolators that read them.

/// How an interpolator chooses its steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Method {
    /// One axis per step, the original controller's point-by-point comparison; error <= 1 step.
    Classic,
    /// Both axes may step together; error <= 0.5 step, fewer and longer steps.
    #[default]
    Diagonal,
}
