//! Accuracy of the single-precision functions against the host's `f64` ones, which are exact to
//! far below an `f32` ulp: dense grids for the stated bounds, proptest for what holds everywhere.

extern crate std;
use super::*;
use core::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use proptest::prelude::*;

/// tan x as sin x / cos x, as the expression language's `tan` computes it. Within 3 ulp for
/// |x| ≤ π/4; for |x| ≤ [`TRIG_ACCURATE_MAX_RAD`] within 3 ulp plus 1e-8·(1 + tan²x), the
/// reduction's error times the derivative, which grows toward the poles. At the f32 nearest
/// each pole there it is large (|tan| > 1e3) but finite and within 1e-3 of itself.
fn tan(x: f32) -> f32 {
    let (s, c) = sin_cos(x);
    s / c
}

/// The spacing of `f32` numbers at `v` (the ulp of `v` rounded to `f32`).
fn ulp(v: f64) -> f64 {
    let f = (v as f32).abs();
    f64::from(f32::from_bits(f.to_bits() + 1) - f)
}

/// Error of `got` against `want`, in ulps of `want`.
fn ulps(got: f32, want: f64) -> f64 {
    (f64::from(got) - want).abs() / ulp(want)
}

/// `n + 1` points evenly spread over `[lo, hi]`, as `f32`.
fn grid(lo: f64, hi: f64, n: u32) -> impl Iterator<Item = f32> {
    (0..=n).map(move |i| (lo + (hi - lo) * f64::from(i) / f64::from(n)) as f32)
}

#[test]
fn the_parts_of_pi_over_2_multiply_exactly() {
    // 8 and 11 significant bits: times any n below 2^13 the product has at most 24.
    assert!(FRAC_PI_2_HI.to_bits().trailing_zeros() >= 23 - 7);
    assert!(FRAC_PI_2_MID.to_bits().trailing_zeros() >= 23 - 10);
    let sum = f64::from(FRAC_PI_2_HI) + f64::from(FRAC_PI_2_MID) + f64::from(FRAC_PI_2_LO);
    assert!((sum - core::f64::consts::FRAC_PI_2).abs() < 2e-15);
    assert!(f64::from(TRIG_ACCURATE_MAX_RAD) < 8191.5 * core::f64::consts::FRAC_PI_2);
}

#[test]
fn the_reduction_is_exact_but_for_its_last_rounding() {
    let limit = f64::from(TRIG_ACCURATE_MAX_RAD);
    for x in grid(-limit, limit, 2_000_000) {
        let (r, quadrant) = reduce(x);
        let n = ((f64::from(x) - f64::from(r)) / core::f64::consts::FRAC_PI_2).round();
        assert_eq!(n.rem_euclid(4.0) as u32, quadrant, "x = {x}");
        let exact = f64::from(x) - n * core::f64::consts::FRAC_PI_2;
        assert!((f64::from(r) - exact).abs() <= 0.5 * ulp(exact) + 5e-11, "x = {x}: {r} vs {exact}");
        assert!(r.abs() <= FRAC_PI_4 + 1e-3, "x = {x}: r = {r}");
    }
}

#[test]
fn sin_and_cos_within_a_quarter_turn_are_within_1_ulp() {
    for x in grid(-f64::from(FRAC_PI_4), f64::from(FRAC_PI_4), 2_000_000) {
        let xs = f64::from(x);
        assert!(ulps(sin(x), xs.sin()) <= 1.0, "sin {x}");
        assert!(ulps(cos(x), xs.cos()) <= 1.0, "cos {x}");
    }
    // Tiny arguments: sin x = x, cos x = 1.
    for x in [1e-30f32, f32::MIN_POSITIVE, 1e-45, 1e-8] {
        assert_eq!((sin(x), sin(-x), cos(x)), (x, -x, 1.0));
    }
}

#[test]
fn sin_and_cos_over_the_accurate_range() {
    // Within 1.6 ulp of the result plus 1e-10 (the reduction's error, seen only near the
    // zeros), so at most 8e-8.
    let limit = f64::from(TRIG_ACCURATE_MAX_RAD);
    for x in grid(-limit, limit, 10_000_000) {
        let xs = f64::from(x);
        for (got, want) in [(sin(x), xs.sin()), (cos(x), xs.cos())] {
            let error = (f64::from(got) - want).abs();
            assert!(error <= 1.6 * ulp(want) + 1e-10 && error <= 8e-8, "x = {x}: {got} vs {want}");
        }
    }
}

#[test]
fn sin_cos_is_sin_and_cos_and_both_are_symmetric() {
    for x in grid(-2_000.0, 2_000.0, 400_000) {
        assert_eq!(sin_cos(x), (sin(x), cos(x)), "x = {x}");
        assert_eq!(sin(-x), -sin(x), "x = {x}");
        assert_eq!(cos(-x), cos(x), "x = {x}");
    }
    assert_eq!(sin_cos(FRAC_PI_2).0, 1.0);
    assert_eq!(cos(PI), -1.0);
}

