//! Part 2 of the motion benchmark: a deterministic polyline drawing (an Archimedean spiral of
//! 2,000 short segments, stroke letters and a zig-zag hatch) pushed segment by segment as the
//! motion task does: plot time with look-ahead, without (every segment alone, stopping at every
//! joint), the seed's time, and `plot_time_lower_bound`.

use super::*;

/// Segments of the reference spiral.
const SPIRAL_SEGMENTS: usize = 2_000;
/// Radius where the spiral starts, mm.
const SPIRAL_START_RADIUS_MM: f64 = 5.0;
/// Distance between turns, mm.
const SPIRAL_PITCH_MM: f64 = 1.5;
/// Segment lengths of the spiral vary between these, mm.
const SPIRAL_SEGMENT_MIN_MM: f64 = 0.2;
const SPIRAL_SEGMENT_MAX_MM: f64 = 0.5;

/// An Archimedean spiral `r = r0 + pitch·θ/2π` cut into segments of 0.2–0.5 mm (lengths from a
/// fixed low-discrepancy sequence), outward and counter-clockwise, starting at the origin; in steps.
fn spiral() -> Vec<Point> {
    let b = SPIRAL_PITCH_MM / std::f64::consts::TAU;
    let at = |theta: f64| {
        let r = SPIRAL_START_RADIUS_MM + b * theta;
        (r * theta.cos() - SPIRAL_START_RADIUS_MM, r * theta.sin())
    };
    let mut theta = 0.0f64;
    let mut points = vec![Point::ORIGIN];
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    for i in 0..SPIRAL_SEGMENTS {
        let frac = (i as f64 * golden).fract();
        let len = SPIRAL_SEGMENT_MIN_MM + (SPIRAL_SEGMENT_MAX_MM - SPIRAL_SEGMENT_MIN_MM) * frac;
        let r = SPIRAL_START_RADIUS_MM + b * theta;
        theta += len / r.hypot(b);
        let (x, y) = at(theta);
        points.push(Point::new((x * SPM).round() as i32, (y * SPM).round() as i32));
    }
    points
}

/// Stroke letters (corners of each letter's single stroke, in a 4 × 6 mm cell).
const LETTERS: &[&[(f64, f64)]] = &[
    &[(0.0, 0.0), (0.0, 6.0), (2.0, 3.0), (4.0, 6.0), (4.0, 0.0)], // M
    &[(0.0, 6.0), (1.0, 0.0), (2.0, 4.0), (3.0, 0.0), (4.0, 6.0)], // W
    &[(0.0, 0.0), (0.0, 6.0), (4.0, 0.0), (4.0, 6.0)],             // N
    &[(0.0, 6.0), (4.0, 6.0), (0.0, 0.0), (4.0, 0.0)],             // Z
    &[(0.0, 0.0), (2.0, 6.0), (4.0, 0.0), (3.0, 3.0), (1.0, 3.0)], // A
    &[(0.0, 0.0), (0.0, 6.0), (0.0, 3.0), (4.0, 6.0), (1.5, 4.0), (4.0, 0.0)], // K
    &[(4.0, 6.0), (0.0, 6.0), (0.0, 3.0), (3.0, 3.0), (0.0, 3.0), (0.0, 0.0), (4.0, 0.0)], // E
    &[(4.0, 6.0), (0.0, 6.0), (0.0, 0.0), (4.0, 0.0), (4.0, 3.0), (2.0, 3.0)], // G
];
/// Letter spacing, mm; the pen draws the move between letters (the machine has no pen lift).
const LETTER_PITCH_MM: f64 = 5.0;
/// Times the letter row is written, one row under the other, and the distance between rows, mm.
const LETTER_ROWS: usize = 3;
const LETTER_ROW_PITCH_MM: f64 = 8.0;
/// Zig-zag hatch: strokes, width and advance per stroke, mm.
const HATCH_STROKES: usize = 200;
const HATCH_WIDTH_MM: f64 = 2.0;
const HATCH_ADVANCE_MM: f64 = 0.25;

/// Rows of stroke letters, one row under the other, starting at the origin; in steps.
fn letters() -> Vec<Point> {
    let mut mm: Vec<(f64, f64)> = Vec::new();
    for row in 0..LETTER_ROWS {
        let y0 = -(row as f64) * LETTER_ROW_PITCH_MM;
        for (k, letter) in LETTERS.iter().enumerate() {
            let x0 = k as f64 * LETTER_PITCH_MM;
            mm.extend(letter.iter().map(|&(x, y)| (x0 + x, y0 + y)));
        }
    }
    to_steps(&mm)
}

/// A zig-zag hatch going down, starting at the origin; in steps.
fn hatch() -> Vec<Point> {
    let mm: Vec<(f64, f64)> = (0..=HATCH_STROKES)
        .map(|i| (if i % 2 == 0 { 0.0 } else { HATCH_WIDTH_MM }, -(i as f64) * HATCH_ADVANCE_MM))
        .collect();
    to_steps(&mm)
}

/// Millimetre points to lattice points, moved so that the first is the origin.
fn to_steps(mm: &[(f64, f64)]) -> Vec<Point> {
    let (x0, y0) = mm[0];
    mm.iter().map(|&(x, y)| Point::new(((x - x0) * SPM).round() as i32, ((y - y0) * SPM).round() as i32)).collect()
}

