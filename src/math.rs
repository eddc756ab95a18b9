//! Single-precision mathematics for the machine: the only floating point the firmware uses.
//!
//! The Cortex-M4F's FPU works in `f32` only; `f64` arithmetic there is a software library tens
//! of times slower, so the firmware has none. Square roots are the FPU's own instruction. The
//! elementary functions are computed in `f32` throughout (the `f32` functions of `libm` that
//! work in `f32` inside, and our own where `libm` computes in `f64`). `min` and `max` are plain
//! comparisons: `f32::min` is a library call on this FPU.
//!
//! Owns no state. Everything here is a pure function of its arguments.

// The FPU's square root as a function of its own: `asm!` cannot name FPU registers on stable
// Rust, but under the hard-float calling convention the argument and the result are in s0.
#[cfg(all(target_arch = "arm", target_os = "none"))]
core::arch::global_asm!(
    ".section .text.servoplot_vsqrtf,\"ax\",%progbits",
    ".global servoplot_vsqrtf",
    ".type servoplot_vsqrtf,%function",
    ".fpu fpv4-sp-d16",
    ".thumb_func",
    "servoplot_vsqrtf:",
    "vsqrt.f32 s0, s0",
    "bx lr",
    ".size servoplot_vsqrtf, . - servoplot_vsqrtf",
);

#[cfg(all(target_arch = "arm", target_os = "none"))]
unsafe extern "C" {
    fn servoplot_vsqrtf(x: f32) -> f32;
}

/// √x, correctly rounded (IEEE 754, as the FPU's VSQRT); NaN for x < 0.
#[inline]
pub fn sqrt(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_os = "none"))]
    {
        // SAFETY: the function above reads s0 and writes s0, as the calling convention allows.
        unsafe { servoplot_vsqrtf(x) }
    }
    #[cfg(not(all(target_arch = "arm", target_os = "none")))]
    {
        libm::sqrtf(x)
    }
}

/// The smaller of `a` and `b` (`b` if either is NaN).
#[inline]
pub fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// The larger of `a` and `b` (`b` if either is NaN).
#[inline]
pub fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// √(x² + y²) without overflow for large arguments.
pub fn hypot(x: f32, y: f32) -> f32 {
    let (x, y) = (x.abs(), y.abs());
    let m = max(x, y);
    if m == 0.0 || !m.is_finite() {
        return m + min(x, y);
    }
    let (u, v) = (x / m, y / m);
    m * sqrt(u * u + v * v)
}

pub fn sin(x: f32) -> f32 {
    libm::sinf(x)
}

pub fn cos(x: f32) -> f32 {
    libm::cosf(x)
}

/// `(sin x, cos x)`.
pub fn sin_cos(x: f32) -> (f32, f32) {
    (sin(x), cos(x))
}

pub fn tan(x: f32) -> f32 {
    libm::tanf(x)
}

pub fn asin(x: f32) -> f32 {
    libm::asinf(x)
}

pub fn acos(x: f32) -> f32 {
    libm::acosf(x)
}

pub fn atan(x: f32) -> f32 {
    libm::atanf(x)
}

pub fn atan2(y: f32, x: f32) -> f32 {
    libm::atan2f(y, x)
}

pub fn exp(x: f32) -> f32 {
    libm::expf(x)
}

/// Natural logarithm.
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}

pub fn log10(x: f32) -> f32 {
    libm::log10f(x)
}

pub fn pow(x: f32, y: f32) -> f32 {
    libm::powf(x, y)
}

pub fn floor(x: f32) -> f32 {
    libm::floorf(x)
}

pub fn ceil(x: f32) -> f32 {
    libm::ceilf(x)
}

/// Nearest integer, halfway cases away from zero.
pub fn round(x: f32) -> f32 {
    libm::roundf(x)
}

pub fn trunc(x: f32) -> f32 {
    libm::truncf(x)
}
