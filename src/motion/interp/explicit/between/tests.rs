//! The check between columns on curves given as functions of the column: smooth curves of any
//! size, sines down to a few steps per wave, kinks and staircases pass; waves the columns miss
//! are refused, from the first chord that shows it to the last.

extern crate std;
use super::*;
use core::f32::consts::{PI, TAU};

/// Runs the check along `h` (rows at a column, fractional columns allowed) over `chords`
/// chords: `Ok` when every chord passes, else the chord being fed when one was refused.
fn check(h: impl Fn(f32) -> f32, chords: i32) -> Result<(), i32> {
    let mut between = BetweenColumns::default();
    for k in 0..chords {
        let u = sample_fraction(k);
        let (h0, h1) = (h(k as f32), h(k as f32 + 1.0));
        between.chord(h0, h1, h(k as f32 + u)).map_err(|_| k)?;
    }
    between.end().map_err(|_| chords)
}

/// A sine of `amplitude` rows and `steps_per_wave` columns per wave, at `phase` radians.
fn sine(amplitude: f32, steps_per_wave: f32, phase: f32) -> impl Fn(f32) -> f32 {
    move |t| amplitude * (TAU * t / steps_per_wave + phase).sin()
}

#[test]
fn sample_fractions_lie_between_the_columns_and_spread_over_every_part_of_the_chord() {
    let mut seen = [0u32; 16];
    for k in 0..1600 {
        let u = sample_fraction(k);
        assert!(u > 0.0 && u < 1.0, "chord {k}: {u}");
        seen[(u * 16.0) as usize] += 1;
    }
    // The golden-ratio sequence: every sixteenth of a chord within a few of its hundred.
    assert!(seen.iter().all(|&n| (90..=110).contains(&n)), "{seen:?}");
}

#[test]
fn smooth_curves_pass_however_large() {
    // Parabolas, a cubic and a Gaussian bump of up to a hundred thousand rows.
    for scale in [1.0, 100.0, 10_000.0, 100_000.0] {
        assert_eq!(check(|t| scale * (t / 100.0 - 1.0).powi(2), 200), Ok(()), "parabola {scale}");
        assert_eq!(check(|t| scale * ((t - 100.0) / 100.0).powi(3), 200), Ok(()), "cubic {scale}");
        assert_eq!(check(|t| scale * (-((t - 100.0) / 20.0).powi(2)).exp(), 200), Ok(()), "gauss {scale}");
    }
}

#[test]
fn sines_of_three_steps_per_wave_or_more_pass_at_any_phase_and_amplitude() {
    for steps_per_wave in [3.0, 4.0, 5.0, 8.0, 10.0, 40.0] {
        for amplitude in [0.5, 3.0, 300.0, 30_000.0] {
            for phase in [0.0, 0.3, PI / 4.0, 1.0, PI / 2.0, 2.0] {
                let wave = sine(amplitude, steps_per_wave, phase);
                assert_eq!(check(wave, 400), Ok(()), "{steps_per_wave} steps per wave, A {amplitude}, phase {phase}");
            }
        }
    }
}

#[test]
fn a_wave_the_columns_miss_is_refused_at_once() {
    // sin(x*628.3)*3 at 100 steps/mm: one wave per step, 300 rows high; the columns see it
    // drift slowly, the curve between them swings its whole height.
    // ω = 628.3 rad/mm is 6.283 rad a step, a little under a whole turn.
    let per_step = 628.3 / 100.0;
    let aliased = |t: f32| 300.0 * (per_step * t).sin();
    let refused_at = check(aliased, 500).expect_err("refused");
    assert!(refused_at <= 3, "refused only at chord {refused_at}");
    // Two, three waves per step, the waves between one and three a step, and waves of up to
    // 2.25 steps, which the columns see as slower waves or alternating, of any height.
    for steps_per_wave in [0.5, 1.0 / 3.0, 0.6, 2.0 / 3.0, 0.75, 0.8, 0.9, 0.95, 0.99, 1.1, 1.25, 1.5, 1.75, 2.0, 2.25]
    {
        for amplitude in [30.0, 300.0, 30_000.0] {
            for phase in [0.0, 0.2, 1.0] {
                let wave = sine(amplitude, steps_per_wave, phase);
                assert!(check(wave, 500).is_err(), "{steps_per_wave} steps per wave, A {amplitude}, phase {phase}");
            }
        }
    }
}

#[test]
fn a_wave_the_columns_miss_on_a_slope_is_refused_too() {
    // The columns rise evenly a hundred rows each: they show no bend, the curve wiggles.
    let wiggle_on_slope = |t: f32| 100.0 * t + 300.0 * (TAU * t * 1.001).sin();
    assert!(check(wiggle_on_slope, 500).is_err());
}

#[test]
fn a_wiggle_within_a_step_passes() {
    // Drawn flat, the path stays within a step of it.
    assert_eq!(check(sine(0.45, 1.0 / 1.0001, 0.0), 2000), Ok(()));
}

#[test]
fn kinks_and_staircases_pass() {
    // A riser in any part of a chord, on a slope the other way.
    for at in [10.01, 10.5, 10.99] {
        let stairs = |t: f32| if t < at { -t } else { 30.0 - t };
        assert_eq!(check(stairs, 20), Ok(()), "riser at {at}");
    }
    // |x| at 10 rows per column, its corner anywhere in a chord.
    for corner in [10.0, 10.25, 10.5, 10.9] {
        assert_eq!(check(|t| 10.0 * (t - corner).abs(), 20), Ok(()), "corner at {corner}");
    }
    // floor: steps of 100 rows every ten columns, anywhere in a chord.
    for offset in [0.0, 0.3, 0.5, 0.99] {
        assert_eq!(check(|t| 100.0 * ((t + offset) / 10.0).floor(), 100), Ok(()), "offset {offset}");
    }
}

#[test]
fn the_last_chord_and_a_lone_chord_are_judged_at_the_end() {
    // Straight, then a bulge of three rows in the last chord.
    let bulge = |t: f32| if t > 9.0 { 3.0 * (PI * (t - 9.0)).sin() } else { 0.0 };
    assert_eq!(check(bulge, 10), Err(10));
    // One chord, straying two rows: nothing around it shows a bend.
    let mut one = BetweenColumns::default();
    assert_eq!(one.chord(0.0, 0.0, 2.0), Ok(()));
    assert_eq!(one.end(), Err(CurveError::Aliased));
    // One row is allowed.
    let mut one = BetweenColumns::default();
    assert_eq!(one.chord(0.0, 0.0, 1.0), Ok(()));
    assert_eq!(one.end(), Ok(()));
}

#[test]
fn a_value_that_is_not_a_number_is_refused() {
    let mut between = BetweenColumns::default();
    assert_eq!(between.chord(0.0, 1.0, f32::NAN), Ok(()));
    assert_eq!(between.end(), Err(CurveError::Aliased));
}
