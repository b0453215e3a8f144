//! The exported table as Arrow and Parquet: the columns of each format, the `huggingface`
//! schema metadata that `datasets` reads its features from, and a writer that streams row
//! groups to a temporary file renamed into place at the end (`rh_contract::fsio`).

use super::example::{Example, Message, Part};
use arrow::array::{ArrayRef, BinaryArray, ListArray, RecordBatch, StringArray, StructArray};
use arrow::buffer::OffsetBuffer;
use arrow::datatypes::{DataType, Field, Fields, Schema};
use parquet::arrow::ArrowWriter;
use parquet::basic::Compression;
use parquet::file::properties::WriterProperties;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Rows per row group: text rows, and rows carrying images (five JPEGs each).
pub const TEXT_ROW_GROUP: usize = 1000;
pub const IMAGE_ROW_GROUP: usize = 16;

/// The table's shape: SFT or preference rows, with or without images.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shape {
    pub preference: bool,
    pub images: bool,
}

/// Every field is nullable: `datasets` reads its columns as nullable and keeps the
/// metadata's features only for fields equal to its own.
fn utf8(name: &str) -> Field {
    Field::new(name, DataType::Utf8, true)
}

fn list_of(item: DataType) -> DataType {
    DataType::List(Arc::new(Field::new("item", item, true)))
}

/// A content part `{type, text}` (text null for an image part).
fn part_fields() -> Fields {
    Fields::from(vec![utf8("type"), utf8("text")])
}

/// A message `{role, content}`: content is a string (text-only) or a list of parts.
fn message_fields(images: bool) -> Fields {
    let content = if images {
        Field::new("content", list_of(DataType::Struct(part_fields())), true)
    } else {
        utf8("content")
    };
    Fields::from(vec![utf8("role"), content])
}

fn messages_type(images: bool) -> DataType {
    list_of(DataType::Struct(message_fields(images)))
}

/// The Arrow schema of a shape, with the `huggingface` features attached.
pub fn schema(shape: Shape) -> Schema {
    let messages = messages_type(shape.images);
    let mut fields = vec![utf8("scene_id"), utf8("family"), utf8("gt_action")];
    if shape.preference {
        fields.extend([
            Field::new("prompt", messages.clone(), true),
            Field::new("chosen", messages.clone(), true),
            Field::new("rejected", messages, true),
            utf8("rejected_action"),
            Field::new("rejected_rules", list_of(DataType::Utf8), true),
            utf8("rejected_reason"),
        ]);
    } else {
        fields.push(Field::new("messages", messages, true));
    }
    if shape.images {
        fields.push(Field::new(
            "images",
            list_of(rh_contract::arrow_schema::image_type()),
            true,
        ));
    }
    let plain = Schema::new(fields);
    let features = features(&plain);
    let metadata: std::collections::HashMap<String, String> =
        [("huggingface".to_string(), features)].into();
    plain.with_metadata(metadata)
}

/// The `datasets` feature of an Arrow type, as JSON text with struct fields in the
/// schema's order (`datasets` keeps the metadata's features only where their Arrow type,
/// field order and nullability included, equals the file's). Lists are written as a
/// one-element JSON list (`[feature]`), the form every `datasets` version reads as a list
/// of that feature (`Sequence` of a struct meant a struct of lists before `datasets` 4).
fn feature(dt: &DataType) -> String {
    match dt {
        DataType::Utf8 => r#"{"dtype": "string", "_type": "Value"}"#.to_string(),
        DataType::Struct(f) if f.len() == 2 && f[0].name() == "bytes" && f[1].name() == "path" => {
            r#"{"_type": "Image"}"#.to_string()
        }
        DataType::Struct(fields) => {
            let entries: Vec<String> = fields
                .iter()
                .map(|f| {
                    format!(
                        "{}: {}",
                        Value::String(f.name().clone()),
                        feature(f.data_type())
                    )
                })
                .collect();
            format!("{{{}}}", entries.join(", "))
        }
        DataType::List(item) => format!("[{}]", feature(item.data_type())),
        other => unreachable!("no export column has type {other}"),
    }
}

