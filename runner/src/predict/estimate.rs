//! `rh-score predict --dry-run`: an estimate of the whole run's tokens and cost, from the
//! first scene's request (every scene's request has the same text and the same number
//! and size of images; only the pixels differ).
//!
//! Tokens: text ≈ characters / 4; an image as OpenAI counts it — `detail: low` 85
//! tokens; otherwise the image is fitted into 2048 × 2048, its shorter side scaled to
//! 768, and it costs 85 + 170 per 512-pixel tile. Other providers count differently:
//! the figure is an estimate, printed as such. Output tokens are at most `max_tokens`
//! per scene, so the cost is given as a range: input only … input + every answer at
//! `max_tokens`.

use super::config::Price;
use serde::Serialize;
use serde_json::Value;

/// The estimate printed by `--dry-run`.
#[derive(Debug, Clone, Serialize)]
pub struct Estimate {
    pub scenes: usize,
    pub images_per_scene: usize,
    pub input_tokens_per_scene: u64,
    pub input_tokens: u64,
    pub output_tokens_at_most: u64,
    /// USD per million tokens (`null`: the model has no price; give --price-in/--price-out).
    pub price: Option<PriceOut>,
    /// Input tokens only, and input plus every answer at `max_tokens` (USD).
    pub cost_usd_at_least: Option<f64>,
    pub cost_usd_at_most: Option<f64>,
    pub method: &'static str,
}

#[derive(Debug, Clone, Copy, Serialize)]
pub struct PriceOut {
    pub input: f64,
    pub output: f64,
}

/// OpenAI's token count of one image of `w` × `h` pixels at `detail`.
pub fn image_tokens(w: u32, h: u32, detail: &str) -> u64 {
    if detail == "low" {
        return 85;
    }
    let (mut w, mut h) = (w as f64, h as f64);
    let fit = (2048.0 / w.max(h)).min(1.0);
    w *= fit;
    h *= fit;
    let short = (768.0 / w.min(h)).min(1.0);
    w *= short;
    h *= short;
    let tiles = (w / 512.0).ceil() * (h / 512.0).ceil();
    85 + 170 * tiles as u64
}

/// Tokens of one request's messages: (text characters / 4 rounded up + images, images).
fn message_tokens(messages: &Value) -> (u64, usize) {
    let (mut chars, mut tokens, mut images) = (0usize, 0u64, 0usize);
    let mut stack = vec![messages];
    while let Some(v) = stack.pop() {
        match v {
            Value::Array(a) => stack.extend(a),
            Value::Object(m) => {
                if let Some(url) = m
                    .get("image_url")
                    .and_then(|u| u.get("url"))
                    .and_then(Value::as_str)
                {
                    let detail = m["image_url"]
                        .get("detail")
                        .and_then(Value::as_str)
                        .unwrap_or("auto");
                    images += 1;
                    tokens += data_url_size(url).map_or(85, |(w, h)| image_tokens(w, h, detail));
                    continue;
                }
                if let Some(t) = m.get("text").and_then(Value::as_str) {
                    chars += t.chars().count();
                }
                if let Some(c) = m.get("content") {
                    match c {
                        Value::String(t) => chars += t.chars().count(),
                        other => stack.push(other),
                    }
                }
            }
            _ => {}
        }
    }
    (tokens + chars.div_ceil(4) as u64, images)
}

/// Width and height of a base64 image data URL.
fn data_url_size(url: &str) -> Option<(u32, u32)> {
    use base64::Engine;
    let data = url.split_once(',')?.1;
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(data)
        .ok()?;
    image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .ok()?
        .into_dimensions()
        .ok()
}

/// The estimate for `scenes` requests like `messages`, answers of at most `max_tokens`.
pub fn estimate(
    messages: &Value,
    scenes: usize,
    max_tokens: u32,
    price: Option<Price>,
) -> Estimate {
    let (per_scene, images) = message_tokens(messages);
    let input = per_scene * scenes as u64;
    let output = max_tokens as u64 * scenes as u64;
    let cost = |i: u64, o: u64, p: &Price| (i as f64 * p.input + o as f64 * p.output) / 1e6;
    Estimate {
        scenes,
        images_per_scene: images,
        input_tokens_per_scene: per_scene,
        input_tokens: input,
        output_tokens_at_most: output,
        price: price.map(|p| PriceOut {
            input: p.input,
            output: p.output,
        }),
        cost_usd_at_least: price.as_ref().map(|p| cost(input, 0, p)),
        cost_usd_at_most: price.as_ref().map(|p| cost(input, output, p)),
        method: "from the first scene's request: text characters / 4, images as OpenAI counts them \
                 (85 tokens at detail low, else 85 + 170 per 512-px tile); output at most max_tokens \
                 per scene",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_tokens_follow_the_openai_rule() {
        assert_eq!(image_tokens(768, 432, "low"), 85);
        // 768 × 432: shorter side below 768 → no scaling; 2 × 1 tiles.
        assert_eq!(image_tokens(768, 432, "high"), 85 + 170 * 2);
        // 4096 × 2048 → 2048 × 1024 → 1536 × 768: 3 × 2 tiles.
        assert_eq!(image_tokens(4096, 2048, "auto"), 85 + 170 * 6);
    }

    #[test]
    fn estimate_counts_text_images_and_cost() {
        let msgs = serde_json::json!([
            {"role": "system", "content": "abcdefgh"},
            {"role": "user", "content": [
                {"type": "text", "text": "abcd"},
                {"type": "image_url", "image_url": {"url": "data:image/jpeg;base64,!!", "detail": "low"}}
            ]}
        ]);
        let e = estimate(
            &msgs,
            10,
            100,
            Some(Price {
                input: 2.0,
                output: 10.0,
            }),
        );
        // 12 characters = 3 tokens, one undecodable image counted as 85.
        assert_eq!((e.input_tokens_per_scene, e.images_per_scene), (88, 1));
        assert_eq!((e.input_tokens, e.output_tokens_at_most), (880, 1000));
        assert!((e.cost_usd_at_least.unwrap() - 880.0 * 2.0 / 1e6).abs() < 1e-15);
        assert!((e.cost_usd_at_most.unwrap() - (880.0 * 2.0 + 1000.0 * 10.0) / 1e6).abs() < 1e-15);
        assert!(estimate(&msgs, 1, 1, None).cost_usd_at_most.is_none());
    }
}
