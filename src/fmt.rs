//! Logging shim: `defmt` on target, the `log` crate on the host, in the style of embassy's own
//! `fmt.rs`. Every module logs through these macros and never names either backend.
#![allow(unused_macros)]

macro_rules! trace {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(target_os = "none")]
        ::defmt::trace!($s $(, $x)*);
        #[cfg(not(target_os = "none"))]
        ::log::trace!($s $(, $x)*);
    }};
}

macro_rules! debug {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(target_os = "none")]
        ::defmt::debug!($s $(, $x)*);
        #[cfg(not(target_os = "none"))]
        ::log::debug!($s $(, $x)*);
    }};
}

macro_rules! info {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(target_os = "none")]
        ::defmt::info!($s $(, $x)*);
        #[cfg(not(target_os = "none"))]
        ::log::info!($s $(, $x)*);
    }};
}

macro_rules! warn {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(target_os = "none")]
        ::defmt::warn!($s $(, $x)*);
        #[cfg(not(target_os = "none"))]
        ::log::warn!($s $(, $x)*);
    }};
}

macro_rules! error {
    ($s:literal $(, $x:expr)* $(,)?) => {{
        #[cfg(target_os = "none")]
        ::defmt::error!($s $(, $x)*);
        #[cfg(not(target_os = "none"))]
        ::log::error!($s $(, $x)*);
    }};
}