#[test]
fn beyond_the_accurate_range_precision_fades_slowly() {
    // n·MID rounds from 12_867 rad on, n·HI from 102_943: until then within 1e-6.
    for x in grid(0.0, 1e5, 1_000_000) {
        let xs = f64::from(x);
        assert!((f64::from(sin(x)) - xs.sin()).abs() <= 1e-6, "sin {x}");
        assert!((f64::from(cos(x)) - xs.cos()).abs() <= 1e-6, "cos {x}");
    }
}

#[test]
fn not_a_number_in_not_a_number_out() {
    for x in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
        assert!(sin(x).is_nan() && cos(x).is_nan() && tan(x).is_nan(), "{x}");
    }
    assert!(asin(1.000_001).is_nan() && acos(-1.5).is_nan());
}

#[test]
fn tan_is_within_3_ulp_plus_its_poles_sensitivity() {
    for x in grid(-f64::from(FRAC_PI_4), f64::from(FRAC_PI_4), 1_000_000) {
        assert!(ulps(tan(x), f64::from(x).tan()) <= 3.0, "tan {x}");
    }
    // Elsewhere the reduction's error is multiplied by tan' = 1 + tan².
    let limit = f64::from(TRIG_ACCURATE_MAX_RAD);
    for x in grid(-limit, limit, 4_000_000) {
        let want = f64::from(x).tan();
        let error = (f64::from(tan(x)) - want).abs();
        assert!(error <= 3.0 * ulp(want) + 1e-8 * (1.0 + want * want), "tan {x}: {} vs {want}", tan(x));
    }
}

#[test]
fn tan_at_the_float_nearest_each_pole_is_large_and_finite() {
    let mut k = 0.5;
    while k * core::f64::consts::PI < f64::from(TRIG_ACCURATE_MAX_RAD) {
        for pole in [k * core::f64::consts::PI, -k * core::f64::consts::PI] {
            let x = pole as f32;
            let (t, want) = (tan(x), f64::from(x).tan());
            assert!(t.is_finite() && t.abs() > 1e3, "tan({x}) = {t}");
            assert!((f64::from(t) - want).abs() <= 1e-3 * want.abs(), "tan({x}) = {t} vs {want}");
        }
        k += 1.0;
    }
}

#[test]
fn asin_and_acos_are_within_3_and_2_5_ulp() {
    for x in grid(-1.0, 1.0, 2_000_000) {
        let xs = f64::from(x);
        assert!(ulps(asin(x), xs.asin()) <= 3.0, "asin {x}");
        assert!(ulps(acos(x), xs.acos()) <= 2.5, "acos {x}");
    }
    assert_eq!((asin(1.0), asin(-1.0), asin(0.0)), (FRAC_PI_2, -FRAC_PI_2, 0.0));
    assert_eq!((acos(1.0), acos(-1.0), acos(0.0)), (0.0, PI, FRAC_PI_2));
}

#[test]
fn atan_is_within_1_5_ulp_and_atan2_within_2() {
    // Every 8th f32 of [0.5, 2), where the polynomial's term is largest and 1/x rounds, and
    // every 1021st of all the positive ones; atan is odd by construction.
    let dense = (0.5f32.to_bits()..2.0f32.to_bits()).step_by(8);
    for bits in dense.chain((0..f32::INFINITY.to_bits()).step_by(1021)) {
        let x = f32::from_bits(bits);
        assert!(ulps(atan(x), f64::from(x).atan()) <= 1.5, "atan {x}");
        assert_eq!(atan(-x), -atan(x), "atan {x}");
    }
    // Pairs in all four quadrants: |y| from 2^-30 to 2^30, x's exponent within 3 of y's or
    // within 60, by turns.
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    for i in 0..2_000_000u32 {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let (e_y, spread) = (97 + (s >> 23) as u32 % 60, if i % 2 == 0 { 7 } else { 121 });
        let e_x = e_y + (s >> 40) as u32 % spread - spread / 2;
        let y = f32::from_bits((s as u32 & 0x807f_ffff) | e_y << 23);
        let x = f32::from_bits(((s >> 32) as u32 & 0x807f_ffff) | e_x << 23);
        assert!(ulps(atan2(y, x), f64::from(y).atan2(f64::from(x))) <= 2.0, "atan2({y}, {x})");
    }
}

