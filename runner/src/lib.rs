//! ReactHuman's model runner and training export: `rh-score predict` ([`predict`]: a
//! model over a dataset through the OpenAI-compatible chat API with the canonical prompt of
//! rh-prompt, into `preds.jsonl`) and `rh-score export` ([`export`]: the canonical prompt
//! with the oracle's plan as fine-tuning data).

pub mod export;
pub mod predict;