/// `{"info": {"features": {...}}}` with the columns in schema order.
fn features(schema: &Schema) -> String {
    feature(&DataType::Struct(schema.fields().clone()))
        .strip_prefix('{')
        .map(|inner| format!("{{\"info\": {{\"features\": {{{inner}}}}}"))
        .expect("a struct's feature is an object")
}

fn strings<'a>(values: impl Iterator<Item = &'a str>) -> ArrayRef {
    Arc::new(StringArray::from_iter_values(values))
}

/// A list column from per-row lengths and the flattened items.
fn list(item: DataType, lengths: impl Iterator<Item = usize>, values: ArrayRef) -> ArrayRef {
    let field = Arc::new(Field::new("item", item, true));
    Arc::new(ListArray::new(
        field,
        OffsetBuffer::from_lengths(lengths),
        values,
        None,
    ))
}

/// The messages of each row as one list column.
fn messages_column(rows: &[Vec<&Message>], images: bool) -> ArrayRef {
    let all: Vec<&Message> = rows.iter().flatten().copied().collect();
    let roles = strings(all.iter().map(|m| m.role));
    let content: ArrayRef = if images {
        let parts: Vec<&Part> = all.iter().flat_map(|m| &m.content).collect();
        let kinds = strings(parts.iter().map(|p| match p {
            Part::Text(_) => "text",
            Part::Image => "image",
        }));
        let texts: ArrayRef = Arc::new(StringArray::from_iter(parts.iter().map(|p| match p {
            Part::Text(t) => Some(t.as_str()),
            Part::Image => None,
        })));
        let parts = StructArray::new(part_fields(), vec![kinds, texts], None);
        list(
            DataType::Struct(part_fields()),
            all.iter().map(|m| m.content.len()),
            Arc::new(parts),
        )
    } else {
        let texts: Vec<String> = all.iter().map(|m| text_of(m)).collect();
        strings(texts.iter().map(String::as_str))
    };
    let messages = StructArray::new(message_fields(images), vec![roles, content], None);
    list(
        DataType::Struct(message_fields(images)),
        rows.iter().map(Vec::len),
        Arc::new(messages),
    )
}

/// A text-only message's content: its text parts joined by newlines.
pub fn text_of(m: &Message) -> String {
    let texts: Vec<&str> = m
        .content
        .iter()
        .filter_map(|p| match p {
            Part::Text(t) => Some(t.as_str()),
            Part::Image => None,
        })
        .collect();
    texts.join("\n")
}

fn assistant(text: &str) -> Message {
    Message {
        role: "assistant",
        content: vec![Part::Text(text.to_string())],
    }
}

/// The rows of `examples` as one record batch of `schema`.
pub fn batch(examples: &[Example], shape: Shape, schema: &Arc<Schema>) -> RecordBatch {
    let mut columns = vec![
        strings(examples.iter().map(|e| e.scene_id.as_str())),
        strings(examples.iter().map(|e| e.family.as_str())),
        strings(examples.iter().map(|e| e.gt_action.as_str())),
    ];
    let chosen: Vec<Message> = examples.iter().map(|e| assistant(&e.chosen)).collect();
    if shape.preference {
        let rejected: Vec<_> = examples
            .iter()
            .map(|e| {
                e.rejected
                    .as_ref()
                    .expect("preference rows have a rejected plan")
            })
            .collect();
        let rejected_msgs: Vec<Message> = rejected.iter().map(|r| assistant(&r.text)).collect();
        let prompts: Vec<Vec<&Message>> =
            examples.iter().map(|e| e.prompt.iter().collect()).collect();
        columns.push(messages_column(&prompts, shape.images));
        columns.push(messages_column(
            &chosen.iter().map(|m| vec![m]).collect::<Vec<_>>(),
            shape.images,
        ));
        columns.push(messages_column(
            &rejected_msgs.iter().map(|m| vec![m]).collect::<Vec<_>>(),
            shape.images,
        ));
        columns.push(strings(rejected.iter().map(|r| r.action.as_str())));
        let rules = strings(rejected.iter().flat_map(|r| r.rules.iter().copied()));
        columns.push(list(
            DataType::Utf8,
            rejected.iter().map(|r| r.rules.len()),
            rules,
        ));
        columns.push(strings(rejected.iter().map(|r| r.reason.as_str())));
    } else {
        let rows: Vec<Vec<&Message>> = examples
            .iter()
            .zip(&chosen)
            .map(|(e, c)| e.prompt.iter().chain(std::iter::once(c)).collect())
            .collect();
        columns.push(messages_column(&rows, shape.images));
    }
    if shape.images {
        let all: Vec<&(Vec<u8>, String)> = examples.iter().flat_map(|e| &e.images).collect();
        let bytes: ArrayRef = Arc::new(BinaryArray::from_iter_values(
            all.iter().map(|i| i.0.as_slice()),
        ));
        let paths = strings(all.iter().map(|i| i.1.as_str()));
        let DataType::Struct(fields) = rh_contract::arrow_schema::image_type() else {
            unreachable!("an image is a struct")
        };
        let images = StructArray::new(fields, vec![bytes, paths], None);
        columns.push(list(
            rh_contract::arrow_schema::image_type(),
            examples.iter().map(|e| e.images.len()),
            Arc::new(images),
        ));
    }
    RecordBatch::try_new(schema.clone(), columns).expect("columns match the export schema")
}

