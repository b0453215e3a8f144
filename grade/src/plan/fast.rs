//! The fast path: a strictly typed parse of the common plan shape. Anything unusual
//! (numeric strings, aliases, missing hands, nested plans, duplicate keys) makes it give
//! up, and the lenient `Value` path decides; both give the same plan for what both
//! accept.

use super::{Parts, RawKf};
use serde::de::{self, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;

#[derive(Deserialize)]
struct FastPlan {
    intent: Option<String>,
    confidence: Option<f64>,
    walking_cmd: Option<[f64; 3]>,
    walking_duration: Option<f64>,
    keyframes: Option<Vec<FastKf>>,
    // Wrappers the lenient path may unwrap: give up when present.
    plan: Option<IgnoredAny>,
    reaction_plan: Option<IgnoredAny>,
    output: Option<IgnoredAny>,
    response: Option<IgnoredAny>,
}

struct FastKf(RawKf);

impl<'de> Deserialize<'de> for FastKf {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = FastKf;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a keyframe")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<FastKf, A::Error> {
                let mut p = [0.0; 3];
                for x in p.iter_mut() {
                    *x = a
                        .next_element()?
                        .ok_or_else(|| de::Error::custom("short point"))?;
                }
                if a.next_element::<IgnoredAny>()?.is_some() {
                    return Err(de::Error::custom("long point"));
                }
                Ok(FastKf(RawKf {
                    t: None,
                    left: Some(p),
                    right: Some(p),
                    knee_bend: 0.0,
                    bare: true,
                }))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<FastKf, A::Error> {
                let mut k = RawKf {
                    t: None,
                    left: None,
                    right: None,
                    knee_bend: 0.0,
                    bare: false,
                };
                let mut seen = [false; 4];
                while let Some(key) = a.next_key::<std::borrow::Cow<'de, str>>()? {
                    let slot = match key.as_ref() {
                        "t" => 0,
                        "left_hand" => 1,
                        "right_hand" => 2,
                        "knee_bend" => 3,
                        _ => return Err(de::Error::custom("unknown keyframe key")),
                    };
                    if std::mem::replace(&mut seen[slot], true) {
                        return Err(de::Error::custom("duplicate key"));
                    }
                    match slot {
                        0 => k.t = a.next_value()?,
                        1 => k.left = a.next_value()?,
                        2 => k.right = a.next_value()?,
                        _ => k.knee_bend = a.next_value::<Option<f64>>()?.unwrap_or(0.0),
                    }
                }
                if k.left.is_none() && k.right.is_none() {
                    return Err(de::Error::custom("no hands"));
                }
                Ok(FastKf(k))
            }
        }
        d.deserialize_any(V)
    }
}

/// The plan's parts, or `None` to fall back to the lenient path.
pub(super) fn parts(text: &str) -> Option<Parts> {
    let p: FastPlan = serde_json::from_str(text).ok()?;
    if p.plan.is_some() || p.reaction_plan.is_some() || p.output.is_some() || p.response.is_some() {
        return None;
    }
    if p.walking_cmd.is_none() && p.keyframes.is_none() {
        return None;
    }
    Some(Parts {
        intent: p.intent,
        confidence: p.confidence,
        cmd: p.walking_cmd.unwrap_or([0.0; 3]),
        duration: p.walking_duration,
        keyframes: p
            .keyframes
            .unwrap_or_default()
            .into_iter()
            .map(|k| k.0)
            .collect(),
    })
}
