//! Figures (`--figures DIR`), each written as SVG, PNG and a caption (`NAME.caption.txt`,
//! defining the metric, n and the intervals; [`captions`]) with plotters:
//! `disposition` (SAA on CATCH vs DODGE scenes, one marker per model with 95% Wilson
//! intervals both ways, dashed diagonal, a legend), `freeze_by_band` (share of NO_ACTION
//! per speed band on the speed-sweeping families, a marker and line style per model, 95%
//! Wilson intervals, n per band), `per_family` (SAA per family and model: bars with 95%
//! Wilson intervals, value labels on white, n per family, 0% drawn as a stub),
//! `safety_rules` (unsafe share per model split by first rule, its Wilson interval; no
//! pooled row), and with `--execute` `outcomes` (caught / struck / missed / clear / not
//! executed per model, and per model and ground-truth action, stacked). Percentage axes
//! run 0–100 and are labelled with whole numbers; no label overlaps another
//! (`tests` checks the SVGs' text boxes).
//!
//! Text is drawn with `ab_glyph` from a font embedded in the binary (Hack, via the
//! `epaint_default_fonts` crate), so no system fonts or fontconfig are needed; in the PNGs
//! by [`png_text::GlyphText`] (plotters' own glyph placement split words).

pub mod captions;
mod parts;
mod png_text;
#[cfg(test)]
mod tests;

use crate::report::Report;
use crate::safety_rule::SafetyRule;
use anyhow::{anyhow, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use std::path::Path;
use std::sync::Once;

use parts::{
    boxed_label, draw_legend, draw_legend_below, error_bar, legend_rows, marker, split_legend,
    style, Key, Rgb, ROW,
};

const FONT: &str = "sans-serif";
// plotters' sizes: the SVG's font-size is size / 1.24 (a 16 → 12.9 px em).
const TITLE: u32 = 22;
const AXIS: u32 = 18;
const TICK: u32 = 16;
const LABEL: u32 = 16;

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font(
            FONT,
            FontStyle::Normal,
            epaint_default_fonts::HACK_REGULAR,
        );
    });
}

type DrawResult = Result<()>;

fn e<T: std::fmt::Debug>(err: T) -> anyhow::Error {
    anyhow!("drawing failed: {err:?}")
}

