//! Stage 1 with a language model (specification §3: the paper's planner is an LLM).
//!
//! [`LlmPlanner`] asks a model, through the shared OpenAI-compatible client
//! ([`rh_llm::Client`], with its response cache, retries and rate-limit handling), for a
//! selection `{family, object_id, room_id}` — never a number. The answer is validated
//! against the catalogue and the family's rules (the object appears in the family, the
//! room hosts it, the family is implemented); on an invalid answer the model is told the
//! error and asked again, up to `max_tries` (configs/planner.toml). If it never gives a
//! valid selection, or the API fails, the deterministic [`LexiconPlanner`] decides and the
//! fallback is recorded in the selection ([`PlannerRecord`], stored in every spec). The
//! description text is stored too. Given its selections a build stays seed-pure, and with
//! the cache a rebuild from the same descriptions makes no request.

use rh_catalog::Catalog;
use rh_physics::spec::{PlannerRecord, Selection};
use rh_scenes::selection::{LexiconPlanner, PlanError, Planner};
use serde::Deserialize;
use serde_json::{json, Value};

const PLANNER_TOML: &str = include_str!("../../configs/planner.toml");

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannerConfig {
    pub version: String,
    pub max_tries: u32,
    pub temperature: f64,
    pub max_tokens: u32,
    pub system: String,
    pub user: String,
    pub retry: String,
    pub client: rh_llm::ClientConfig,
}

impl PlannerConfig {
    pub fn embedded() -> PlannerConfig {
        toml::from_str(PLANNER_TOML).expect("configs/planner.toml is valid")
    }
}

/// The planner that asks a model.
pub struct LlmPlanner<'a> {
    catalog: &'a Catalog,
    client: rh_llm::Client,
    model: String,
    cfg: PlannerConfig,
    rt: tokio::runtime::Runtime,
}

