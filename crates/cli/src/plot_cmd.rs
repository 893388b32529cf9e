//! `hikari plot`: error against time as a chart (PNG), one line per
//! renderer on log–log axes, from what `render --reference` prints at its
//! checkpoints (`scripts/error-curves.sh` prefixes each line with the scene
//! and the renderer), so a user sees which estimator suits a scene.

use crate::render_cmd::UsageError;
use anyhow::{Context, Result};
use clap::Args;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct PlotArgs {
    /// Text file (`-`: standard input) of lines `LABEL: pass N, T s: relRMSE E …`,
    /// as `hikari render --reference` prints them with a label put in
    /// front (error-curves.sh writes them so). Lines without `relRMSE` are
    /// skipped.
    pub input: PathBuf,
    /// The chart (.png).
    #[arg(short, long, default_value = "error.png")]
    pub output: PathBuf,
    /// A title above the chart.
    #[arg(long, default_value = "")]
    pub title: String,
}

/// One label's points: (seconds, relRMSE).
#[derive(Debug, PartialEq)]
pub struct Curve {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// The curves in `text` (from `source`, for errors), in order of first appearance.
pub fn parse(text: &str, source: &str) -> Result<Vec<Curve>, UsageError> {
    let mut curves: Vec<Curve> = Vec::new();
    for (number, line) in text.lines().enumerate() {
        if !line.contains("relRMSE") {
            continue;
        }
        let bad = |what: &str| UsageError(format!("{source}:{}: {what} in {line:?}", number + 1));
        let (label, rest) = line.split_once(": pass ").ok_or_else(|| bad("no `LABEL: pass`"))?;
        let seconds: f64 = rest
            .split_once(", ")
            .and_then(|(_, t)| t.split_once(" s:"))
            .and_then(|(t, _)| t.trim().parse().ok())
            .ok_or_else(|| bad("no time `, T s:`"))?;
        let error: f64 = rest
            .split("relRMSE ")
            .nth(1)
            .and_then(|e| e.split_whitespace().next())
            .and_then(|e| e.parse().ok())
            .ok_or_else(|| bad("no number after relRMSE"))?;
        if !(seconds > 0.0 && seconds.is_finite() && error > 0.0 && error.is_finite()) {
            return Err(bad("a time or an error that is not a positive number"));
        }
        let label = label.trim().to_string();
        match curves.iter_mut().find(|c| c.label == label) {
            Some(curve) => curve.points.push((seconds, error)),
            None => curves.push(Curve { label, points: vec![(seconds, error)] }),
        }
    }
    if curves.is_empty() {
        return Err(UsageError(format!("{source}: no error curves (lines with `: pass N, T s: relRMSE E`)")));
    }
    Ok(curves)
}

pub fn run(args: &PlotArgs) -> Result<()> {
    let ext = args.output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if ext.as_deref() != Some("png") {
        return Err(UsageError(format!("{}: the chart is written as .png", args.output.display())).into());
    }
    let (text, source) = if args.input == Path::new("-") {
        (std::io::read_to_string(std::io::stdin()).context("reading standard input")?, "<stdin>".to_string())
    } else {
        let source = args.input.display().to_string();
        let text = std::fs::read_to_string(&args.input).map_err(|e| UsageError(format!("{source}: {e}")))?;
        (text, source)
    };
    let curves = parse(&text, &source)?;
    let (width, height) = (800u32, 560u32);
    let data = draw(&curves, &args.title, width, height)?;
    hikari_core::output::write_rgb8_png(&args.output, width, height, data)?;
    eprintln!("wrote {} ({} curves)", args.output.display(), curves.len());
    Ok(())
}

/// Line colours that stay apart on white (matplotlib's "tab10").
const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(127, 127, 127),
];

/// 1, 2 and 5 times the powers of ten between `lo` and `hi`: the labelled
/// lines of a log axis.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for exponent in lo.log10().floor() as i32..=hi.log10().ceil() as i32 {
        for mantissa in [1.0, 2.0, 5.0] {
            let v = mantissa * 10f64.powi(exponent);
            if (lo..=hi).contains(&v) {
                out.push(v);
            }
        }
    }
    out
}

