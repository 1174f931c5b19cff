//! ROS 2 type description hashes (RIHS01, REP 2016), computed from `.msg` texts.
//!
//! A type's hash is the SHA-256 of a canonical JSON form of its type description: the type's
//! name and fields (each field's name, type id, capacity, string capacity and nested type name,
//! as in type_description_interfaces/msg/FieldType) and the same for every type it references,
//! sorted by name. Default values and constants are not part of it. Written as
//! `RIHS01_<64 hex digits>`. These are the hashes rosbag2 Jazzy writes in `metadata.yaml`
//! (`type_description_hash`) and in each MCAP channel's metadata (`topic_type_hash`); a test checks
//! them against rosbags' independent implementation and the Jazzy hashes of the standard types.
//!
//! The input is the MCAP `ros2msg` schema form: the type's own `.msg` text, then each dependency
//! after a line of `=` and a `MSG: pkg/Type` line (as [`super::RosMessage::schema`] writes it), so
//! the same function hashes our types and topics copied from another bag.

use serde::Serialize;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io;
use thiserror::Error;

/// Why a schema could not be hashed.
#[derive(Debug, Error, PartialEq)]
pub enum TypeHashError {
    /// A line of a `.msg` text that is neither a field, a constant, a comment nor blank.
    #[error("{type_name}: cannot read the field line {line:?}")]
    BadLine {
        /// The type whose text holds the line.
        type_name: String,
        /// The line.
        line: String,
    },
    /// A field's type that is neither primitive nor among the schema's dependencies.
    #[error("{type_name}: field type {field_type:?} is not defined in the schema")]
    UnknownType {
        /// The type whose field it is.
        type_name: String,
        /// The field's type as written.
        field_type: String,
    },
}

/// Field type ids of type_description_interfaces/msg/FieldType (Jazzy).
mod type_id {
    pub const NESTED: u8 = 1;
    pub const STRING: u8 = 17;
    pub const WSTRING: u8 = 18;
    pub const BOUNDED_STRING: u8 = 21;
    pub const BOUNDED_WSTRING: u8 = 22;
    /// Added to a scalar type's id for a fixed-size array `T[N]`.
    pub const ARRAY_OFFSET: u8 = 48;
    /// Added for a bounded sequence `T[<=N]`.
    pub const BOUNDED_SEQUENCE_OFFSET: u8 = 96;
    /// Added for an unbounded sequence `T[]`.
    pub const UNBOUNDED_SEQUENCE_OFFSET: u8 = 144;
}

/// The id of a primitive `.msg` type, or None. `char` is an unsigned 8-bit integer and `byte` an
/// octet in ROS 2 (the `.msg` to IDL mapping of rosidl_adapter).
fn primitive_id(name: &str) -> Option<u8> {
    Some(match name {
        "int8" => 2,
        "uint8" | "char" => 3,
        "int16" => 4,
        "uint16" => 5,
        "int32" => 6,
        "uint32" => 7,
        "int64" => 8,
        "uint64" => 9,
        "float32" => 10,
        "float64" => 11,
        "bool" => 15,
        "byte" => 16,
        _ => return None,
    })
}

#[derive(Debug, Serialize)]
struct FieldType {
    type_id: u8,
    capacity: u64,
    string_capacity: u64,
    nested_type_name: String,
}

#[derive(Debug, Serialize)]
struct Field {
    name: String,
    #[serde(rename = "type")]
    field_type: FieldType,
}

#[derive(Debug, Serialize)]
struct IndividualTypeDescription {
    type_name: String,
    fields: Vec<Field>,
}

#[derive(Debug, Serialize)]
struct TypeDescription {
    type_description: IndividualTypeDescription,
    referenced_type_descriptions: Vec<IndividualTypeDescription>,
}

/// The RIHS01 hash of `type_name` (`pkg/msg/Type` or `pkg/Type`) whose schema is `schema`.
pub fn rihs01(type_name: &str, schema: &str) -> Result<String, TypeHashError> {
    let texts = split_schema(type_name, schema);
    let root = full_name(type_name);
    let mut described = BTreeMap::new();
    describe(&root, &texts, &mut described)?;
    let type_description = described
        .remove(&root)
        .expect("the root type was described");
    let description = TypeDescription {
        type_description,
        // a BTreeMap iterates in name order: the order REP 2016 asks for
        referenced_type_descriptions: described.into_values().collect(),
    };
    let json = canonical_json(&description);
    Ok(format!("RIHS01_{:x}", Sha256::digest(json)))
}

/// `pkg/Type` → `pkg/msg/Type` (a name already in the long form is kept).
fn full_name(name: &str) -> String {
    match name.split('/').collect::<Vec<_>>()[..] {
        [pkg, ty] => format!("{pkg}/msg/{ty}"),
        _ => name.to_string(),
    }
}