fn color(i: usize) -> RGBColor {
    const C: [RGBColor; 10] = [
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
    C[i % C.len()]
}

/// Dash (length, gap) in px of model `i`'s line; (0, 0) is solid.
fn dash(i: usize) -> (u32, u32) {
    [(0, 0), (10, 5), (3, 4), (16, 5), (7, 3), (2, 7)][i % 6]
}

/// Per model the expected CATCH and DODGE scenes (the disposition's n).
pub(crate) fn gt_counts(r: &Report) -> (Vec<u64>, Vec<u64>) {
    let count = |g: &str| -> Vec<u64> {
        r.models
            .iter()
            .map(|m| {
                m.by_gt_action
                    .iter()
                    .find(|x| x.group == g)
                    .map_or(0, |x| x.expected)
            })
            .collect()
    };
    (count("CATCH"), count("DODGE"))
}

/// One disposition marker: model, point and intervals in percent.
struct DispPoint {
    model: usize,
    x: f64,
    y: f64,
    x_ci: Option<[f64; 2]>,
    y_ci: Option<[f64; 2]>,
}

/// The disposition's points; those within 1.5 points of one another set 2.5 points
/// apart sideways (the caption says so), so coinciding models stay visible.
fn disposition_points(r: &Report) -> Vec<DispPoint> {
    let row = |m: &crate::report::ModelReport, g: &str| {
        m.by_gt_action.iter().find(|x| x.group == g).cloned()
    };
    let pct = |ci: Option<[f64; 2]>| ci.map(|[a, b]| [100.0 * a, 100.0 * b]);
    let mut pts: Vec<DispPoint> = Vec::new();
    for (i, m) in r.models.iter().enumerate() {
        let (Some(c), Some(d)) = (row(m, "CATCH"), row(m, "DODGE")) else {
            continue;
        };
        let (Some(x), Some(y)) = (c.saa, d.saa) else {
            continue;
        };
        pts.push(DispPoint {
            model: i,
            x: 100.0 * x,
            y: 100.0 * y,
            x_ci: pct(c.saa_ci),
            y_ci: pct(d.saa_ci),
        });
    }
    let mut group: Vec<usize> = (0..pts.len()).collect();
    for i in 0..pts.len() {
        for j in 0..i {
            if (pts[i].x - pts[j].x).abs() < 1.5 && (pts[i].y - pts[j].y).abs() < 1.5 {
                group[i] = group[j];
                break;
            }
        }
    }
    let (xs, ys): (Vec<f64>, Vec<f64>) = pts.iter().map(|p| (p.x, p.y)).unzip();
    for (i, p) in pts.iter_mut().enumerate() {
        let members: Vec<usize> = (0..xs.len()).filter(|&j| group[j] == group[i]).collect();
        let k = members.iter().position(|&j| j == i).unwrap_or(0) as f64;
        let dx = (k - (members.len() as f64 - 1.0) / 2.0) * 2.5;
        p.x = xs[i] + dx;
        p.y = ys[i];
        if let Some(ci) = &mut p.x_ci {
            *ci = [ci[0] + dx, ci[1] + dx];
        }
    }
    pts
}

fn disposition<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, r: &Report) -> DrawResult {
    root.fill(&WHITE).map_err(e)?;
    let (nc, nd) = gt_counts(r);
    let same = |v: &[u64]| v.windows(2).all(|w| w[0] == w[1]);
    let per_model_n = !(same(&nc) && same(&nd));
    let items: Vec<(String, Key)> = r
        .models
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let n = if per_model_n {
                format!(" (n={}/{})", nc[i], nd[i])
            } else {
                String::new()
            };
            (format!("{}{n}", m.model), Key::Marker(i))
        })
        .collect();
    let (plot, legend_area) = split_legend(root, &items);
    let n_of = |v: &[u64]| match (per_model_n, v.first()) {
        (false, Some(n)) => format!("; n = {n}"),
        _ => String::new(),
    };
    let mut chart = ChartBuilder::on(&plot)
        .caption("SAA on CATCH vs DODGE scenes", (FONT, TITLE))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(60)
        // A margin beyond 0–100 %, so a marker in a corner is drawn whole.
        .build_cartesian_2d(-5f64..105f64, -5f64..105f64)
        .map_err(e)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .x_labels(6)
        .y_labels(6)
        .x_desc(format!("SAA on CATCH scenes (%{})", n_of(&nc)))
        .y_desc(format!("SAA on DODGE scenes (%{})", n_of(&nd)))
        .x_label_formatter(&percent_label)
        .y_label_formatter(&percent_label)
        .label_style((FONT, TICK))
        .axis_desc_style((FONT, AXIS))
        .draw()
        .map_err(e)?;
    chart
        .draw_series(DashedLineSeries::new(
            vec![(0.0, 0.0), (100.0, 100.0)],
            6,
            4,
            BLACK.mix(0.5).stroke_width(1),
        ))
        .map_err(e)?;
    let pts = disposition_points(r);
    if pts.is_empty() {
        let (x, y) = chart.backend_coord(&(50.0, 50.0));
        let st = style(LABEL, BLACK, HPos::Center, VPos::Center);
        let msg = "no model has scored both CATCH and DODGE scenes";
        plot.draw(&Text::new(msg, (x, y), st)).map_err(e)?;
    }
    for p in &pts {
        let c = color(p.model);
        if let Some([lo, hi]) = p.x_ci {
            error_bar(
                &plot,
                chart.backend_coord(&(lo, p.y)),
                chart.backend_coord(&(hi, p.y)),
                c,
            )?;
        }
        if let Some([lo, hi]) = p.y_ci {
            error_bar(
                &plot,
                chart.backend_coord(&(p.x, lo)),
                chart.backend_coord(&(p.x, hi)),
                c,
            )?;
        }
    }
    for p in &pts {
        marker(&plot, p.model, chart.backend_coord(&(p.x, p.y)), 7)?;
    }
    draw_legend(&legend_area, &items)?;
    root.present().map_err(e)?;
    Ok(())
}

const BANDS: [&str; 4] = ["slow", "normal", "fast", "very_fast"];

