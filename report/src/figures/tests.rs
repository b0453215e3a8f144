//! Figure checks on a synthetic report: every figure has its caption, no two text
//! elements of an SVG overlap, text is large enough, percentage axes stop at 100, and
//! the bars carry their values.

use super::*;
use crate::baseline::{baseline_plan, majority_action, BaselineKind};
use crate::config::Config;
use crate::synthetic::{dataset_of, synth_rows};

/// A text element's box in px: (x0, y0, x1, y1), from its font size × characters (0.62 em
/// per character: the embedded monospaced font's advance is 0.6 em, and sans-serif
/// fonts are narrower), its anchor and its rotation.
#[derive(Debug, Clone)]
pub(super) struct TextBox {
    pub text: String,
    pub size: f64,
    pub b: (f64, f64, f64, f64),
}

fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let i = tag.find(&key)? + key.len();
    let j = tag[i..].find('"')? + i;
    Some(tag[i..j].to_string())
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Every `<text>` element of `svg` with its estimated box.
pub(super) fn text_boxes(svg: &str) -> Vec<TextBox> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find("<text") {
        let Some(close) = rest[i..].find('>') else {
            break;
        };
        let tag = &rest[i..i + close];
        let Some(end) = rest[i + close..].find("</text>") else {
            break;
        };
        let text = unescape(rest[i + close + 1..i + close + end].trim());
        rest = &rest[i + close + end..];
        let num = |n: &str| {
            attr(tag, n)
                .and_then(|v| v.parse::<f64>().ok())
                .unwrap_or(0.0)
        };
        let (x, y, f) = (num("x"), num("y"), num("font-size"));
        let w = 0.62 * f * text.chars().count() as f64;
        let x0 = match attr(tag, "text-anchor").as_deref() {
            Some("end") => x - w,
            Some("middle") => x - w / 2.0,
            _ => x,
        };
        let y0 = match attr(tag, "dy").as_deref() {
            Some("0.76em") => y,
            Some("0.5ex") => y - 0.5 * f,
            Some("-0.5ex") => y - f,
            _ => y - 0.8 * f,
        };
        let mut b = (x0, y0, x0 + w, y0 + f);
        if attr(tag, "transform")
            .is_some_and(|t| t.starts_with("rotate(270") || t.starts_with("rotate(90"))
        {
            // Rotated about (x, y): the box turns on its side.
            let (dx0, dy0, dx1, dy1) = (b.0 - x, b.1 - y, b.2 - x, b.3 - y);
            b = (x + dy0.min(dy1), y - dx1, x + dy0.max(dy1), y - dx0);
        }
        if !text.is_empty() {
            out.push(TextBox { text, size: f, b });
        }
    }
    out
}

/// Pairs of text boxes that overlap by more than a pixel each way.
pub(super) fn overlaps(boxes: &[TextBox]) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (i, a) in boxes.iter().enumerate() {
        for b in &boxes[..i] {
            let ox = a.b.2.min(b.b.2) - a.b.0.max(b.b.0);
            let oy = a.b.3.min(b.b.3) - a.b.1.max(b.b.1);
            if ox > 1.0 && oy > 1.0 {
                out.push((a.text.clone(), b.text.clone()));
            }
        }
    }
    out
}

/// A report of the oracle, a model that never answers with a plan (0 % everywhere) and
/// the majority and always-catch baselines (which coincide on the disposition plot
/// when the majority class is CATCH).
fn report() -> (Report, usize) {
    let ds = dataset_of(&synth_rows(120, 2));
    let cfg = Config::default();
    let maj = majority_action(&ds);
    let mut text = String::new();
    for s in ds.scenes.iter().filter(|s| s.valid) {
        for (kind, name) in [
            (BaselineKind::Oracle, "oracle"),
            (BaselineKind::Majority, "majority"),
            (BaselineKind::AlwaysCatch, "always-catch"),
            (BaselineKind::Freeze, "freeze"),
        ] {
            let plan = baseline_plan(kind, s, maj, 0, &cfg);
            text += &serde_json::json!({"scene_id": s.scene_id, "model": name, "plan": plan})
                .to_string();
            text.push('\n');
        }
        text += &format!(
            "{{\"scene_id\":\"{}\",\"model\":\"mute\",\"response\":\"no\"}}\n",
            s.scene_id
        );
    }
    let mut sc = crate::score::Scoring::new(&ds, &cfg);
    sc.score_reader(std::io::Cursor::new(text.into_bytes()))
        .unwrap();
    (Report::build(&sc, "mem"), ds.families.len())
}

