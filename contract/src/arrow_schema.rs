//! The scene table as an Arrow schema (feature `arrow`).

use crate::columns::{Column, ColumnType, COLUMNS};
use arrow::datatypes::{DataType, Field, Schema};
use std::sync::Arc;

/// The Arrow type of a column type.
pub fn data_type(ty: ColumnType) -> DataType {
    let list = |item: DataType| DataType::List(Arc::new(Field::new("item", item, true)));
    match ty {
        ColumnType::Utf8 => DataType::Utf8,
        ColumnType::Bool => DataType::Boolean,
        ColumnType::UInt64 => DataType::UInt64,
        ColumnType::UInt32 => DataType::UInt32,
        ColumnType::Float64 => DataType::Float64,
        ColumnType::Vec3 => {
            DataType::FixedSizeList(Arc::new(Field::new("item", DataType::Float64, false)), 3)
        }
        ColumnType::Utf8List => list(DataType::Utf8),
        ColumnType::UInt32List => list(DataType::UInt32),
        ColumnType::Float64List => list(DataType::Float64),
        ColumnType::Vec4F32List => list(DataType::FixedSizeList(
            Arc::new(Field::new("item", DataType::Float32, false)),
            4,
        )),
        ColumnType::ImageList => list(image_type()),
    }
}

/// One image of an `ImageList` column: `{bytes: binary, path: string}`, the Arrow type
/// of `datasets`' `Image` feature.
pub fn image_type() -> DataType {
    DataType::Struct(
        vec![
            Field::new("bytes", DataType::Binary, true),
            Field::new("path", DataType::Utf8, true),
        ]
        .into(),
    )
}

/// The Arrow field of a column.
pub fn field(column: &Column) -> Field {
    Field::new(column.name, data_type(column.ty), column.nullable)
}

/// The scene table's columns, in order, without schema metadata.
pub fn schema() -> Schema {
    Schema::new(COLUMNS.iter().map(field).collect::<Vec<_>>())
}
