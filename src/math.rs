//! Single-precision mathematics for the machine: the only floating point the firmware uses.
//!
//! The Cortex-M4F's FPU works in `f32` only; `f64` arithmetic there is a software library tens
//! of times slower, so the firmware has none. Square roots are the FPU's own instruction. The
//! elementary functions are computed in `f32` throughout: our own where `libm` computes in
//! `f64` inside (`sinf`, `cosf`, `tanf` and `asinf` do, `acosf` uses a software square root)
//! or where a little less accuracy takes much less code (atan and atan2), `libm`'s `f32`
//! functions where they stay in `f32` (exp, ln, floor, ceil, round, trunc), and the decimal
//! logarithm and the power from exp and ln. `min` and `max` are plain comparisons: `f32::min`
//! is a library call on this FPU.
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

// ----- sine, cosine, tangent ----------------------------------------------------------------
//
// x = n·π/2 + r with n an integer and |r| ≤ π/4 (Cody–Waite: π/2 in three parts, the first two
// short enough that n times them is exact), then a polynomial for sin r or cos r chosen by n
// mod 4. The polynomials are minimax (Remez exchange, relative error) on [-π/4, π/4]:
// sin r ≈ r + r·z·(S1 + z·(S2 + z·S3)) within 3.8e-9 of sin r relatively, and
// cos r ≈ 1 - z/2 + z²·(C1 + z·(C2 + z·C3)) within 1.2e-10, with z = r² (both far below an f32
// ulp, 6e-8, so the rounding of the f32 arithmetic is what remains).

/// π/2 = `FRAC_PI_2_HI + FRAC_PI_2_MID + FRAC_PI_2_LO` to 1.7e-15. HI has 8 significant bits and
/// MID 11, so `n·HI` and `n·MID` are exact f32 products for |n| < 2^13 (n has at most 13 bits).
const FRAC_PI_2_HI: f32 = 1.570_312_5;
const FRAC_PI_2_MID: f32 = 4.837_513e-4;
const FRAC_PI_2_LO: f32 = 7.549_79e-8;

/// 2/π.
const FRAC_2_PI: f32 = core::f32::consts::FRAC_2_PI;

/// 1.5·2^23: an f32 of magnitude below 2^22 plus this is rounded to an integer (ties to even),
/// which is then in the low bits of the sum's significand.
const ROUND_TO_INT_MAGIC: f32 = 12_582_912.0;

/// Largest |x| (radians) for which the reduction of sin, cos and tan is exact to 5e-11 before its
/// last rounding: n = round(x·2/π) stays below 2^13 (8191.5·π/2 ≈ 12_867.2). Beyond it products
/// start to round: sin and cos stay within 1e-6 up to 1e5 rad, then the error grows about as
/// 2^-24·|x|, the spacing of f32 numbers there, so as the argument's own precision; from
/// 2^22·π/2 ≈ 6.6e6 on even the quadrant is lost and the result means nothing, but it stays
/// finite (and within [-1, 1] for sin and cos).
pub const TRIG_ACCURATE_MAX_RAD: f32 = 12_867.0;

/// Bound on the reduced argument for |x| beyond [`TRIG_ACCURATE_MAX_RAD`], where rounding can
/// make it anything: there the polynomials stay within [-1, 1]. It is not π/4 because the
/// rounded x·2/π can pick the neighbouring n near a half-integer, leaving r a little beyond π/4
/// with the result still right.
const REDUCED_MAX_RAD: f32 = 1.0;

const S1: f32 = -1.666_665_5e-1;
const S2: f32 = 8.332_16e-3;
const S3: f32 = -1.951_528_2e-4;
const C1: f32 = 4.166_664_6e-2;
const C2: f32 = -1.388_731_6e-3;
const C3: f32 = 2.443_315_7e-5;

