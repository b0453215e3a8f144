//! Where a dataset is: `--dataset` (and the Python package's `Dataset(...)`) as a local
//! directory — a path, `$RH_DATASET`, or a Hugging Face Hub dataset id fetched by rh-hub
//! (reqwest), kept out of the grading core, which reads local directories only.

mod hub_dataset;

pub use hub_dataset::resolve_dir;
