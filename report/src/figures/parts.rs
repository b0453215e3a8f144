//! Drawing parts of the figures: text styles, model markers, error bars, labels on a
//! white box, and legends (a column beside a chart or rows under it), every key and its
//! label centred on one line.

use super::{color, dash, e, DrawResult, FONT, LABEL};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// A text style anchored at `h`, `v`.
pub(super) fn style(size: u32, c: RGBColor, h: HPos, v: VPos) -> TextStyle<'static> {
    let mut st = TextStyle::from((FONT, size).into_font()).pos(Pos::new(h, v));
    st.color = c.to_backend_color();
    st
}

/// Draws model `i`'s marker (circle, triangle, square, diamond, cross, inverted
/// triangle, then again) centred at
/// pixel `p` of `area`.
pub(super) fn marker<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    i: usize,
    p: (i32, i32),
    r: i32,
) -> DrawResult {
    let c = color(i);
    let fill = c.filled();
    let outline = WHITE.stroke_width(1);
    let (x, y) = p;
    match i % 6 {
        0 => {
            area.draw(&Circle::new(p, r, fill)).map_err(e)?;
            area.draw(&Circle::new(p, r, outline)).map_err(e)?;
        }
        1 => {
            let pts = vec![(x, y - r - 1), (x + r + 1, y + r), (x - r - 1, y + r)];
            area.draw(&Polygon::new(pts, fill)).map_err(e)?;
        }
        2 => {
            let s = r - 1;
            area.draw(&Rectangle::new([(x - s, y - s), (x + s, y + s)], fill))
                .map_err(e)?;
        }
        3 => {
            let s = r + 1;
            let pts = vec![(x, y - s), (x + s, y), (x, y + s), (x - s, y)];
            area.draw(&Polygon::new(pts, fill)).map_err(e)?;
        }
        5 => {
            let pts = vec![(x, y + r + 1), (x + r + 1, y - r), (x - r - 1, y - r)];
            area.draw(&Polygon::new(pts, fill)).map_err(e)?;
        }
        _ => {
            let st = c.stroke_width(3);
            area.draw(&PathElement::new(vec![(x - r, y - r), (x + r, y + r)], st))
                .map_err(e)?;
            area.draw(&PathElement::new(vec![(x - r, y + r), (x + r, y - r)], st))
                .map_err(e)?;
        }
    }
    Ok(())
}

/// An error bar between pixels `a` and `b` with end caps across it.
pub(super) fn error_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    a: (i32, i32),
    b: (i32, i32),
    c: RGBColor,
) -> DrawResult {
    let st = c.stroke_width(2);
    area.draw(&PathElement::new(vec![a, b], st)).map_err(e)?;
    let vertical = a.0 == b.0;
    for p in [a, b] {
        let cap = if vertical {
            vec![(p.0 - 4, p.1), (p.0 + 4, p.1)]
        } else {
            vec![(p.0, p.1 - 4), (p.0, p.1 + 4)]
        };
        area.draw(&PathElement::new(cap, st)).map_err(e)?;
    }
    Ok(())
}

/// Text on a white box (so no grid line runs through it), anchored left-centre at `p`.
pub(super) fn boxed_label<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    p: (i32, i32),
    c: RGBColor,
) -> DrawResult {
    let st = style(LABEL, c, HPos::Left, VPos::Center);
    let (w, h) = area.estimate_text_size(text, &st).map_err(e)?;
    let (w, h) = (w as i32, h as i32);
    area.draw(&Rectangle::new(
        [(p.0 - 2, p.1 - h / 2 - 2), (p.0 + w + 2, p.1 + h / 2 + 2)],
        WHITE.filled(),
    ))
    .map_err(e)?;
    area.draw(&Text::new(text.to_string(), p, st)).map_err(e)?;
    Ok(())
}

/// What a legend row shows left of its label.
#[derive(Clone, Copy)]
pub(super) enum Key {
    /// A filled square.
    Swatch(RGBColor),
    /// Model `i`'s marker.
    Marker(usize),
    /// Model `i`'s line style and marker.
    Line(usize),
}