/// `(r, n mod 4)` with x = n·π/2 + r, |r| ≤ π/4 (a hair more at the edges). NaN for a non-finite
/// x; beyond [`TRIG_ACCURATE_MAX_RAD`] r is clamped to ±[`REDUCED_MAX_RAD`] so results stay
/// bounded.
#[inline]
fn reduce(x: f32) -> (f32, u32) {
    let t = x * FRAC_2_PI + ROUND_TO_INT_MAGIC;
    let n = t - ROUND_TO_INT_MAGIC;
    // x - n·HI is exact (Sterbenz: the two are within a factor of two of each other, or n = 0),
    // n·MID is exact and so is the difference (both are multiples of 2^-24 and it is below 1);
    // only n·LO and the last difference round.
    let r = ((x - n * FRAC_PI_2_HI) - n * FRAC_PI_2_MID) - n * FRAC_PI_2_LO;
    // The low bits of t's significand are n (two's complement modulo 2^22).
    let quadrant = t.to_bits() & 3;
    if x.abs() <= TRIG_ACCURATE_MAX_RAD {
        (r, quadrant)
    } else if x.is_finite() {
        (max(-REDUCED_MAX_RAD, min(r, REDUCED_MAX_RAD)), quadrant)
    } else {
        (f32::NAN, 0)
    }
}

/// sin r for |r| ≤ π/4.
#[inline]
fn sin_poly(r: f32) -> f32 {
    let z = r * r;
    r + r * z * (S1 + z * (S2 + z * S3))
}

/// cos r for |r| ≤ π/4.
#[inline]
fn cos_poly(r: f32) -> f32 {
    let z = r * r;
    z * z * (C1 + z * (C2 + z * C3)) - 0.5 * z + 1.0
}

/// sin x (radians). Within 1 ulp for |x| ≤ π/4; for |x| ≤ [`TRIG_ACCURATE_MAX_RAD`] within
/// 1.6 ulp of the result plus 1e-10 (the reduction's error, which shows only near the zeros),
/// at most 8e-8; see that constant beyond. NaN for an infinite or NaN x.
#[inline]
pub fn sin(x: f32) -> f32 {
    let (r, quadrant) = reduce(x);
    let v = if quadrant & 1 == 0 { sin_poly(r) } else { cos_poly(r) };
    if quadrant & 2 == 0 { v } else { -v }
}

/// cos x (radians); accuracy as [`sin`].
#[inline]
pub fn cos(x: f32) -> f32 {
    let (r, quadrant) = reduce(x);
    let v = if quadrant & 1 == 0 { cos_poly(r) } else { sin_poly(r) };
    if (quadrant + 1) & 2 == 0 { v } else { -v }
}

/// `(sin x, cos x)` for the cost of one reduction; accuracy as [`sin`].
pub fn sin_cos(x: f32) -> (f32, f32) {
    let (r, quadrant) = reduce(x);
    let (s, c) = (sin_poly(r), cos_poly(r));
    let (s, c) = if quadrant & 1 == 0 { (s, c) } else { (c, -s) };
    if quadrant & 2 == 0 { (s, c) } else { (-s, -c) }
}

// ----- inverse functions ----------------------------------------------------------------------
//
// The angle of (x, y) is k·π/2 + atan t with k = 0, 1 or 2 and |t| ≤ 1: for |y| ≤ |x| it is
// atan(|y|/x), plus π if x < 0; for |y| > |x| it is π/2 + atan(-x/|y|); y's sign is the
// result's. One division, then atan t ≈ t + t·z·(A0 + z·(A1 + … + z·A7)) with z = t², minimax
// (Remez exchange, relative error) on [0, 1]: within 1.9e-8 of atan t relatively with the
// coefficients rounded to f32, a third of an ulp. The rest is the f32 arithmetic: near |t| = 1
// the term t·z·(…) is a quarter of the result and its roundings add up to most of an ulp, and
// the quotient's rounding (half an ulp of t) is up to 0.8 ulp of the angle where t's ulp is
// twice the angle's. Checked on the host: atan over every f32 within 1.42 ulp, atan2 over 10⁹
// random pairs within 1.77 ulp. One function for both saves the 600 bytes of `libm`'s, which
// are within 1 ulp and 1.5 ulp through breakpoints and tables.

const A0: f32 = -3.333_315_3e-1;
const A1: f32 = 1.999_377_3e-1;
const A2: f32 = -1.421_105_6e-1;
const A3: f32 = 1.066_600_4e-1;
const A4: f32 = -7.552_213e-2;
const A5: f32 = 4.321_185e-2;
const A6: f32 = -1.636_792_3e-2;
const A7: f32 = 2.920_691_2e-3;

/// π/2 minus its f32, `FRAC_PI_2`: k·π/2 is `k·FRAC_PI_2 + k·FRAC_PI_2_REST` to 4e-15.
const FRAC_PI_2_REST: f32 = -4.371_139e-8;

