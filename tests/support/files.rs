//! G-code files as the tools that feed plotters write them, for the tests that plot and check
//! them.

use std::fmt::Write;

/// A file as vpype writes it for a pen lifted by M3/M5: closed polylines (polygons of many short
/// segments, on circles of different sizes) drawn pen down, with pen-up travel between them.
pub fn polyline_file() -> String {
    let mut out = String::from("$213=1\nG21\nG90\n");
    for (k, (cx, cy, r, sides)) in
        [(0.0, 0.0, 30.0, 90), (60.0, 20.0, 15.0, 48), (-50.0, 40.0, 20.0, 64), (20.0, -60.0, 40.0, 120)]
            .into_iter()
            .enumerate()
    {
        let at = |i: usize| {
            let t = std::f64::consts::TAU * i as f64 / sides as f64;
            (cx + r * t.cos(), cy + r * t.sin())
        };
        let (x, y) = at(0);
        writeln!(out, "G0 X{x:.3} Y{y:.3}\nM3").unwrap();
        for i in 1..=sides {
            let (x, y) = at(i);
            let feed = if i == 1 { format!(" F{}", 2000 + 500 * k) } else { String::new() };
            writeln!(out, "G1 X{x:.3} Y{y:.3}{feed}").unwrap();
        }
        out.push_str("M5\n");
    }
    out.push_str("G0 X0 Y0\nM2\n");
    out
}

/// A file of arcs: a chain of half circles of different radii turning both ways (a scalloped
/// line), full circles, an R-word arc and lines between.
pub fn arc_file() -> String {
    let mut out = String::from("G21\nG90\nG0 X-150 Y0\nF2400\n");
    let mut x = -150.0;
    let radii = [5.0, 10.0, 3.0, 8.0, 12.0, 6.0, 1.5, 4.0];
    for (i, r) in radii.iter().chain(&radii).chain(&radii).map(|r| r / 2.0).enumerate() {
        let g = if i % 2 == 0 { "G2" } else { "G3" };
        writeln!(out, "{g} X{:.3} Y0 I{r:.3} J0", x + 2.0 * r).unwrap();
        x += 2.0 * r;
    }
    out.push_str("G1 X10 Y0\nG2 X10 Y0 I15 J0\nG3 X40 Y30 R30\nG1 X40 Y50\n");
    out.push_str("G91\nG2 X20 Y20 I20 J0\nG3 X-10 Y10 I-10 J0\nG2 X0 Y0 I0 J-25 F3600\nG90\nG0 X0 Y0\n");
    out
}
