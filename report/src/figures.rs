//! Figures (`--figures DIR`), each written as SVG and PNG with plotters:
//! `disposition` (SAA on CATCH vs DODGE scenes, one point per model, dashed diagonal),
//! `freeze_by_band` (share of NO_ACTION per speed band, speed-sweeping families),
//! `per_family` (SAA per family and model), `safety_rules` (first-rule breakdown, legend
//! below), and with `--execute` `outcomes` (caught / struck / missed / clear / not
//! executed per model, and per model and ground-truth action, stacked). Percentage axes
//! are labelled with whole numbers.
//!
//! Text is rendered with `ab_glyph` from a font embedded in the binary (Hack, via the
//! `epaint_default_fonts` crate), so no system fonts or fontconfig are needed.

use crate::report::Report;
use crate::safety_rule::SafetyRule;
use anyhow::{anyhow, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

const FONT: &str = "sans-serif";

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

/// Splits off a legend column on the right, wide enough for the longest label.
fn split_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    items: &[(String, RGBColor)],
) -> (DrawingArea<DB, Shift>, DrawingArea<DB, Shift>) {
    let longest = items.iter().map(|i| i.0.chars().count()).max().unwrap_or(0);
    let width = (40 + longest * 8).clamp(120, 460) as i32;
    let (w, _) = root.dim_in_pixel();
    root.split_horizontally(w as i32 - width)
}

fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    items: &[(String, RGBColor)],
) -> DrawResult {
    for (i, (label, c)) in items.iter().enumerate() {
        let y = 60 + 22 * i as i32;
        area.draw(&Rectangle::new([(6, y), (20, y + 12)], c.filled()))
            .map_err(e)?;
        area.draw(&Text::new(label.clone(), (26, y - 1), (FONT, 12)))
            .map_err(e)?;
    }
    Ok(())
}