fn freeze_by_band<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, r: &Report) -> DrawResult {
    root.fill(&WHITE).map_err(e)?;
    // One series per model; the pooled "ALL" row is not a model.
    let series: Vec<_> = r.analyses.speed.iter().take(r.models.len()).collect();
    let items: Vec<(String, Key)> = series
        .iter()
        .enumerate()
        .map(|(i, s)| (s.model.clone(), Key::Line(i)))
        .collect();
    let (plot, legend_area) = split_legend(root, &items);
    let band_n: Vec<String> = (0..4)
        .map(|b| {
            captions::n_text(
                series
                    .iter()
                    .map(|s| s.decisions_by_band.get(b).copied().unwrap_or(0)),
            )
        })
        .collect();
    let mut chart = ChartBuilder::on(&plot)
        .caption("Freeze rate (NO_ACTION) by speed band", (FONT, TITLE))
        .margin(15)
        .x_label_area_size(70)
        .y_label_area_size(60)
        .build_cartesian_2d(-0.4f64..3.4f64, -4f64..104f64)
        .map_err(e)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .disable_x_mesh()
        .x_labels(0)
        .y_labels(6)
        .y_label_formatter(&percent_label)
        .x_desc("speed band (speed-sweeping families)")
        .y_desc("decisions that freeze (%)")
        .label_style((FONT, TICK))
        .axis_desc_style((FONT, AXIS))
        .draw()
        .map_err(e)?;
    // The band names and their n under the axis, two lines each.
    for (b, name) in BANDS.iter().enumerate() {
        let (x, y) = chart.backend_coord(&(b as f64, -4.0));
        let st = style(TICK, BLACK, HPos::Center, VPos::Top);
        plot.draw(&Text::new(name.to_string(), (x, y + 6), st.clone()))
            .map_err(e)?;
        plot.draw(&Text::new(band_n[b].clone(), (x, y + 24), st))
            .map_err(e)?;
    }
    // Models side by side within each band, so equal rates (often 0 %) stay visible.
    let k = series.len().max(1) as f64;
    for (i, s) in series.iter().enumerate() {
        let c = color(i);
        let dx = (i as f64 - (k - 1.0) / 2.0) * (0.6 / k).min(0.1);
        let pts: Vec<(usize, f64, f64)> = s
            .freeze_rate_by_band
            .iter()
            .enumerate()
            .filter_map(|(b, v)| v.map(|v| (b, b as f64 + dx, 100.0 * v)))
            .collect();
        let line: Vec<(f64, f64)> = pts.iter().map(|p| (p.1, p.2)).collect();
        match dash(i) {
            (0, _) => chart
                .draw_series(LineSeries::new(line, c.stroke_width(2)))
                .map(|_| ())
                .map_err(e)?,
            (d, g) => chart
                .draw_series(DashedLineSeries::new(line, d, g, c.stroke_width(2)))
                .map(|_| ())
                .map_err(e)?,
        }
        for &(b, x, _) in &pts {
            if let Some(Some([lo, hi])) = s.freeze_rate_by_band_ci.get(b) {
                let (a, z) = (
                    chart.backend_coord(&(x, 100.0 * lo)),
                    chart.backend_coord(&(x, 100.0 * hi)),
                );
                error_bar(&plot, a, z, c.mix(0.6).rgb_color())?;
            }
        }
        for &(_, x, y) in &pts {
            marker(&plot, i, chart.backend_coord(&(x, y)), 6)?;
        }
    }
    draw_legend(&legend_area, &items)?;
    root.present().map_err(e)?;
    Ok(())
}

/// Pixel height of one bar of the per-family figure.
const BAR_PX: u32 = 20;