pub(super) const ROW: i32 = 26;

fn legend_width(items: &[(String, Key)]) -> i32 {
    let longest = items.iter().map(|i| i.0.chars().count()).max().unwrap_or(0);
    (60 + longest as i32 * (LABEL as i32 * 62 / 100)).clamp(140, 520)
}

/// Splits off a legend column on the right, wide enough for the longest label.
pub(super) fn split_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    items: &[(String, Key)],
) -> (DrawingArea<DB, Shift>, DrawingArea<DB, Shift>) {
    let (w, _) = root.dim_in_pixel();
    root.split_horizontally(w as i32 - legend_width(items))
}

/// A key at pixel `(x, yc)` (its vertical centre), 30 px wide.
fn draw_key<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    k: Key,
    x: i32,
    yc: i32,
) -> DrawResult {
    match k {
        Key::Swatch(c) => area
            .draw(&Rectangle::new(
                [(x + 8, yc - 7), (x + 22, yc + 7)],
                c.filled(),
            ))
            .map_err(e),
        Key::Marker(i) => marker(area, i, (x + 15, yc), 6),
        Key::Line(i) => {
            let st = color(i).stroke_width(2);
            let pts = vec![(x, yc), (x + 30, yc)];
            match dash(i) {
                (0, _) => area.draw(&PathElement::new(pts, st)).map_err(e)?,
                (d, g) => area
                    .draw(&DashedPathElement::new(pts, d, g, st))
                    .map_err(e)?,
            }
            marker(area, i, (x + 15, yc), 5)
        }
    }
}

/// A legend column: one row per item, its key and label centred on the same line.
pub(super) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    items: &[(String, Key)],
) -> DrawResult {
    for (i, (label, k)) in items.iter().enumerate() {
        let yc = 70 + ROW * i as i32;
        draw_key(area, *k, 4, yc)?;
        let st = style(LABEL, BLACK, HPos::Left, VPos::Center);
        area.draw(&Text::new(label.clone(), (40, yc), st))
            .map_err(e)?;
    }
    Ok(())
}

/// A legend in rows under a chart: items left to right, wrapping at the area's width.
pub(super) fn draw_legend_below<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    items: &[(String, Key)],
    x0: i32,
) -> DrawResult {
    let (w, _) = area.dim_in_pixel();
    let (mut x, mut yc) = (x0, 16);
    for (label, k) in items {
        let st = style(LABEL, BLACK, HPos::Left, VPos::Center);
        let (tw, _) = area.estimate_text_size(label, &st).map_err(e)?;
        let need = 36 + tw as i32 + 24;
        if x > x0 && x + need > w as i32 {
            (x, yc) = (x0, yc + ROW);
        }
        draw_key(area, *k, x, yc)?;
        area.draw(&Text::new(label.clone(), (x + 36, yc), st))
            .map_err(e)?;
        x += need;
    }
    Ok(())
}

/// Rows of the legend under a chart of width `w`, as [`draw_legend_below`] wraps them.
pub(super) fn legend_rows(items: &[(String, Key)], w: i32, x0: i32) -> i32 {
    let (mut x, mut rows) = (x0, 1);
    for (label, _) in items {
        let need = 60 + label.chars().count() as i32 * (LABEL as i32 * 62 / 100);
        if x > x0 && x + need > w {
            (x, rows) = (x0, rows + 1);
        }
        x += need;
    }
    rows
}

/// A lighter shade of a colour (for error bars behind markers).
pub(super) trait Rgb {
    fn rgb_color(&self) -> RGBColor;
}
impl Rgb for RGBAColor {
    fn rgb_color(&self) -> RGBColor {
        let RGBAColor(r, g, b, a) = *self;
        let mix = |c: u8| (c as f64 * a + 255.0 * (1.0 - a)).round() as u8;
        RGBColor(mix(r), mix(g), mix(b))
    }
}