/// Why an answer is not a valid selection (told to the model).
fn validate(catalog: &Catalog, answer: &str) -> Result<(String, String, String), String> {
    let v = first_json_object(answer).ok_or_else(|| {
        "the answer holds no JSON object; reply with {\"family\", \"object_id\", \"room_id\"}"
            .to_string()
    })?;
    let field = |k: &str| -> Result<String, String> {
        v.get(k)
            .and_then(Value::as_str)
            .map(|s| s.trim().to_string())
            .ok_or_else(|| format!("field \"{k}\" is missing or not a string"))
    };
    let (family, object_id, room_id) = (field("family")?, field("object_id")?, field("room_id")?);
    if rh_scenes::families::get(&family).is_none() {
        return Err(format!(
            "family \"{family}\" does not exist; choose one of: {}",
            rh_scenes::randomize::implemented_families()
        ));
    }
    let object = catalog.object(&object_id).ok_or_else(|| {
        format!(
            "object_id \"{object_id}\" is not in the catalogue; objects for {family} include: {}",
            examples(catalog, &family)
        )
    })?;
    if !object.families.contains(&family) {
        return Err(format!(
            "object \"{object_id}\" cannot take part in {family}; it appears in: {}. Objects for {family} include: {}",
            object.families.join(", "),
            examples(catalog, &family)
        ));
    }
    let room = catalog
        .room(&room_id)
        .ok_or_else(|| format!("room_id \"{room_id}\" is not a catalogue room"))?;
    if !room.hosts(&family) {
        return Err(format!(
            "room \"{room_id}\" does not host {family}; rooms that do: {}",
            catalog
                .rooms_for_family(&family)
                .map(|r| r.id.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    Ok((family, object_id, room_id))
}

fn examples(catalog: &Catalog, family: &str) -> String {
    catalog
        .objects_for_family(family)
        .take(8)
        .map(|o| o.id.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The first balanced `{...}` of a text that parses as a JSON object.
fn first_json_object(text: &str) -> Option<serde_json::Map<String, Value>> {
    let bytes = text.as_bytes();
    let mut start = 0;
    while let Some(off) = bytes[start..].iter().position(|&b| b == b'{') {
        let s = start + off;
        let (mut depth, mut in_str, mut esc) = (0usize, false, false);
        for (i, &b) in bytes[s..].iter().enumerate() {
            if in_str {
                match (esc, b) {
                    (true, _) => esc = false,
                    (false, b'\\') => esc = true,
                    (false, b'"') => in_str = false,
                    _ => {}
                }
                continue;
            }
            match b {
                b'"' => in_str = true,
                b'{' => depth += 1,
                b'}' => {
                    depth -= 1;
                    if depth == 0 {
                        if let Ok(Value::Object(m)) = serde_json::from_str(&text[s..s + i + 1]) {
                            return Some(m);
                        }
                        break;
                    }
                }
                _ => {}
            }
        }
        start = s + 1;
    }
    None
}

impl<'a> LlmPlanner<'a> {
    pub fn new(
        catalog: &'a Catalog,
        client: rh_llm::ClientConfig,
        cache: Option<rh_llm::cache::Cache>,
        model: &str,
        cfg: PlannerConfig,
    ) -> Result<LlmPlanner<'a>, String> {
        let rt = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .map_err(|e| format!("cannot start the async runtime: {e}"))?;
        Ok(LlmPlanner {
            catalog,
            client: rh_llm::Client::new(client, cache)?,
            model: model.to_string(),
            cfg,
            rt,
        })
    }

    fn system_text(&self) -> String {
        let families = rh_scenes::families::all()
            .iter()
            .map(|f| format!("- {}", f.name()))
            .collect::<Vec<_>>()
            .join("\n");
        let objects = self
            .catalog
            .objects
            .iter()
            .map(|o| format!("- {}: {} [{}]", o.id, o.name, o.families.join(", ")))
            .collect::<Vec<_>>()
            .join("\n");
        let rooms = self
            .catalog
            .rooms
            .iter()
            .map(|r| {
                let hosted = if r.families.is_empty() {
                    "all".to_string()
                } else {
                    r.families.join(", ")
                };
                format!("- {}: {} [{hosted}]", r.id, r.name)
            })
            .collect::<Vec<_>>()
            .join("\n");
        self.cfg
            .system
            .replace("{families}", &families)
            .replace("{objects}", &objects)
            .replace("{rooms}", &rooms)
            .trim()
            .to_string()
    }

    /// Asks the model; `Ok` with the validated triple and the tries used, or the reason
    /// it gave none.
    fn ask(&self, description: &str) -> Result<((String, String, String), u32), String> {
        let mut messages = vec![
            json!({"role": "system", "content": self.system_text()}),
            json!({"role": "user", "content": self.cfg.user.replace("{description}", description)}),
        ];
        let mut params = serde_json::Map::new();
        params.insert("temperature".into(), json!(self.cfg.temperature));
        params.insert("max_tokens".into(), json!(self.cfg.max_tokens));
        let mut last = String::new();
        for attempt in 1..=self.cfg.max_tries.max(1) {
            let req = rh_llm::ChatRequest::new(
                &self.model,
                Value::Array(messages.clone()),
                params.clone(),
                0,
            );
            let reply = self.rt.block_on(self.client.chat(&req)).map_err(|e| {
                format!(
                    "the model could not be asked: {}",
                    self.client.redact(&e.to_string())
                )
            })?;
            match validate(self.catalog, &reply.text) {
                Ok(sel) => return Ok((sel, attempt)),
                Err(e) => {
                    messages.push(json!({"role": "assistant", "content": reply.text}));
                    messages.push(
                        json!({"role": "user", "content": self.cfg.retry.replace("{error}", &e)}),
                    );
                    last = e;
                }
            }
        }
        Err(format!(
            "no valid selection in {} tries (last: {last})",
            self.cfg.max_tries.max(1)
        ))
    }
}

impl Planner for LlmPlanner<'_> {
    fn plan(&self, description: &str, seed: u64) -> Result<Selection, PlanError> {
        if description.trim().is_empty() {
            return Err(PlanError::Empty);
        }
        match self.ask(description) {
            Ok(((family, object_id, room_id), tries)) => Ok(Selection {
                family,
                object_id,
                room_id,
                description: Some(description.to_string()),
                planner: Some(PlannerRecord {
                    planner: "llm".into(),
                    model: Some(self.model.clone()),
                    version: Some(self.cfg.version.clone()),
                    tries,
                    fallback: None,
                }),
            }),
            Err(reason) => {
                let mut s = LexiconPlanner::new(self.catalog).plan(description, seed)?;
                s.planner = Some(PlannerRecord {
                    planner: "lexicon".into(),
                    model: Some(self.model.clone()),
                    version: Some(self.cfg.version.clone()),
                    tries: self.cfg.max_tries.max(1),
                    fallback: Some(reason),
                });
                Ok(s)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_what_is_wrong() {
        let c = Catalog::embedded().unwrap();
        let ok = validate(
            &c,
            "Sure: {\"family\": \"bouncing_object\", \"object_id\": \"steel_apple\", \"room_id\": \"kitchen\"}",
        )
        .unwrap();
        assert_eq!(ok.1, "steel_apple");
        let e = validate(
            &c,
            "{\"family\": \"juggling\", \"object_id\": \"apple\", \"room_id\": \"kitchen\"}",
        )
        .unwrap_err();
        assert!(e.contains("family \"juggling\" does not exist"), "{e}");
        let e = validate(
            &c,
            "{\"family\": \"thrown_object\", \"object_id\": \"unicorn\", \"room_id\": \"kitchen\"}",
        )
        .unwrap_err();
        assert!(e.contains("not in the catalogue"), "{e}");
        let e = validate(&c, "no json here").unwrap_err();
        assert!(e.contains("no JSON object"), "{e}");
        assert!(PlannerConfig::embedded().max_tries >= 1);
    }
}
