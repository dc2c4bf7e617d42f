//! The versioned JSON of every `--json` output: each document is an object whose
//! `schema` field names its kind and version (`cadmorph.seams/1`), described by the JSON
//! Schema shipped in `crates/cli/schema/cadmorph.schema.json` (printed by `cadmorph
//! schema`). A version changes only when a field is removed or changes meaning; new
//! fields may be added within one.

use anyhow::Result;
use serde_json::{Map, Value};

/// The version of every document kind this build writes.
pub const VERSION: u32 = 1;

/// The shipped JSON Schema (draft 2020-12).
pub const SCHEMA: &str = include_str!("../schema/cadmorph.schema.json");

/// `body` (an object) with the field `schema: "cadmorph.<kind>/<VERSION>"` added.
pub fn document(kind: &str, body: Value) -> Value {
    let mut out = Map::new();
    out.insert("schema".to_owned(), Value::String(format!("cadmorph.{kind}/{VERSION}")));
    match body {
        Value::Object(fields) => out.extend(fields),
        other => {
            out.insert("value".to_owned(), other);
        }
    }
    Value::Object(out)
}

/// Prints the document of `kind` on standard output.
pub fn print(kind: &str, body: Value) -> Result<()> {
    println!("{}", serde_json::to_string_pretty(&document(kind, body))?);
    Ok(())
}

/// Arguments of `schema`.
#[derive(clap::Args)]
pub struct Args {}

/// Runs `schema`: prints the JSON Schema of every `--json` output.
pub fn run(_: Args) -> Result<()> {
    print!("{SCHEMA}");
    Ok(())
}
