//! The plots in docs/, drawn with `plotters` as SVG (grid lines, log axes, legends) and written
//! atomically: a failed command leaves no half-written plot.

use anyhow::{anyhow, Result};
use host_sim::output::write_atomic;
use plotters::prelude::*;
use std::path::Path;

/// Line and dot colours (Tableau 10: distinct and readable on white).
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Colour `i` of [`COLOURS`], cycling.
fn colour(i: usize) -> RGBAColor {
    COLOURS[i % COLOURS.len()].to_rgba()
}

/// Width and height of every plot, in SVG pixels.
const SIZE: (u32, u32) = (900, 540);

/// Draws into an SVG string with `draw`, then writes it to `path`.
fn write_svg(
    path: &Path,
    draw: impl FnOnce(DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<()>,
) -> Result<()> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("plot: {e}"))?;
        draw(root.clone())?;
        root.present().map_err(|e| anyhow!("plot: {e}"))?;
    }
    write_atomic(path, svg.as_bytes())
}

/// The lowest and highest value of `v` widened to whole decades (for a log axis).
fn decades(v: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = v.filter(|x| *x > 0.0).fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
    if lo > hi {
        return 1.0..10.0;
    }
    10f64.powf(lo.log10().floor())..10f64.powf(hi.log10().ceil().max(lo.log10().floor() + 1.0))
}

/// One line per series on log-log axes, dots at the measured points; a series whose name
/// starts with `clustered` is drawn thin.
pub fn loglog(
    path: &Path,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<()> {
    let xs = decades(series.iter().flat_map(|(_, v)| v.iter().map(|p| p.0)));
    let ys = decades(series.iter().flat_map(|(_, v)| v.iter().map(|p| p.1)));
    write_svg(path, |root| {
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(xs.log_scale(), ys.log_scale())
            .map_err(|e| anyhow!("plot: {e}"))?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .x_label_formatter(&|v| format!("{v}"))
            .y_label_formatter(&|v| format!("{v}"))
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(|e| anyhow!("plot: {e}"))?;
        for (i, (label, pts)) in series.iter().enumerate() {
            let c = colour(i);
            let width = if label.starts_with("clustered") { 1 } else { 2 };
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(width)))
                .map_err(|e| anyhow!("plot: {e}"))?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled()))).map_err(|e| anyhow!("plot: {e}"))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 12))
            .draw()
            .map_err(|e| anyhow!("plot: {e}"))
    })
}

/// A point of a scatter plot: its label, the group it is coloured by, x and y.
pub type Labelled<'a> = (String, &'a str, f64, f64);

/// Numbered dots coloured by group on linear axes from zero, with the numbered labels listed
/// beside the chart.
pub fn scatter(path: &Path, title: &str, x_desc: &str, y_desc: &str, points: &[Labelled<'_>]) -> Result<()> {
    let xmax = points.iter().map(|p| p.2).fold(0.0, f64::max).max(1e-9) * 1.1;
    let ymax = points.iter().map(|p| p.3).fold(0.0, f64::max).max(1e-9) * 1.1;
    let mut groups: Vec<&str> = Vec::new();
    for p in points {
        if !groups.contains(&p.1) {
            groups.push(p.1);
        }
    }
    let colour = |g: &str| colour(groups.iter().position(|x| *x == g).unwrap_or(0));
    write_svg(path, |root| {
        let (left, right) = root.split_horizontally(SIZE.0 - 300);
        let mut chart = ChartBuilder::on(&left)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..xmax, 0.0..ymax)
            .map_err(|e| anyhow!("plot: {e}"))?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .label_style(("sans-serif", 13))
            .draw()
            .map_err(|e| anyhow!("plot: {e}"))?;
        for g in &groups {
            let c = colour(g);
            let mine: Vec<(usize, &Labelled<'_>)> = points.iter().enumerate().filter(|(_, p)| p.1 == *g).collect();
            chart
                .draw_series(mine.iter().map(|(i, p)| {
                    EmptyElement::at((p.2, p.3))
                        + Circle::new((0, 0), 5, c.filled())
                        + Text::new(format!("{}", i + 1), (6, -14), ("sans-serif", 12).into_font().color(&c))
                }))
                .map_err(|e| anyhow!("plot: {e}"))?
                .label(*g)
                .legend(move |(x, y)| Circle::new((x + 8, y), 5, c.filled()));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 12))
            .draw()
            .map_err(|e| anyhow!("plot: {e}"))?;
        for (i, p) in points.iter().enumerate() {
            let style = ("sans-serif", 12).into_font().color(&colour(p.1));
            right
                .draw(&Text::new(format!("{:2} {}: {}", i + 1, p.1, p.0), (8, 40 + 15 * i as i32), style))
                .map_err(|e| anyhow!("plot: {e}"))?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_are_svg_with_their_labels_and_leave_nothing_on_failure() {
        let dir = std::env::temp_dir().join(format!("plot-test-{}", std::process::id()));
        let (a, b) = (dir.join("a.svg"), dir.join("b.svg"));
        loglog(&a, "T", "x", "y", &[("lattice".into(), vec![(10.0, 0.5), (1000.0, 2.0)])]).unwrap();
        scatter(&b, "T", "x", "y", &[("f64".into(), "scalar", 1.0, 0.5), ("bayer".into(), "dither", 2.0, 0.7)])
            .unwrap();
        for (path, label) in [(&a, "lattice"), (&b, "bayer")] {
            let svg = std::fs::read_to_string(path).unwrap();
            assert!(svg.starts_with("<svg") && svg.contains(label), "{}", path.display());
        }
        let bad = dir.join("a.svg").join("c.svg");
        assert!(loglog(&bad, "T", "x", "y", &[]).is_err());
        assert!(!bad.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
