//! The dataset's rows as JSON objects (every column, by name), for the site's per-scene
//! files.

use crate::error::InputError;
use anyhow::Result;
use arrow::array::{
    Array, ArrayRef, BooleanArray, FixedSizeListArray, Float32Array, Float64Array, Int32Array,
    Int64Array, ListArray, StringArray, UInt32Array, UInt64Array,
};
use arrow::datatypes::DataType;
use serde_json::{Map, Value};
use std::collections::BTreeMap;
use std::path::Path;

fn num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// Row `i` of an Arrow array as JSON (the column types the dataset uses).
fn value(a: &ArrayRef, i: usize) -> Value {
    if a.is_null(i) {
        return Value::Null;
    }
    let any = a.as_any();
    match a.data_type() {
        DataType::Utf8 => Value::String(any.downcast_ref::<StringArray>().unwrap().value(i).into()),
        DataType::Boolean => Value::Bool(any.downcast_ref::<BooleanArray>().unwrap().value(i)),
        DataType::Float64 => num(any.downcast_ref::<Float64Array>().unwrap().value(i)),
        DataType::Float32 => {
            // Shortest decimal that round-trips the f32, not its f64 widening.
            let x = any.downcast_ref::<Float32Array>().unwrap().value(i);
            x.to_string().parse::<f64>().map_or(Value::Null, num)
        }
        DataType::UInt64 => any.downcast_ref::<UInt64Array>().unwrap().value(i).into(),
        DataType::UInt32 => any.downcast_ref::<UInt32Array>().unwrap().value(i).into(),
        DataType::Int64 => any.downcast_ref::<Int64Array>().unwrap().value(i).into(),
        DataType::Int32 => any.downcast_ref::<Int32Array>().unwrap().value(i).into(),
        DataType::List(_) => {
            let l = any.downcast_ref::<ListArray>().unwrap().value(i);
            Value::Array((0..l.len()).map(|j| value(&l, j)).collect())
        }
        DataType::FixedSizeList(_, _) => {
            let l = any.downcast_ref::<FixedSizeListArray>().unwrap().value(i);
            Value::Array((0..l.len()).map(|j| value(&l, j)).collect())
        }
        _ => Value::Null,
    }
}

/// Every row of `dir/data/*.parquet` (files in name order) as a JSON object, keyed by
/// `scene_id` (the first row of a duplicated id wins, as in [`crate::dataset`]).
pub fn read_rows(dir: &Path) -> Result<BTreeMap<String, Map<String, Value>>> {
    let files = crate::dataset::parquet_files(&dir.join("data"))?;
    let mut rows = BTreeMap::new();
    for file in files {
        let reader = crate::dataset::open_parquet(&file, 1024)?;
        for batch in reader {
            let batch = batch.map_err(|e| InputError(format!("{}: {e}", file.display())))?;
            let schema = batch.schema();
            for i in 0..batch.num_rows() {
                let mut row = Map::new();
                for (field, col) in schema.fields().iter().zip(batch.columns()) {
                    row.insert(field.name().clone(), value(col, i));
                }
                let Some(Value::String(id)) = row.get("scene_id").cloned() else {
                    continue;
                };
                rows.entry(id).or_insert(row);
            }
        }
    }
    Ok(rows)
}