#[test]
fn every_figure_has_its_caption_and_no_text_overlaps() {
    let (r, families) = report();
    let dir = tempfile::tempdir().unwrap();
    let files = write_figures(&r, dir.path()).unwrap();
    let names = [
        "disposition",
        "freeze_by_band",
        "per_family",
        "safety_rules",
    ];
    assert_eq!(files.len(), 3 * names.len(), "{files:?}");
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap();
    for f in names {
        let caption = read(&format!("{f}.caption.txt"));
        assert!(
            caption.len() > 200,
            "{f}: a caption that says something: {caption}"
        );
        assert!(
            caption.contains("n = ") || caption.contains("n beside"),
            "{f}: n: {caption}"
        );
        let svg = read(&format!("{f}.svg"));
        let boxes = text_boxes(&svg);
        assert!(boxes.len() >= 8, "{f}: {boxes:?}");
        let clash = overlaps(&boxes);
        assert!(clash.is_empty(), "{f}: overlapping labels {clash:?}");
        for b in &boxes {
            assert!(b.size >= 11.5, "{f}: {:?} is {} px", b.text, b.size);
            if let Ok(v) = b.text.parse::<f64>() {
                assert!((0.0..=100.0).contains(&v), "{f}: a tick at {v}");
            }
        }
        let png = std::fs::read(dir.path().join(format!("{f}.png"))).unwrap();
        assert!(png.starts_with(b"\x89PNG"), "{f}.png");
    }
    // Metric definitions travel with the figures that plot them.
    assert!(read("disposition.caption.txt").contains("situational action accuracy"));
    assert!(read("safety_rules.caption.txt").contains("R4 CATCH or NO_ACTION"));
    assert!(read("freeze_by_band.caption.txt").contains("NO_ACTION"));

    // Per family: one value label per (model, family) bar; the mute model's bars say 0%.
    let fam = read("per_family.svg");
    let labels = text_boxes(&fam)
        .iter()
        .filter(|b| b.text.ends_with('%') && b.text[..b.text.len() - 1].parse::<f64>().is_ok())
        .count();
    assert_eq!(labels, r.models.len() * families, "{labels}");
    assert!(
        fam.contains(">\n0%\n<") || fam.contains(">0%<"),
        "a 0 % bar is labelled"
    );
    // n per family, and no pooled row in the safety figure.
    assert!(fam.contains("(n = "), "n beside each family");
    let safety = read("safety_rules.svg");
    assert!(safety.contains("mute (n="));
    assert!(!safety.contains("ALL (n="), "no pooled row");
    // The disposition's models are in its legend, once each.
    let disp = read("disposition.svg");
    for m in ["oracle", "majority", "always-catch", "mute"] {
        let n = text_boxes(&disp)
            .iter()
            .filter(|b| b.text.starts_with(m))
            .count();
        assert_eq!(n, 1, "{m} in the legend");
    }
    // Only the major mesh lines (plotters draws its fine "light" mesh in black at
    // opacity 0.1; the major lines at 0.2).
    for f in names {
        let text = read(&format!("{f}.svg"));
        assert!(
            text.contains("opacity=\"0.2\""),
            "{f}: major mesh lines drawn"
        );
        assert!(!text.contains("opacity=\"0.1\""), "{f}: no fine mesh");
    }
}

#[test]
fn the_overlap_check_finds_overlapping_labels() {
    let svg = "<svg><text x=\"10\" y=\"10\" dy=\"0.76em\" text-anchor=\"start\" font-size=\"12\">majority</text>\n\
        <text x=\"14\" y=\"12\" dy=\"0.76em\" text-anchor=\"start\" font-size=\"12\">always-catch</text>\n\
        <text x=\"10\" y=\"40\" dy=\"0.76em\" text-anchor=\"start\" font-size=\"12\">apart</text></svg>";
    let boxes = text_boxes(svg);
    assert_eq!(boxes.len(), 3);
    assert_eq!(
        overlaps(&boxes),
        vec![("always-catch".to_string(), "majority".to_string())]
    );
}

#[test]
fn coinciding_disposition_points_are_set_apart() {
    let (r, _) = report();
    let pts = disposition_points(&r);
    for (i, a) in pts.iter().enumerate() {
        for b in &pts[..i] {
            let d = ((a.x - b.x).powi(2) + (a.y - b.y).powi(2)).sqrt();
            assert!(d >= 2.0, "models {} and {} at {d}", a.model, b.model);
        }
    }
}