fn per_family<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, r: &Report) -> DrawResult {
    root.fill(&WHITE).map_err(e)?;
    let fams: Vec<&str> = r.dataset.families.iter().map(|s| s.as_str()).collect();
    let n = fams.len().max(1);
    let k = r.models.len().max(1);
    let items: Vec<(String, Key)> = r
        .models
        .iter()
        .enumerate()
        .map(|(i, m)| (m.model.clone(), Key::Swatch(color(i))))
        .collect();
    let (plot, legend_area) = split_legend(root, &items);
    let names: Vec<String> = fams
        .iter()
        .enumerate()
        .map(|(fi, f)| {
            let counts = r
                .models
                .iter()
                .map(|m| m.by_family.get(fi).map_or(0, |row| row.expected));
            format!("{f} ({})", captions::n_text(counts))
        })
        .collect();
    let longest = names.iter().map(|s| s.chars().count()).max().unwrap_or(0) as u32;
    let mut chart = ChartBuilder::on(&plot)
        .caption("SAA per family", (FONT, TITLE))
        .margin(15)
        // Room right of 100 % for a bar's value label.
        .margin_right(60)
        .x_label_area_size(50)
        .y_label_area_size(20 + longest * TICK * 62 / 100)
        .build_cartesian_2d(0f64..100f64, -0.5f64..(n as f64 - 0.5))
        .map_err(e)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .x_labels(6)
        .y_labels(n + 1)
        .y_label_formatter(&|y| category_label(&names, *y))
        .disable_y_mesh()
        .x_desc("SAA (%), 95% Wilson intervals")
        .x_label_formatter(&percent_label)
        .label_style((FONT, TICK))
        .axis_desc_style((FONT, AXIS))
        .draw()
        .map_err(e)?;
    let h = 0.84 / k as f64;
    for (mi, m) in r.models.iter().enumerate() {
        let c = color(mi);
        for (fi, row) in m.by_family.iter().enumerate().take(n) {
            if row.expected == 0 {
                continue;
            }
            let y0 = (n - 1 - fi) as f64 + 0.42 - (mi + 1) as f64 * h;
            let (y_top, y_bot, y_mid) = (y0 + h * 0.9, y0, y0 + h * 0.45);
            let v = row.saa.map_or(0.0, |v| 100.0 * v);
            // A 0 % bar is a stub a few pixels wide, so it reads as zero, not as missing.
            let a = chart.backend_coord(&(0.0, y_top));
            let b = chart.backend_coord(&(v, y_bot));
            let b = (b.0.max(a.0 + 3), b.1);
            plot.draw(&Rectangle::new([a, b], c.filled())).map_err(e)?;
            let mut end = b.0;
            if let Some([lo, hi]) = row.saa_ci {
                let p = chart.backend_coord(&(100.0 * lo, y_mid));
                let q = chart.backend_coord(&(100.0 * hi, y_mid));
                error_bar(&plot, p, q, BLACK.mix(0.75).rgb_color())?;
                end = end.max(q.0);
            }
            let yc = chart.backend_coord(&(0.0, y_mid)).1;
            // Dark text: the bar's colour says the model, the label only the value.
            boxed_label(
                &plot,
                &format!("{v:.0}%"),
                (end + 6, yc),
                RGBColor(40, 40, 40),
            )?;
        }
    }
    draw_legend(&legend_area, &items)?;
    root.present().map_err(e)?;
    Ok(())
}

/// A chart of horizontal percentage bars (0–100 % of decisions), one row per name from
/// the top, its axes drawn; `label_width` px for the row names.
fn percent_rows_chart<'a, DB: DrawingBackend>(
    plot: &DrawingArea<DB, Shift>,
    caption: &str,
    names: &[String],
    x_desc: &str,
) -> Result<
    ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
> {
    let n = names.len().max(1);
    let longest = names.iter().map(|s| s.chars().count()).max().unwrap_or(0) as u32;
    let mut chart = ChartBuilder::on(plot)
        .caption(caption, (FONT, TITLE))
        .margin(15)
        .margin_right(110)
        .x_label_area_size(50)
        .y_label_area_size((20 + longest * TICK * 62 / 100).clamp(100, 480))
        .build_cartesian_2d(0f64..100f64, -0.5f64..(n as f64 - 0.5))
        .map_err(e)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .x_labels(6)
        .y_labels(n + 1)
        .y_label_formatter(&|y| category_label(names, *y))
        .disable_y_mesh()
        .x_desc(x_desc)
        .x_label_formatter(&percent_label)
        .label_style((FONT, TICK))
        .axis_desc_style((FONT, AXIS))
        .draw()
        .map_err(e)?;
    Ok(chart)
}