#[test]
fn atan_and_atan2_of_zeros_infinities_and_extremes_are_the_ieee_ones() {
    assert_eq!((atan(0.0).to_bits(), atan(-0.0).to_bits()), (0, (-0.0f32).to_bits()));
    assert_eq!((atan(f32::INFINITY), atan(f32::NEG_INFINITY)), (FRAC_PI_2, -FRAC_PI_2));
    assert!(atan(f32::NAN).is_nan() && atan2(f32::NAN, 1.0).is_nan() && atan2(0.0, f32::NAN).is_nan());
    let edges = [0.0, 1e-45, 1e-38, f32::MIN_POSITIVE, 1e-20, 0.5, 1.0, 3.0, 1e20, f32::MAX, f32::INFINITY];
    let signed = edges.iter().flat_map(|&v| [v, -v]);
    for y in signed.clone() {
        for x in signed.clone() {
            let (got, want) = (atan2(y, x), f64::from(y).atan2(f64::from(x)));
            let what = std::format!("atan2({y:e}, {x:e}) = {got:e}, not {want:e}");
            assert_eq!(got.is_sign_negative(), y.is_sign_negative(), "{what}");
            if y == 0.0 || x == 0.0 || y.is_infinite() || x.is_infinite() || y.abs() == x.abs() {
                assert_eq!(got, want as f32, "{what}");
            } else {
                assert!(ulps(got, want) <= 2.0, "{what}");
            }
        }
    }
    assert_eq!((atan2(1e-45, 1e38), atan2(1e-45, -1e38), atan2(1e38, 1e-45)), (0.0, PI, FRAC_PI_2));
}

#[test]
fn the_elementary_functions_are_within_their_bounds() {
    for i in 0..=1_000_000u32 {
        let u = f64::from(i) / 1e6;
        let x = (-80.0 + 160.0 * u) as f32;
        assert!(ulps(exp(x), f64::from(x).exp()) <= 1.0, "exp {x}");
        let p = (1e-30 * 1e60f64.powf(u)) as f32;
        assert!(ulps(ln(p), f64::from(p).ln()) <= 1.0, "ln {p}");
        assert!(ulps(log10(p), f64::from(p).log10()) <= 2.0, "log10 {p}");
        let a = (-1e4 + 2e4 * u) as f32;
        assert!(ulps(atan(a), f64::from(a).atan()) <= 1.5, "atan {a}");
        let (y, x) = ((-3.0 + 6.0 * u) as f32, (2.0 - 5.0 * u * u) as f32);
        assert!(ulps(atan2(y, x), f64::from(y).atan2(f64::from(x))) <= 2.0, "atan2({y}, {x})");
        let (b, e) = ((0.01 + 100.0 * u) as f32, (-3.0 + 6.0 * (u64::from(i) * 7_919 % 1_000_001) as f64 / 1e6) as f32);
        let bound = 1.0 + 2.0 * (f64::from(e) * f64::from(b).ln()).abs();
        assert!(ulps(pow(b, e), f64::from(b).powf(f64::from(e))) <= bound, "pow({b}, {e})");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]

    /// Any finite argument, however large: sin and cos finite and within [-1, 1].
    #[test]
    fn sin_and_cos_are_bounded_everywhere(bits in any::<u32>()) {
        let x = f32::from_bits(bits);
        prop_assume!(x.is_finite());
        let (s, c) = sin_cos(x);
        prop_assert!(s.abs() <= 1.0 && c.abs() <= 1.0, "x = {x}: {s}, {c}");
        prop_assert_eq!((s, c), (sin(x), cos(x)));
    }

    /// Random arguments of the accurate range, against the host.
    #[test]
    fn sin_cos_tan_match_the_host(x in -TRIG_ACCURATE_MAX_RAD..TRIG_ACCURATE_MAX_RAD) {
        let xs = f64::from(x);
        let (s, c) = sin_cos(x);
        prop_assert!((f64::from(s) - xs.sin()).abs() <= 1.6 * ulp(xs.sin()) + 1e-10);
        prop_assert!((f64::from(c) - xs.cos()).abs() <= 1.6 * ulp(xs.cos()) + 1e-10);
        let t = xs.tan();
        prop_assert!((f64::from(tan(x)) - t).abs() <= 3.0 * ulp(t) + 1e-8 * (1.0 + t * t));
    }

    #[test]
    fn asin_acos_match_the_host(x in -1.0f32..=1.0) {
        prop_assert!(ulps(asin(x), f64::from(x).asin()) <= 3.0);
        prop_assert!(ulps(acos(x), f64::from(x).acos()) <= 2.5);
    }
}

#[test]
fn pow_keeps_the_sign_rules_of_a_power() {
    let near = |got: f32, want: f32| (got - want).abs() <= 8.0 * f32::EPSILON * want.abs();
    assert_eq!((pow(-2.0, 5.0), pow(-2.0, 6.0), pow(-2.0, -5.0), pow(10.0, 10.0)), (-32.0, 64.0, -1.0 / 32.0, 1e10));
    assert!(near(pow(10.0, 14.0), 1e14) && near(pow(1.5, -37.0), 1.5f32.powi(-37)));
    assert!(pow(-2.0, 0.5).is_nan() && pow(f32::NAN, 2.0).is_nan());
    assert_eq!((pow(0.0, 2.5), pow(0.0, -1.5), pow(7.0, 0.0), pow(1.0, 1e30)), (0.0, f32::INFINITY, 1.0, 1.0));
    assert_eq!((pow(f32::INFINITY, 0.5), pow(f32::INFINITY, -0.5)), (f32::INFINITY, 0.0));
}