/// The chart as RGB rows.
fn draw(curves: &[Curve], title: &str, width: u32, height: u32) -> Result<Vec<u8>> {
    // egui's own sans-serif font, already in the binary: no system fonts needed.
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    let points = || curves.iter().flat_map(|c| c.points.iter().copied());
    let (t0, t1) = points().fold((f64::INFINITY, 0.0f64), |(a, b), (t, _)| (a.min(t), b.max(t)));
    let (e0, e1) = points().fold((f64::INFINITY, 0.0f64), |(a, b), (_, e)| (a.min(e), b.max(e)));
    // Percent on the vertical axis; a little room around the data.
    let (x0, x1) = (t0 / 1.3, t1 * 1.3);
    let (y0, y1) = (100.0 * e0 / 1.3, 100.0 * e1 * 1.3);
    let mut data = vec![255u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut data, (width, height)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(
                (x0..x1).log_scale().with_key_points(ticks(x0, x1)),
                (y0..y1).log_scale().with_key_points(ticks(y0, y1)),
            )?;
        // Plain numbers on both axes: 0.5, 2, 10, not 0.500 or 10.0.
        let plain = |v: &f64| format!("{}", (v * 1000.0).round() / 1000.0);
        chart
            .configure_mesh()
            .x_label_formatter(&plain)
            .y_label_formatter(&plain)
            .x_desc("wall time (s)")
            .y_desc("relRMSE (% of the reference's mean)")
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 16))
            .draw()?;
        for (i, curve) in curves.iter().enumerate() {
            let color = COLOURS[i % COLOURS.len()].stroke_width(2);
            let series = curve.points.iter().map(|&(t, e)| (t, 100.0 * e));
            chart
                .draw_series(LineSeries::new(series.clone(), color))?
                .label(&curve.label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
            chart.draw_series(series.map(|p| Circle::new(p, 3, color.filled())))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        root.present()?;
    }
    Ok(data)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "cornell-box: reference, 16384 spp path tracing, 61 s
cornell-box vcm: pass 12, 5.03 s: relRMSE 0.1190 meanratio 0.9990 block16 0.0100 (RMS-relative 0.0300)
cornell-box path: pass 3, 5.10 s: relRMSE 0.2600 meanratio 1.0010 block16 0.0200
cornell-box vcm: pass 50, 20.01 s: relRMSE 0.0590 meanratio 0.9995 block16 0.0050
";

    #[test]
    fn reads_the_curves_that_render_prints() {
        let curves = parse(TEXT, "t.txt").unwrap();
        assert_eq!(curves.len(), 2);
        assert_eq!(curves[0].label, "cornell-box vcm");
        assert_eq!(curves[0].points, vec![(5.03, 0.1190), (20.01, 0.0590)]);
        assert_eq!(curves[1].points, vec![(5.10, 0.26)]);
    }

    #[test]
    fn bad_lines_are_located() {
        let e = parse("a: pass 1, x s: relRMSE 0.1\n", "t.txt").unwrap_err();
        assert!(e.0.contains("t.txt:1") && e.0.contains("time"), "{}", e.0);
        let e = parse("\nb: pass 1, 2 s: relRMSE -1\n", "t.txt").unwrap_err();
        assert!(e.0.contains("t.txt:2") && e.0.contains("positive"), "{}", e.0);
        let e = parse("nothing here\n", "t.txt").unwrap_err();
        assert!(e.0.contains("no error curves"), "{}", e.0);
    }

    /// The chart has the curves' colours in it, not only axes.
    #[test]
    fn draws_a_chart() {
        let curves = parse(TEXT, "t.txt").unwrap();
        let data = draw(&curves, "cornell-box", 400, 300).unwrap();
        let coloured = data.chunks(3).filter(|p| p.iter().max().unwrap() - p.iter().min().unwrap() > 80).count();
        assert!(coloured > 100, "{coloured} coloured pixels");
    }
}