fn safety_rules<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, r: &Report) -> DrawResult {
    root.fill(&WHITE).map_err(e)?;
    // One row per model; the pooled "ALL" breakdown mixes models and is left out.
    let rows: Vec<_> = r.analyses.safety.iter().take(r.models.len()).collect();
    let n = rows.len().max(1);
    let names: Vec<String> = rows
        .iter()
        .map(|s| format!("{} (n={})", s.model, s.decisions))
        .collect();
    let items: Vec<(String, Key)> = SafetyRule::ALL
        .iter()
        .map(|r| {
            (
                format!("{}: {}", r.as_str(), r.describe()),
                Key::Swatch(rule_color(*r)),
            )
        })
        .collect();
    let (w, h) = root.dim_in_pixel();
    let below = 12 + ROW * legend_rows(&items, w as i32, 20);
    let (plot, legend_area) = root.split_vertically(h as i32 - below);
    let chart = percent_rows_chart(
        &plot,
        "Unsafe decisions by first rule fired",
        &names,
        "decisions (%) where a safety rule fired, 95% Wilson interval of the total",
    )?;
    for (i, s) in rows.iter().enumerate() {
        let y = (n - 1 - i) as f64;
        let d = s.decisions.max(1) as f64;
        let mut before = 0u64;
        for rule in SafetyRule::ALL {
            let k = s.first_rule.get(rule);
            if k > 0 {
                let a = chart.backend_coord(&(100.0 * before as f64 / d, y + 0.32));
                let b = chart.backend_coord(&(100.0 * (before + k) as f64 / d, y - 0.32));
                plot.draw(&Rectangle::new([a, b], rule_color(rule).filled()))
                    .map_err(e)?;
            }
            before += k;
        }
        let total = 100.0 * s.violations as f64 / d;
        let mut end = chart.backend_coord(&(total, y)).0;
        if let Some([lo, hi]) = crate::stats::wilson(s.violations, s.decisions) {
            let p = chart.backend_coord(&(100.0 * lo, y));
            let q = chart.backend_coord(&(100.0 * hi, y));
            error_bar(&plot, p, q, BLACK)?;
            end = end.max(q.0);
        }
        let label = if s.decisions == 0 {
            "no decisions".to_string()
        } else {
            format!("{total:.0}% unsafe")
        };
        boxed_label(
            &plot,
            &label,
            (end + 6, chart.backend_coord(&(0.0, y)).1),
            BLACK,
        )?;
    }
    draw_legend_below(&legend_area, &items, 20)?;
    root.present().map_err(e)?;
    Ok(())
}

fn rule_color(r: SafetyRule) -> RGBColor {
    [
        RGBColor(127, 127, 127),
        RGBColor(214, 39, 40),
        RGBColor(148, 103, 189),
        RGBColor(255, 127, 14),
    ][r.index()]
}

/// Outcome segments of the `outcomes` figure: name, colour.
const OUTCOME_SEGMENTS: [(&str, RGBColor); 5] = [
    ("caught", RGBColor(44, 160, 44)),
    ("struck", RGBColor(214, 39, 40)),
    ("missed", RGBColor(255, 127, 14)),
    ("clear", RGBColor(120, 144, 156)),
    ("not executed (R1)", RGBColor(200, 200, 200)),
];

/// The `outcomes` figure's rows: per model its decisions, then per ground-truth action.
fn outcome_rows(x: &crate::execution::ExecutionReport) -> Vec<(String, [u64; 5])> {
    use crate::execution::report::Counts;
    let seg = |c: &Counts| [c.caught, c.struck, c.missed, c.clear, c.not_executed];
    let mut rows = Vec::new();
    for m in &x.models {
        let n = |c: &Counts| seg(c).iter().sum::<u64>();
        rows.push((format!("{} (all, n={})", m.model, n(&m.all)), seg(&m.all)));
        for (gt, c) in &m.by_gt_action {
            rows.push((format!("{} gt {gt} (n={})", m.model, n(c)), seg(c)));
        }
    }
    rows
}

/// Execution outcomes (`--execute`): stacked bars of caught / struck / missed / clear /
/// not executed, as shares of each row's decisions.
fn outcomes<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, r: &Report) -> DrawResult {
    root.fill(&WHITE).map_err(e)?;
    let rows = r.execution.as_ref().map(outcome_rows).unwrap_or_default();
    let n = rows.len().max(1);
    let names: Vec<String> = rows.iter().map(|(name, _)| name.clone()).collect();
    let items: Vec<(String, Key)> = OUTCOME_SEGMENTS
        .iter()
        .map(|(l, c)| (l.to_string(), Key::Swatch(*c)))
        .collect();
    let (w, h) = root.dim_in_pixel();
    let below = 12 + ROW * legend_rows(&items, w as i32, 20);
    let (plot, legend_area) = root.split_vertically(h as i32 - below);
    let chart = percent_rows_chart(
        &plot,
        "Execution outcomes per model and ground-truth action",
        &names,
        "decisions (%)",
    )?;
    for (si, (_, c)) in OUTCOME_SEGMENTS.iter().enumerate() {
        for (i, (_, counts)) in rows.iter().enumerate() {
            let total: u64 = counts.iter().sum();
            if total == 0 || counts[si] == 0 {
                continue;
            }
            let before: u64 = counts[..si].iter().sum();
            let x0 = 100.0 * before as f64 / total as f64;
            let x1 = x0 + 100.0 * counts[si] as f64 / total as f64;
            let y = (n - 1 - i) as f64;
            let a = chart.backend_coord(&(x0, y + 0.35));
            let b = chart.backend_coord(&(x1, y - 0.35));
            plot.draw(&Rectangle::new([a, b], c.filled())).map_err(e)?;
        }
    }
    draw_legend_below(&legend_area, &items, 20)?;
    root.present().map_err(e)?;
    Ok(())
}

