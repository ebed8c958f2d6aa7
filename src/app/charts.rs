//! Charts (plotters) for `compare` and `stability`, each written as SVG and PNG, and the
//! equal-time image strip with insets.

use std::path::Path;
use std::sync::OnceLock;

use anyhow::{anyhow, Context as _, Result};
use glam::Vec3;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use restir_pt::image_io::srgb_encode;

/// Text needs a font to be measured and drawn; Debian's fonts-dejavu-core (tools/setup.sh) has it.
const FONT_FILE: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
const FONT: &str = "sans-serif";

fn register_font() -> Result<()> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            let bytes = std::fs::read(FONT_FILE)
                .map_err(|e| format!("{FONT_FILE}: cannot read the chart font ({e}); install fonts-dejavu-core (tools/setup.sh)"))?;
            plotters::style::register_font(FONT, FontStyle::Normal, Box::leak(bytes.into_boxed_slice()))
                .map_err(|_| format!("{FONT_FILE}: not a usable TrueType font"))
        })
        .clone()
        .map_err(|e| anyhow!(e))
}

const SERIES_COLOURS: [RGBColor; 8] = [
    RGBColor(76, 114, 176),
    RGBColor(221, 132, 82),
    RGBColor(85, 168, 104),
    RGBColor(196, 78, 82),
    RGBColor(129, 114, 179),
    RGBColor(147, 120, 96),
    RGBColor(218, 139, 195),
    RGBColor(100, 100, 100),
];

pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

pub struct LineChart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub log_x: bool,
    pub series: &'a [Series],
}

/// A padded range around the finite, positive values (log axes need positive bounds).
fn axis_range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return (1.0, 10.0);
    }
    if log {
        (lo / 1.5, hi * 1.5)
    } else {
        let pad = ((hi - lo) * 0.05).max(0.5);
        (lo - pad, hi + pad)
    }
}

fn draw<DB: DrawingBackend, X: Ranged<ValueType = f64> + ValueFormatter<f64>>(
    root: DrawingArea<DB, Shift>,
    chart: &LineChart,
    x: X,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let fail = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("drawing a chart: {e}");
    root.fill(&WHITE).map_err(fail)?;
    let (y0, y1) = axis_range(chart.series.iter().flat_map(|s| s.points.iter().map(|p| p.1)), true);
    let mut plot = ChartBuilder::on(&root)
        .caption(chart.title, (FONT, 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x, (y0..y1).log_scale())
        .map_err(fail)?;
    plot.configure_mesh()
        .x_desc(chart.x_label)
        .y_desc(chart.y_label)
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style((FONT, 13))
        .draw()
        .map_err(fail)?;
    for (i, s) in chart.series.iter().enumerate() {
        let colour = SERIES_COLOURS[i % SERIES_COLOURS.len()];
        let points: Vec<(f64, f64)> = s.points.iter().copied().filter(|p| p.1 > 0.0 && p.1.is_finite()).collect();
        plot.draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
            .map_err(fail)?
            .label(s.name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        plot.draw_series(points.into_iter().map(|p| Circle::new(p, 4, colour.filled())))
            .map_err(fail)?;
    }
    plot.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 13))
        .draw()
        .map_err(fail)?;
    root.present().map_err(fail)?;
    Ok(())
}

fn draw_on<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, chart: &LineChart) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let xs = chart.series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
    let (x0, x1) = axis_range(xs, chart.log_x);
    if chart.log_x {
        draw(root, chart, LogCoord::from((x0..x1).log_scale()))
    } else {
        draw(root, chart, RangedCoordf64::from(x0..x1))
    }
}

const CHART_SIZE: (u32, u32) = (800, 520);

/// Writes `<stem>.svg` and `<stem>.png`: the series as lines with markers on a log y axis.
pub fn write_line_chart(stem: &Path, chart: &LineChart) -> Result<()> {
    register_font()?;
    let svg = stem.with_extension("svg");
    let png = stem.with_extension("png");
    draw_on(SVGBackend::new(&svg, CHART_SIZE).into_drawing_area(), chart).with_context(|| format!("{}", svg.display()))?;
    draw_on(BitMapBackend::new(&png, CHART_SIZE).into_drawing_area(), chart).with_context(|| format!("{}", png.display()))?;
    Ok(())
}

/// One column of the strip: a label and a linear RGB image.
pub struct StripPanel<'a> {
    pub label: String,
    pub pixels: &'a [Vec3],
}

/// A square window of the image: the inset's source.
#[derive(Debug, Clone, Copy)]
pub struct Inset {
    pub x: u32,
    pub y: u32,
    pub size: u32,
}

const LABEL_HEIGHT: u32 = 24;
const PANEL_MIN_WIDTH: u32 = 256;

/// Writes a PNG strip: one column per panel, the full image above its inset (the `inset`
/// window, magnified), the inset's window outlined on the full image, labels on top.
pub fn write_image_strip(path: &Path, width: u32, height: u32, panels: &[StripPanel], inset: Inset) -> Result<()> {
    register_font()?;
    let scale = PANEL_MIN_WIDTH.div_ceil(width).max(1);
    let (pw, ph) = (width * scale, height * scale);
    let inset_scale = pw / inset.size.max(1);
    let inset_h = inset.size * inset_scale;
    let (w, h) = (pw * panels.len() as u32, LABEL_HEIGHT + ph + inset_h);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let mut put = |x: u32, y: u32, c: [u8; 3]| {
        let i = ((y * w + x) * 3) as usize;
        buf[i..i + 3].copy_from_slice(&c);
    };
    for (p, panel) in panels.iter().enumerate() {
        let x0 = p as u32 * pw;
        let colour = |x: u32, y: u32| {
            let v = panel.pixels[(y * width + x) as usize];
            [srgb_encode(v.x), srgb_encode(v.y), srgb_encode(v.z)]
        };
        for y in 0..ph {
            for x in 0..pw {
                let (sx, sy) = (x / scale, y / scale);
                let (lo_x, lo_y) = (inset.x * scale, inset.y * scale);
                let (hi_x, hi_y) = (lo_x + inset.size * scale - 1, lo_y + inset.size * scale - 1);
                let inside = (lo_x..=hi_x).contains(&x) && (lo_y..=hi_y).contains(&y);
                let edge = inside && (x == lo_x || x == hi_x || y == lo_y || y == hi_y);
                put(x0 + x, LABEL_HEIGHT + y, if edge { [255, 40, 40] } else { colour(sx, sy) });
            }
        }
        for y in 0..inset_h {
            for x in 0..pw.min(inset.size * inset_scale) {
                let (sx, sy) = (inset.x + x / inset_scale, inset.y + y / inset_scale);
                put(x0 + x, LABEL_HEIGHT + ph + y, colour(sx.min(width - 1), sy.min(height - 1)));
            }
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        for (p, panel) in panels.iter().enumerate() {
            root.draw(&Text::new(
                panel.label.clone(),
                (p as i32 * pw as i32 + 6, 4),
                (FONT, 15).into_font().color(&BLACK),
            ))
            .map_err(|e| anyhow!("{}: drawing a label: {e}", path.display()))?;
        }
        root.present().map_err(|e| anyhow!("{}: {e}", path.display()))?;
    }
    let file = std::fs::File::create(path).with_context(|| format!("{}: cannot create PNG", path.display()))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .write_header()
        .and_then(|mut wr| wr.write_image_data(&buf))
        .map_err(|e| anyhow!("{}: cannot write PNG: {e}", path.display()))
}