/// `a` then `b` moved to start where `a` ends.
fn chain(a: &[Point], b: &[Point]) -> Vec<Point> {
    let end = a[a.len() - 1];
    a.iter().copied().chain(b.iter().skip(1).map(|p| Point::new(p.x + end.x, p.y + end.y))).collect()
}

fn line_to(to: Point, at: Point, settings: &Settings) -> Curve {
    match Curve::new(&Shape::Straight { to }, at, settings) {
        Ok(c) => c,
        Err(e) => panic!("a line to {to:?} was refused: {e:?}"),
    }
}

/// Draws the polyline as the motion task does: push while the planner has room, otherwise take
/// the next command. Returns the steps, the ticks and the end point.
#[inline(never)]
fn draw_lookahead(points: &[Point], settings: &Settings) -> (u64, u64, Point) {
    let mut p = Planner::<Curve, PLANNER_SEGMENTS>::new(Limits::from_settings(settings));
    let (mut next, mut planned_end, mut at) = (1, points[0], points[0]);
    let (mut n, mut ticks) = (0u64, 0u64);
    loop {
        while next < points.len() && !p.is_full() {
            let curve = line_to(points[next], planned_end, settings);
            planned_end = points[next];
            if p.push(curve, DRAW_FEED, settings.method).is_err() {
                panic!("the planner refused a segment it had room for");
            }
            next += 1;
        }
        match p.next_cmd() {
            Some(Ok(c)) => {
                n += 1;
                ticks += u64::from(c.interval_ticks);
                at = at.stepped(c.step);
            }
            Some(Err(e)) => panic!("a line failed in the planner: {e:?}"),
            None if next >= points.len() => break,
            None => {}
        }
    }
    (n, ticks, at)
}

/// Draws the polyline one segment at a time: each is planned alone and stops at its end.
fn draw_one_by_one(points: &[Point], settings: &Settings) -> (u64, u64, Point) {
    let mut p = Planner::<Curve, PLANNER_SEGMENTS>::new(Limits::from_settings(settings));
    let (mut n, mut ticks, mut at) = (0u64, 0u64, points[0]);
    for &to in &points[1..] {
        let curve = line_to(to, at, settings);
        at = to;
        if p.push(curve, DRAW_FEED, settings.method).is_err() {
            panic!("an idle planner refused a segment");
        }
        let (k, t) = drain(&mut p);
        n += k;
        ticks += t;
    }
    (n, ticks, at)
}

fn length_mm(points: &[Point]) -> f64 {
    points.windows(2).map(|w| (f64::from(w[1].x - w[0].x) / SPM).hypot(f64::from(w[1].y - w[0].y) / SPM)).sum()
}

pub fn table() {
    let spiral = spiral();
    let letters = letters();
    let hatch = hatch();
    let whole = chain(&chain(&spiral, &letters), &hatch);
    let drawings: [(&str, &[Point]); 4] = [
        ("spiral, 2,000 × 0.2–0.5 mm", &spiral),
        ("24 stroke letters, 4 × 6 mm", &letters),
        ("zig-zag hatch, 200 × 2 mm", &hatch),
        ("whole: spiral, letters, hatch", &whole),
    ];
    println!("### Polyline drawing: look-ahead vs stopping at every joint");
    println!();
    println!(
        "Every segment is a G1 line at F{DRAW_FEED_MM_PER_MIN} mm/min, `Settings::default()` \
         (junction deviation 0.02 mm, acceleration 500 mm/s², start rate 300 mm/min), look-ahead of \
         {PLANNER_SEGMENTS} segments. Bound: `plot_time_lower_bound`."
    );
    println!();
    println!(
        "| drawing | method | segments | length (mm) | steps | look-ahead (s) | no look-ahead (s) | seed: classic, constant 500 steps/s (s) | lower bound (s) | look-ahead / bound | CPU incl. line setup (ns/step) |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (name, points) in drawings {
        for method in [Method::Classic, Method::Diagonal] {
            let settings = settings_for(method);
            let limits = Limits::from_settings(&settings);
            let end = points[points.len() - 1];
            let (steps, ticks, at) = draw_lookahead(points, &settings);
            let (steps_alone, ticks_alone, at_alone) = draw_one_by_one(points, &settings);
            assert_eq!((at, at_alone), (end, end), "{name}: the pen must end at the last point");
            assert_eq!(steps, steps_alone, "{name}: same steps with and without look-ahead");
            let classic_axis = points.windows(2).fold([0u64; 2], |acc, w| {
                [acc[0] + w[1].x.abs_diff(w[0].x) as u64, acc[1] + w[1].y.abs_diff(w[0].y) as u64]
            });
            let seed = seed_seconds(&settings, classic_axis);
            let bound = f64::from(plot_time_lower_bound(&limits, method, DRAW_FEED, points));
            let time = ticks as f64 / f64::from(TICK_HZ);
            let cpu = ns_per_step(|| (), |()| black_box(draw_lookahead(points, &settings)).0);
            println!(
                "| {} | {} | {} | {:.1} | {} | {:.3} | {:.3} | {:.1} | {:.3} | {:.3} | {:.1} |",
                name,
                method_name(method),
                points.windows(2).filter(|w| w[0] != w[1]).count(),
                length_mm(points),
                steps,
                time,
                ticks_alone as f64 / f64::from(TICK_HZ),
                seed,
                bound,
                time / bound,
                cpu
            );
        }
    }
    println!();
}
