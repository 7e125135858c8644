//! Scatter plots with reference lines as SVG documents, drawn by `plotters`: the plots of
//! `gaitclip eval --plots` (Bland–Altman, predicted against reference, error by speed).

use anyhow::{anyhow, Result};
use plotters::prelude::*;

/// Plot size, px.
const SIZE: (u32, u32) = (560, 440);
/// The colour of the points of the series drawn first, then the next ones.
pub const COLOURS: [RGBColor; 4] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0x94, 0x67, 0xbd),
];
/// The colour of the reference lines.
const LINE: RGBColor = RGBColor(0xd6, 0x27, 0x28);

struct Series {
    points: Vec<(f64, f64)>,
    colour: RGBColor,
    label: Option<String>,
}

struct Line {
    from: (f64, f64),
    to: (f64, f64),
    label: String,
    dashed: bool,
}

/// A scatter plot being built: points in series, reference lines, then [`Plot::svg`].
pub struct Plot {
    title: String,
    x_label: String,
    y_label: String,
    x: (f64, f64),
    y: (f64, f64),
    series: Vec<Series>,
    lines: Vec<Line>,
}

impl Plot {
    /// An empty plot over `x` × `y`.
    pub fn new(title: &str, x_label: &str, y_label: &str, x: (f64, f64), y: (f64, f64)) -> Plot {
        Plot {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x,
            y,
            series: Vec::new(),
            lines: Vec::new(),
        }
    }

    /// Points (clamped into the plot) in `colour`, named in the legend if `label` is given.
    pub fn points(&mut self, points: &[(f64, f64)], colour: RGBColor, label: Option<String>) {
        let c = |v: f64, r: (f64, f64)| v.clamp(r.0, r.1);
        self.series.push(Series {
            points: points
                .iter()
                .map(|&(a, b)| (c(a, self.x), c(b, self.y)))
                .collect(),
            colour,
            label,
        });
    }

    /// A straight reference line from `from` to `to`, labelled at its end.
    pub fn line(&mut self, from: (f64, f64), to: (f64, f64), label: &str, dashed: bool) {
        self.lines.push(Line {
            from,
            to,
            label: label.into(),
            dashed,
        });
    }

    /// The SVG document.
    pub fn svg(&self) -> Result<String> {
        let mut out = String::new();
        self.draw(SVGBackend::with_string(&mut out, SIZE).into_drawing_area())
            .map_err(|e| anyhow!("drawing the plot {:?}: {e}", self.title))?;
        Ok(out)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(&self.title, ("sans-serif", 15))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d(self.x.0..self.x.1, self.y.0..self.y.1)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .x_labels(5)
            .y_labels(5)
            .draw()?;
        for s in &self.series {
            let colour = s.colour;
            let drawn = chart.draw_series(
                s.points
                    .iter()
                    .map(|&p| Circle::new(p, 2, colour.mix(0.5).filled())),
            )?;
            if let Some(label) = &s.label {
                drawn
                    .label(label.as_str())
                    .legend(move |(x, y)| Circle::new((x, y), 4, colour.filled()));
            }
        }
        for l in &self.lines {
            let ends = [l.from, l.to];
            if l.dashed {
                chart.draw_series(DashedLineSeries::new(ends, 5, 4, LINE.stroke_width(1)))?;
            } else {
                chart.draw_series(LineSeries::new(ends, LINE.stroke_width(1)))?;
            }
            if !l.label.is_empty() {
                let style = ("sans-serif", 12).into_font().color(&LINE).pos(
                    plotters::style::text_anchor::Pos::new(
                        plotters::style::text_anchor::HPos::Right,
                        plotters::style::text_anchor::VPos::Bottom,
                    ),
                );
                chart.draw_series(std::iter::once(Text::new(l.label.clone(), l.to, style)))?;
            }
        }
        if self.series.iter().any(|s| s.label.is_some()) {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
        }
        root.present()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_points_lines_and_legend() {
        let mut p = Plot::new("t", "x (m)", "y (m)", (0.0, 2.0), (-1.0, 1.0));
        p.points(
            &[(0.5, 0.5), (1.5, -0.5), (9.0, 9.0)],
            COLOURS[1],
            Some("walk".into()),
        );
        p.line((0.0, 0.0), (2.0, 0.0), "bias +0.000 m", false);
        p.line((0.0, 0.5), (2.0, 0.5), "+1.96 SD", true);
        let svg = p.svg().unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert_eq!(
            svg.matches("<circle").count(),
            3 + 1,
            "3 points and 1 legend mark"
        );
        for text in ["walk", "bias +0.000 m", "+1.96 SD", "x (m)", "y (m)"] {
            assert!(svg.contains(text), "{text}");
        }
        assert!(
            svg.contains("#FF7F0E") || svg.contains("#ff7f0e"),
            "series colour"
        );
    }
}