/// The schema's `.msg` texts by full type name.
fn split_schema<'a>(type_name: &str, schema: &'a str) -> BTreeMap<String, &'a str> {
    let mut texts = BTreeMap::new();
    let mut name = full_name(type_name);
    let mut start = 0;
    let mut offset = 0;
    for line in schema.split_inclusive('\n') {
        let bare = line.trim_end();
        if bare.len() >= 3 && bare.chars().all(|c| c == '=') {
            texts.insert(name.clone(), &schema[start..offset]);
            start = offset + line.len();
        } else if let Some(next) = bare.strip_prefix("MSG: ") {
            if start == offset {
                name = full_name(next.trim());
                start = offset + line.len();
            }
        }
        offset += line.len();
    }
    texts.insert(name, &schema[start..]);
    texts
}

/// Describes `name` and, recursively, every type its fields reference, into `out`.
fn describe(
    name: &str,
    texts: &BTreeMap<String, &str>,
    out: &mut BTreeMap<String, IndividualTypeDescription>,
) -> Result<(), TypeHashError> {
    if out.contains_key(name) {
        return Ok(());
    }
    let text = texts.get(name).ok_or_else(|| TypeHashError::UnknownType {
        type_name: name.to_string(),
        field_type: name.to_string(),
    })?;
    let package = name.split('/').next().unwrap_or_default();
    let mut fields = Vec::new();
    for line in text.lines() {
        if let Some(field) = parse_field(name, package, line)? {
            fields.push(field);
        }
    }
    if fields.is_empty() {
        // rosidl gives an empty structure one placeholder member
        fields.push(Field {
            name: "structure_needs_at_least_one_member".into(),
            field_type: scalar(3, 0, String::new()),
        });
    }
    let nested: Vec<String> = fields
        .iter()
        .map(|f| f.field_type.nested_type_name.clone())
        .filter(|n| !n.is_empty())
        .collect();
    out.insert(
        name.to_string(),
        IndividualTypeDescription {
            type_name: name.to_string(),
            fields,
        },
    );
    for n in nested {
        if !texts.contains_key(&n) {
            return Err(TypeHashError::UnknownType {
                type_name: name.to_string(),
                field_type: n,
            });
        }
        describe(&n, texts, out)?;
    }
    Ok(())
}

fn scalar(type_id: u8, string_capacity: u64, nested_type_name: String) -> FieldType {
    FieldType {
        type_id,
        capacity: 0,
        string_capacity,
        nested_type_name,
    }
}

/// One `.msg` line → a field; None for blank lines, comments and constants.
fn parse_field(type_name: &str, package: &str, line: &str) -> Result<Option<Field>, TypeHashError> {
    let code = line.split('#').next().unwrap_or_default().trim();
    if code.is_empty() {
        return Ok(None);
    }
    let bad = || TypeHashError::BadLine {
        type_name: type_name.to_string(),
        line: line.to_string(),
    };
    let (ty, rest) = code.split_once(char::is_whitespace).ok_or_else(bad)?;
    let rest = rest.trim_start();
    let name_len = rest
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    let (name, after) = rest.split_at(name_len);
    if name.is_empty() {
        return Err(bad());
    }
    // a constant: `TYPE NAME=value` or `TYPE NAME = value`
    if after.trim_start().starts_with('=') {
        return Ok(None);
    }
    let field_type = parse_type(type_name, package, ty)?;
    Ok(Some(Field {
        name: name.to_string(),
        field_type,
    }))
}

/// A `.msg` type (`float64`, `string<=8`, `Point[]`, `pkg/Type[<=4]`, `uint8[16]`) → its FieldType.
fn parse_type(type_name: &str, package: &str, ty: &str) -> Result<FieldType, TypeHashError> {
    let bad = || TypeHashError::BadLine {
        type_name: type_name.to_string(),
        line: ty.to_string(),
    };
    let (base, array) = match ty.find('[') {
        Some(i) => (
            &ty[..i],
            Some(ty[i + 1..].strip_suffix(']').ok_or_else(bad)?),
        ),
        None => (ty, None),
    };
    let mut field = base_type(type_name, package, base)?;
    let number = |s: &str| s.trim().parse::<u64>().map_err(|_| bad());
    if let Some(a) = array {
        let (offset, capacity) = if a.is_empty() {
            (type_id::UNBOUNDED_SEQUENCE_OFFSET, 0)
        } else if let Some(n) = a.strip_prefix("<=") {
            (type_id::BOUNDED_SEQUENCE_OFFSET, number(n)?)
        } else {
            (type_id::ARRAY_OFFSET, number(a)?)
        };
        field.type_id += offset;
        field.capacity = capacity;
    }
    Ok(field)
}