/// The export's Parquet file, written row group by row group under a temporary name and
/// renamed onto its path by [`Sink::finish`] (dropped unfinished, the temporary is removed).
pub struct Sink {
    pub shape: Shape,
    pub schema: Arc<Schema>,
    writer: Option<ArrowWriter<std::io::BufWriter<std::fs::File>>>,
    pending: Option<rh_contract::fsio::Unsynced>,
    path: PathBuf,
    pub rows: usize,
}

impl Sink {
    pub fn create(path: &Path, shape: Shape) -> Result<Sink, String> {
        let fail = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
        let pending = rh_contract::fsio::Unsynced::at(path).map_err(|e| fail(&e))?;
        let file = std::fs::File::create(pending.temp()).map_err(|e| fail(&e))?;
        let schema = Arc::new(schema(shape));
        let kv = schema.metadata().get("huggingface").map(|v| {
            vec![parquet::file::metadata::KeyValue::new(
                "huggingface".into(),
                v.clone(),
            )]
        });
        let group = if shape.images {
            IMAGE_ROW_GROUP
        } else {
            TEXT_ROW_GROUP
        };
        let props = WriterProperties::builder()
            .set_key_value_metadata(kv)
            .set_compression(Compression::SNAPPY)
            .set_max_row_group_row_count(Some(group))
            .set_created_by("rh-score export".to_string())
            .build();
        let writer =
            ArrowWriter::try_new(std::io::BufWriter::new(file), schema.clone(), Some(props))
                .map_err(|e| fail(&e))?;
        Ok(Sink {
            shape,
            schema,
            writer: Some(writer),
            pending: Some(pending),
            path: path.to_path_buf(),
            rows: 0,
        })
    }

    pub fn write(&mut self, examples: &[Example]) -> Result<(), String> {
        let rows = batch(examples, self.shape, &self.schema);
        let writer = self.writer.as_mut().expect("open until finish");
        writer
            .write(&rows)
            .map_err(|e| format!("{}: {e}", self.path.display()))?;
        self.rows += examples.len();
        Ok(())
    }

    /// Writes the footer, syncs and renames the file into place; returns its path.
    pub fn finish(mut self) -> Result<PathBuf, String> {
        let fail = |e: &dyn std::fmt::Display| format!("{}: {e}", self.path.display());
        let writer = self.writer.take().expect("open until finish");
        writer
            .into_inner()
            .map_err(|e| fail(&e))?
            .into_inner()
            .map_err(|e| fail(&e))?;
        let pending = self.pending.take().expect("open until finish");
        pending.commit().map_err(|e| fail(&e))?;
        Ok(self.path.clone())
    }
}

impl Drop for Sink {
    fn drop(&mut self) {
        if let Some(p) = self.pending.take() {
            p.discard();
        }
    }
}