/// atan x (radians, in [-π/2, π/2]) as the angle of (1, x): within 1.5 ulp. ±0 → ±0, ±∞ →
/// ±π/2, NaN → NaN.
pub fn atan(x: f32) -> f32 {
    atan2(x, 1.0)
}

/// The angle of (x, y) (radians, in [-π, π]): within 2 ulp. Zeros and infinities as IEEE 754
/// has them, the sign always y's: atan2(±0, +0) = ±0, atan2(±0, -0) = ±π, atan2(±∞, +∞) =
/// ±π/4, atan2(±∞, -∞) = ±3π/4. NaN if either is NaN.
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    let (a, b) = (x.abs(), y.abs());
    let steep = b > a;
    let k = if steep {
        1.0
    } else if x.is_sign_negative() {
        2.0
    } else {
        0.0
    };
    let t = if steep {
        -x / b
    } else if a == b {
        // Here too (0, 0) and (∞, ∞), whose quotients would be NaN.
        if a == 0.0 { 0.0 } else { 1.0f32.copysign(x) }
    } else {
        b / x
    };
    let z = t * t;
    let c = t * z * (A0 + z * (A1 + z * (A2 + z * (A3 + z * (A4 + z * (A5 + z * (A6 + z * A7)))))));
    let angle = k * core::f32::consts::FRAC_PI_2 + (t + (c + k * FRAC_PI_2_REST));
    angle.copysign(y)
}

/// asin x (radians, in [-π/2, π/2]) as atan2(x, √((1-x)(1+x))), with the FPU's square root:
/// within 3 ulp (2.9 at worst over every `f32` in [-1, 1]). NaN outside [-1, 1].
pub fn asin(x: f32) -> f32 {
    atan2(x, sqrt((1.0 - x) * (1.0 + x)))
}

/// acos x (radians, in [0, π]) as atan2(√((1-x)(1+x)), x): within 2.5 ulp (2.4 at worst over
/// every `f32` in [-1, 1]). NaN outside [-1, 1].
pub fn acos(x: f32) -> f32 {
    atan2(sqrt((1.0 - x) * (1.0 + x)), x)
}

// ----- libm's f32 functions that stay in f32 (each checked within 1 ulp) ----------------------

/// e^x.
pub fn exp(x: f32) -> f32 {
    libm::expf(x)
}

/// Natural logarithm.
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}

/// Decimal logarithm, ln x · log10 e: within 2 ulp, in no code of its own.
pub fn log10(x: f32) -> f32 {
    ln(x) * core::f32::consts::LOG10_E
}

/// Integer exponents up to this magnitude are powers by repeated squaring in [`pow`].
pub const POW_BY_SQUARING_MAX_EXPONENT: f32 = 1024.0;

/// x^y. An integer y of at most [`POW_BY_SQUARING_MAX_EXPONENT`] in magnitude is done by
/// repeated squaring, any x (within 2 ulp per multiplication, 20 at most). Any other y is
/// e^(y·ln x) for x ≥ 0 and NaN for x < 0: the rounding of y·ln x (up to one of its ulps) is an
/// absolute error of the exponent, so that result is within `1 + 2·|y·ln x|` ulp (10^1.5
/// within 8 ulp, 2^-0.5 within 2). Far below a step for drawing, in a quarter of the code of
/// `libm::powf`, which is within 1 ulp.
pub fn pow(x: f32, y: f32) -> f32 {
    if trunc(y) == y && y.abs() <= POW_BY_SQUARING_MAX_EXPONENT {
        let (mut n, mut square, mut product) = (y.abs() as u32, x, 1.0);
        while n > 0 {
            if n & 1 == 1 {
                product *= square;
            }
            square *= square;
            n >>= 1;
        }
        return if y < 0.0 { 1.0 / product } else { product };
    }
    if x < 0.0 {
        return f32::NAN;
    }
    exp(y * ln(x))
}

/// Largest integer not above x.
pub fn floor(x: f32) -> f32 {
    libm::floorf(x)
}

/// Smallest integer not below x.
pub fn ceil(x: f32) -> f32 {
    libm::ceilf(x)
}

/// Nearest integer, halfway cases away from zero. Out of line: it is called from many places,
/// none of them per step.
#[inline(never)]
pub fn round(x: f32) -> f32 {
    libm::roundf(x)
}

/// x without its fraction (toward zero).
pub fn trunc(x: f32) -> f32 {
    libm::truncf(x)
}

#[cfg(test)]
mod tests;