fn disposition<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, r: &Report) -> DrawResult {
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(root)
        .caption("Disposition: SAA on CATCH vs DODGE scenes", (FONT, 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(55)
        // A margin beyond 0–100 %, so a marker in a corner is drawn whole.
        .build_cartesian_2d(-6f64..106f64, -6f64..106f64)
        .map_err(e)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .x_desc("SAA on CATCH scenes (%)")
        .y_desc("SAA on DODGE scenes (%)")
        .x_label_formatter(&percent_label)
        .y_label_formatter(&percent_label)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(e)?;
    chart
        .draw_series(DashedLineSeries::new(
            vec![(0.0, 0.0), (100.0, 100.0)],
            6,
            4,
            BLACK.mix(0.6).stroke_width(1),
        ))
        .map_err(e)?;
    for (i, m) in r.models.iter().enumerate() {
        let (Some(x), Some(y)) = (m.by_gt_action[0].saa, m.by_gt_action[1].saa) else {
            continue;
        };
        let (x, y) = (100.0 * x, 100.0 * y);
        let c = color(i);
        chart
            .draw_series(std::iter::once(Circle::new((x, y), 6, c.filled())))
            .map_err(e)?;
        let tx = if x > 75.0 { x - 22.0 } else { x + 1.5 };
        chart
            .draw_series(std::iter::once(Text::new(
                format!(
                    "{} (n={}/{})",
                    m.model, m.by_gt_action[0].expected, m.by_gt_action[1].expected
                ),
                (tx, (y + 2.5).min(104.0)),
                (FONT, 13).into_font().color(&c),
            )))
            .map_err(e)?;
    }
    root.present().map_err(e)?;
    Ok(())
}

fn freeze_by_band<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, r: &Report) -> DrawResult {
    root.fill(&WHITE).map_err(e)?;
    let bands = ["slow", "normal", "fast", "very_fast"];
    let legend_items: Vec<(String, RGBColor)> = r
        .analyses
        .speed
        .iter()
        .filter(|s| s.model != "ALL")
        .enumerate()
        .map(|(i, s)| (s.model.clone(), color(i)))
        .collect();
    let (plot, legend_area) = split_legend(root, &legend_items);
    let mut chart = ChartBuilder::on(&plot)
        .caption("Freeze rate (NO_ACTION) by speed band", (FONT, 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d(-0.3f64..3.3f64, -4f64..104f64)
        .map_err(e)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .x_labels(4)
        .x_label_formatter(&|x| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && (0.0..4.0).contains(&i) {
                bands[i as usize].to_string()
            } else {
                String::new()
            }
        })
        .y_label_formatter(&percent_label)
        .x_desc("speed band (speed-sweeping families; models side by side)")
        .y_desc("decisions that freeze (%)")
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(e)?;
    let series: Vec<_> = r
        .analyses
        .speed
        .iter()
        .filter(|s| s.model != "ALL")
        .collect();
    // Models side by side within each band, so equal rates (often 0 %) stay visible.
    let k = series.len().max(1) as f64;
    for (i, s) in series.iter().enumerate() {
        let c = color(i);
        let dx = (i as f64 - (k - 1.0) / 2.0) * (0.5 / k).min(0.08);
        let pts: Vec<(f64, f64)> = s
            .freeze_rate_by_band
            .iter()
            .enumerate()
            .filter_map(|(b, v)| v.map(|v| (b as f64 + dx, 100.0 * v)))
            .collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(e)?;
        chart
            .draw_series(pts.into_iter().map(|p| Circle::new(p, 4, c.filled())))
            .map_err(e)?;
    }
    draw_legend(&legend_area, &legend_items)?;
    root.present().map_err(e)?;
    Ok(())
}

fn per_family<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, r: &Report) -> DrawResult {
    root.fill(&WHITE).map_err(e)?;
    let fams: Vec<&str> = r.dataset.families.iter().map(|s| s.as_str()).collect();
    let n = fams.len().max(1);
    let k = r.models.len().max(1);
    let legend_items: Vec<(String, RGBColor)> = r
        .models
        .iter()
        .enumerate()
        .map(|(i, m)| (m.model.clone(), color(i)))
        .collect();
    let (plot, legend_area) = split_legend(root, &legend_items);
    let mut chart = ChartBuilder::on(&plot)
        .caption("SAA per family", (FONT, 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(140)
        // Room right of 100 % for the bars' labels.
        .build_cartesian_2d(0f64..122f64, -0.5f64..(n as f64 - 0.5))
        .map_err(e)?;
    let names = fams.clone();
    chart
        .configure_mesh()
        .max_light_lines(0)
        .y_labels(n + 1)
        .y_label_formatter(&|y| category_label(&names, *y))
        .disable_y_mesh()
        .x_desc("SAA (%) — each bar labelled with its value and n (expected scenes)")
        .x_label_formatter(&percent_label)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(e)?;
    let h = 0.8 / k as f64;
    // Every bar is labelled "57% n=12", so a 0 % bar reads as zero, not as missing.
    let font = ((h * 0.9 * 380.0 / n as f64) as u32).clamp(8, 12);
    for (mi, m) in r.models.iter().enumerate() {
        let labels: Vec<_> = m
            .by_family
            .iter()
            .enumerate()
            .filter(|(_, row)| row.expected > 0)
            .map(|(fi, row)| {
                let y0 = (n - 1 - fi) as f64 + 0.4 - (mi + 1) as f64 * h;
                let v = row.saa.map_or(0.0, |v| 100.0 * v);
                Text::new(
                    format!("{v:.0}% n={}", row.expected),
                    (v + 0.8, y0 + h * 0.9),
                    (FONT, font).into_font().color(&color(mi)),
                )
            })
            .collect();
        chart.draw_series(labels).map_err(e)?;
    }
    for (mi, m) in r.models.iter().enumerate() {
        let c = color(mi);
        let bars: Vec<_> = m
            .by_family
            .iter()
            .enumerate()
            .filter_map(|(fi, row)| {
                let v = row.saa?;
                let y0 = (n - 1 - fi) as f64 + 0.4 - (mi + 1) as f64 * h;
                Some(Rectangle::new(
                    [(0.0, y0), (100.0 * v, y0 + h * 0.9)],
                    c.filled(),
                ))
            })
            .collect();
        chart.draw_series(bars).map_err(e)?;
    }
    draw_legend(&legend_area, &legend_items)?;
    root.present().map_err(e)?;
    Ok(())
}

/// A chart of horizontal percentage bars (0–100 % of decisions), one row per name from
/// the top, its axes drawn; `label_width` px for the row names.
fn percent_rows_chart<'a, DB: DrawingBackend>(
    plot: &DrawingArea<DB, Shift>,
    caption: &str,
    names: &[String],
    label_width: u32,
) -> Result<
    ChartContext<
        'a,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
> {
    let n = names.len().max(1);
    let mut chart = ChartBuilder::on(plot)
        .caption(caption, (FONT, 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(label_width)
        .build_cartesian_2d(0f64..100f64, -0.5f64..(n as f64 - 0.5))
        .map_err(e)?;
    chart
        .configure_mesh()
        .max_light_lines(0)
        .y_labels(n + 1)
        .y_label_formatter(&|y| category_label(names, *y))
        .disable_y_mesh()
        .x_desc("decisions (%)")
        .x_label_formatter(&percent_label)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(e)?;
    Ok(chart)
}

fn safety_rules<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, r: &Report) -> DrawResult {
    root.fill(&WHITE).map_err(e)?;
    let rows: Vec<_> = r.analyses.safety.iter().collect();
    let n = rows.len().max(1);
    let names: Vec<String> = rows
        .iter()
        .map(|s| format!("{} n={}", s.model, s.decisions))
        .collect();
    let legend_items: Vec<(String, RGBColor)> = SafetyRule::ALL
        .iter()
        .map(|r| {
            (
                format!("{}: {}", r.as_str(), r.describe()),
                color(r.index() + 3),
            )
        })
        .collect();
    let (_, h) = root.dim_in_pixel();
    let (plot, legend_area) = root.split_vertically(h as i32 - LEGEND_BELOW);
    let mut chart = percent_rows_chart(
        &plot,
        "Safety violations by first rule (% of decisions)",
        &names,
        140,
    )?;
    for (i, s) in rows.iter().enumerate() {
        let y = (n - 1 - i) as f64;
        let label = if s.decisions == 0 {
            "no decisions".to_string()
        } else if s.violations == 0 {
            "no violations".to_string()
        } else {
            continue;
        };
        chart
            .draw_series(std::iter::once(Text::new(
                label,
                (1.0, y + 0.12),
                (FONT, 12),
            )))
            .map_err(e)?;
    }
    for rule in SafetyRule::ALL {
        let c = color(rule.index() + 3);
        let bars: Vec<_> = rows
            .iter()
            .enumerate()
            .filter(|(_, s)| s.decisions > 0)
            .map(|(i, s)| {
                let d = s.decisions as f64;
                let before: u64 = SafetyRule::ALL[..rule.index()]
                    .iter()
                    .map(|r| s.first_rule.get(*r))
                    .sum();
                let x0 = 100.0 * before as f64 / d;
                let x1 = x0 + 100.0 * s.first_rule.get(rule) as f64 / d;
                let y = (n - 1 - i) as f64;
                Rectangle::new([(x0, y - 0.35), (x1, y + 0.35)], c.filled())
            })
            .collect();
        chart.draw_series(bars).map_err(e)?;
    }
    for (i, (label, c)) in legend_items.iter().enumerate() {
        let x = 160 + 480 * (i as i32 % 2);
        let y = 10 + 22 * (i as i32 / 2);
        legend_area
            .draw(&Rectangle::new([(x, y), (x + 14, y + 12)], c.filled()))
            .map_err(e)?;
        legend_area
            .draw(&Text::new(label.clone(), (x + 20, y - 1), (FONT, 12)))
            .map_err(e)?;
    }
    root.present().map_err(e)?;
    Ok(())
}

/// Outcome segments of the `outcomes` figure: name, colour.
const OUTCOME_SEGMENTS: [(&str, RGBColor); 5] = [
    ("caught", RGBColor(44, 160, 44)),
    ("struck", RGBColor(214, 39, 40)),
    ("missed", RGBColor(255, 127, 14)),
    ("clear", RGBColor(120, 144, 156)),
    ("not executed (R1)", RGBColor(215, 215, 215)),
];

/// The `outcomes` figure's rows: per model its decisions, then per ground-truth action.
fn outcome_rows(x: &crate::execution::ExecutionReport) -> Vec<(String, [u64; 5])> {
    use crate::execution::report::Counts;
    let seg = |c: &Counts| [c.caught, c.struck, c.missed, c.clear, c.not_executed];
    let mut rows = Vec::new();
    for m in &x.models {
        let n = |c: &Counts| seg(c).iter().sum::<u64>();
        rows.push((format!("{} (all) n={}", m.model, n(&m.all)), seg(&m.all)));
        for (gt, c) in &m.by_gt_action {
            rows.push((format!("{}  gt {gt} n={}", m.model, n(c)), seg(c)));
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
    let longest = names.iter().map(|s| s.chars().count()).max().unwrap_or(0);
    let (_, h) = root.dim_in_pixel();
    let (plot, legend_area) = root.split_vertically(h as i32 - 40);
    let mut chart = percent_rows_chart(
        &plot,
        "Execution outcomes (% of decisions; per model and ground-truth action)",
        &names,
        (20 + longest * 7).clamp(140, 420) as u32,
    )?;
    for (si, (_, c)) in OUTCOME_SEGMENTS.iter().enumerate() {
        let bars: Vec<_> = rows
            .iter()
            .enumerate()
            .filter_map(|(i, (_, counts))| {
                let total: u64 = counts.iter().sum();
                if total == 0 || counts[si] == 0 {
                    return None;
                }
                let before: u64 = counts[..si].iter().sum();
                let x0 = 100.0 * before as f64 / total as f64;
                let x1 = x0 + 100.0 * counts[si] as f64 / total as f64;
                let y = (n - 1 - i) as f64;
                Some(Rectangle::new([(x0, y - 0.35), (x1, y + 0.35)], c.filled()))
            })
            .collect();
        chart.draw_series(bars).map_err(e)?;
    }
    for (i, (label, c)) in OUTCOME_SEGMENTS.iter().enumerate() {
        let x = 20 + 150 * i as i32;
        legend_area
            .draw(&Rectangle::new([(x, 10), (x + 14, 22)], c.filled()))
            .map_err(e)?;
        legend_area
            .draw(&Text::new(label.to_string(), (x + 20, 9), (FONT, 12)))
            .map_err(e)?;
    }
    root.present().map_err(e)?;
    Ok(())
}

/// Height of the legend strip under the safety-rule chart (two rows of two).
const LEGEND_BELOW: i32 = 60;

/// Tick label of a percentage axis: whole numbers ("10", not "10.0", which the bitmap
/// font spaced as "10. 0").
fn percent_label(v: &f64) -> String {
    if (-1e-9..=100.0 + 1e-9).contains(v) {
        format!("{v:.0}")
    } else {
        String::new()
    }
}

macro_rules! both {
    ($dir:expr, $name:literal, $size:expr, $f:ident, $r:expr, $out:expr) => {{
        let svg = $dir.join(concat!($name, ".svg"));
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, $size).into_drawing_area();
            $f(&root, $r)?;
        }
        rh_contract::fsio::write_file(&svg, "a figure", text.as_bytes())?;
        let png = $dir.join(concat!($name, ".png"));
        let (w, h) = $size;
        let mut pixels = vec![0u8; w as usize * h as usize * 3];
        {
            let root = BitMapBackend::with_buffer(&mut pixels, $size).into_drawing_area();
            $f(&root, $r)?;
        }
        rh_contract::fsio::write_file(&png, "a figure", &png_bytes(&pixels, w, h)?)?;
        $out.push(svg);
        $out.push(png);
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

/// Writes every figure into `dir` (created if needed), each file whole or not at all
/// (`rh_contract::fsio`); returns the files written.
pub fn write_figures(r: &Report, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
    register_font();
    std::fs::create_dir_all(dir)
        .map_err(|e| rh_contract::fsio::CannotWrite::new("the figures directory", dir, e))?;
    let mut out = Vec::new();
    let fam_h = (140
        + r.dataset.families.len().max(4) as u32 * (14 + 10 * r.models.len().clamp(1, 8) as u32))
        .min(2400);
    let safety_h = (160 + 40 * r.analyses.safety.len() as u32).max(320) + LEGEND_BELOW as u32;
    both!(dir, "disposition", (640, 600), disposition, r, out);
    both!(dir, "freeze_by_band", (900, 500), freeze_by_band, r, out);
    both!(dir, "per_family", (1080, fam_h), per_family, r, out);
    both!(dir, "safety_rules", (1000, safety_h), safety_rules, r, out);
    if let Some(x) = &r.execution {
        let outcomes_h = (140 + 26 * outcome_rows(x).len() as u32).clamp(300, 2400);
        both!(dir, "outcomes", (1000, outcomes_h), outcomes, r, out);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::baseline::{baseline_plan, majority_action, BaselineKind};
    use crate::config::Config;
    use crate::synthetic::{dataset_of, synth_rows};

    #[test]
    fn bars_carry_value_and_n_and_meshes_have_no_fine_grid() {
        let ds = dataset_of(&synth_rows(80, 2));
        let cfg = Config::default();
        let maj = majority_action(&ds);
        let mut text = String::new();
        for s in ds.scenes.iter().filter(|s| s.valid) {
            let plan = baseline_plan(BaselineKind::Oracle, s, maj, 0, &cfg);
            text += &serde_json::json!({"scene_id": s.scene_id, "model": "oracle", "plan": plan})
                .to_string();
            // A model that never answers with a plan: SAA 0 % in every family.
            text += &format!(
                "\n{{\"scene_id\":\"{}\",\"model\":\"mute\",\"response\":\"no\"}}\n",
                s.scene_id
            );
        }
        let mut sc = crate::score::Scoring::new(&ds, &cfg);
        sc.score_reader(std::io::Cursor::new(text.into_bytes()))
            .unwrap();
        let r = Report::build(&sc, "mem");
        let dir = tempfile::tempdir().unwrap();
        write_figures(&r, dir.path()).unwrap();
        let svg = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap();
        let fam = svg("per_family.svg");
        // One label per (model, family) bar; the mute model's 0 % bars say so.
        let labels = fam.matches(" n=").count();
        assert_eq!(labels, 2 * ds.families.len(), "{labels}");
        assert!(fam.contains("0% n="), "a 0 % bar is labelled: {fam}");
        assert!(svg("safety_rules.svg").contains("mute n="));
        // Only the major mesh lines (plotters draws its fine "light" mesh, the 1 % graph
        // paper, in black at opacity 0.1; the major lines at 0.2).
        for f in [
            "disposition",
            "freeze_by_band",
            "per_family",
            "safety_rules",
        ] {
            let text = svg(&format!("{f}.svg"));
            assert!(
                text.contains("opacity=\"0.2\""),
                "{f}: major mesh lines drawn"
            );
            assert!(!text.contains("opacity=\"0.1\""), "{f}: no fine mesh");
        }
        assert!(svg("disposition.svg").contains("oracle (n="));
    }
}