/// Tick label of a percentage axis: whole numbers ("10", not "10.0"), blank outside 0–100.
fn percent_label(v: &f64) -> String {
    if (-1e-9..=100.0 + 1e-9).contains(v) {
        format!("{v:.0}")
    } else {
        String::new()
    }
}

/// Writes figure `$f` as `$name.svg`, `.png` and `.caption.txt` into `$dir`.
macro_rules! figure {
    ($dir:expr, $name:literal, $size:expr, $f:ident, $r:expr, $caption:expr, $out:expr) => {{
        let (w, h) = $size;
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, (w, h)).into_drawing_area();
            $f(&root, $r)?;
        }
        let svg = $dir.join(concat!($name, ".svg"));
        rh_contract::fsio::write_file(&svg, "a figure", text.as_bytes())?;
        let mut pixels = vec![0u8; w as usize * h as usize * 3];
        {
            let bitmap = BitMapBackend::with_buffer(&mut pixels, (w, h));
            let root = png_text::GlyphText::new(bitmap, epaint_default_fonts::HACK_REGULAR)
                .into_drawing_area();
            $f(&root, $r)?;
        }
        let png = $dir.join(concat!($name, ".png"));
        rh_contract::fsio::write_file(&png, "a figure", &png_bytes(&pixels, w, h)?)?;
        let txt = $dir.join(concat!($name, ".caption.txt"));
        let caption = format!("{}\n", $caption);
        rh_contract::fsio::write_file(&txt, "a figure caption", caption.as_bytes())?;
        $out.extend([svg, png, txt]);
    }};
}

/// The PNG of an RGB bitmap, encoded as `image` saves one (its default PNG settings).
fn png_bytes(pixels: &[u8], w: u32, h: u32) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(pixels, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| anyhow!("encoding a figure as PNG: {e}"))?;
    Ok(bytes)
}

/// Writes every figure into `dir` (created if needed) as `NAME.svg`, `NAME.png` and
/// `NAME.caption.txt`, each file whole or not at all (`rh_contract::fsio`); returns the
/// files written.
pub fn write_figures(r: &Report, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
    register_font();
    std::fs::create_dir_all(dir)
        .map_err(|e| rh_contract::fsio::CannotWrite::new("the figures directory", dir, e))?;
    let mut out = Vec::new();
    let k = r.models.len().clamp(1, 10) as u32;
    let fam_h = (130 + r.dataset.families.len().max(3) as u32 * (10 + BAR_PX * k)).clamp(360, 3000);
    let rows_h = |rows: usize| (150 + 34 * rows as u32).max(300) + 70;
    figure!(
        dir,
        "disposition",
        (820, 600),
        disposition,
        r,
        captions::disposition(r),
        out
    );
    let cap = captions::freeze_by_band(r);
    figure!(
        dir,
        "freeze_by_band",
        (900, 540),
        freeze_by_band,
        r,
        cap,
        out
    );
    figure!(
        dir,
        "per_family",
        (1000, fam_h),
        per_family,
        r,
        captions::per_family(r),
        out
    );
    let safety = (1000, rows_h(r.models.len()));
    figure!(
        dir,
        "safety_rules",
        safety,
        safety_rules,
        r,
        captions::safety_rules(r),
        out
    );
    if let Some(x) = &r.execution {
        let size = (1000, rows_h(outcome_rows(x).len()).min(3000));
        figure!(
            dir,
            "outcomes",
            size,
            outcomes,
            r,
            captions::outcomes(r),
            out
        );
    }
    Ok(out)
}

/// Label of a horizontal bar chart's category axis: bar `i` (counted from the bottom) shows
/// `names[len − 1 − i]`, so the first name is at the top; off-integer ticks stay blank.
fn category_label<S: AsRef<str>>(names: &[S], y: f64) -> String {
    let i = y.round();
    if (y - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
        names[names.len() - 1 - i as usize].as_ref().to_string()
    } else {
        String::new()
    }
}