/// The scalar part of a field type.
fn base_type(type_name: &str, package: &str, base: &str) -> Result<FieldType, TypeHashError> {
    if let Some(id) = primitive_id(base) {
        return Ok(scalar(id, 0, String::new()));
    }
    for (prefix, plain, bounded) in [
        ("string", type_id::STRING, type_id::BOUNDED_STRING),
        ("wstring", type_id::WSTRING, type_id::BOUNDED_WSTRING),
    ] {
        if base == prefix {
            return Ok(scalar(plain, 0, String::new()));
        }
        if let Some(n) = base.strip_prefix(prefix).and_then(|r| r.strip_prefix("<=")) {
            let n = n.parse::<u64>().map_err(|_| TypeHashError::BadLine {
                type_name: type_name.to_string(),
                line: base.to_string(),
            })?;
            return Ok(scalar(bounded, n, String::new()));
        }
    }
    let nested = if base.contains('/') {
        full_name(base)
    } else {
        format!("{package}/msg/{base}")
    };
    Ok(scalar(type_id::NESTED, 0, nested))
}

/// JSON as Python's `json.dumps(..., separators=(', ', ': '))` writes it: the form REP 2016
/// hashes. Keys in declaration order; names are ASCII (checked when parsed).
fn canonical_json(description: &TypeDescription) -> Vec<u8> {
    let mut out = Vec::new();
    let mut ser = serde_json::Serializer::with_formatter(&mut out, SpacedFormatter);
    description
        .serialize(&mut ser)
        .expect("a type description serialises");
    out
}

/// serde_json formatter with `", "` between items and `": "` after keys.
struct SpacedFormatter;

impl serde_json::ser::Formatter for SpacedFormatter {
    fn begin_array_value<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        separate(w, first)
    }

    fn begin_object_key<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        separate(w, first)
    }

    fn begin_object_value<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        w.write_all(b": ")
    }
}

/// `", "` before every item but the first.
fn separate<W: ?Sized + io::Write>(w: &mut W, first: bool) -> io::Result<()> {
    if first {
        Ok(())
    } else {
        w.write_all(b", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::{Clock, DiagnosticArray, Float64, PointStamped, RosMessage, Temperature};

    /// Jazzy's hashes of the standard types (as rosidl generates them; rosbags 0.11.9's
    /// `Typestore.hash_rihs01` over its ROS2_JAZZY store gives the same values).
    #[test]
    fn standard_types_hash_as_in_jazzy() {
        let header_schema = format!(
            "{}\n{}\nMSG: builtin_interfaces/Time\n{}",
            crate::messages::HEADER_DEFINITION.trim_end(),
            "=".repeat(80),
            crate::messages::TIME_DEFINITION
        );
        assert_eq!(
            rihs01("std_msgs/msg/Header", &header_schema).unwrap(),
            "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01"
        );
        assert_eq!(
            rihs01(
                "builtin_interfaces/msg/Time",
                crate::messages::TIME_DEFINITION
            )
            .unwrap(),
            "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197"
        );
        assert_eq!(
            Float64::type_hash(),
            "RIHS01_705ba9c3d1a09df43737eb67095534de36fd426c0587779bda2bc51fe790182a"
        );
        assert_eq!(
            PointStamped::type_hash(),
            "RIHS01_4c0296af86e01e562e9e0405d138a01537247580076c58ea38d7923ac1045897"
        );
        assert_eq!(
            Clock::type_hash(),
            "RIHS01_692f7a66e93a3c83e71765d033b60349ba68023a8c689a79e48078bcb5c58564"
        );
        assert_eq!(
            Temperature::type_hash(),
            "RIHS01_72514a14126ab9f8a9abec974c78e5610a367b59db5da355ff1fb982d5bad4b8"
        );
        // byte fields, constants and a sequence of a nested type of the same package
        assert_eq!(
            DiagnosticArray::type_hash(),
            "RIHS01_5a8a36efb05fb25070fa0fb3810290c0e6cd4862b54a8fb975a1ee8dc55a333e"
        );
    }

    #[test]
    fn arrays_bounds_and_defaults_change_the_description_as_rep_2016_says() {
        let plain = rihs01("p/msg/A", "float64 x\n").unwrap();
        // a default value and a comment are not part of the hash
        assert_eq!(
            rihs01("p/msg/A", "float64 x 0.5  # metres\n").unwrap(),
            plain
        );
        // a constant is not either
        assert_eq!(rihs01("p/msg/A", "int32 K=3\nfloat64 x\n").unwrap(), plain);
        let variants = [
            "float64[] x\n",
            "float64[3] x\n",
            "float64[<=3] x\n",
            "float32 x\n",
        ];
        for v in variants {
            assert_ne!(rihs01("p/msg/A", v).unwrap(), plain, "{v}");
        }
        assert_ne!(
            rihs01("p/msg/A", "string<=8 s\n").unwrap(),
            rihs01("p/msg/A", "string s\n").unwrap()
        );
    }

    #[test]
    fn a_missing_dependency_or_a_bad_line_is_an_error() {
        assert!(matches!(
            rihs01("p/msg/A", "q/Missing m\n"),
            Err(TypeHashError::UnknownType { .. })
        ));
        assert!(matches!(
            rihs01("p/msg/A", "float64\n"),
            Err(TypeHashError::BadLine { .. })
        ));
        assert!(matches!(
            rihs01("p/msg/A", "float64[x] v\n"),
            Err(TypeHashError::BadLine { .. })
        ));
    }
}
