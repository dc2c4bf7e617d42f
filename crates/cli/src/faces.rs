//! The one face numbering of every subcommand: a face is its index in file order (the
//! order `info` lists, `seams` measures and `ffd fit --around` takes) together with its
//! entity (`DE 7` in IGES, `#531` in STEP), in tables and in JSON alike.

use cadmorph::brep::EntityRef;
use serde_json::{json, Value};

/// `1 (DE 7)`: the index and the face entity, as every table prints a face.
pub fn label(index: usize, entity: &EntityRef) -> String {
    format!("{index} ({entity})")
}

/// `{"index": 1, "entity": "DE 7", "surface": "DE 9"}`: a face in every JSON output.
pub fn json(index: usize, entity: &EntityRef, surface: &EntityRef) -> Value {
    json!({ "index": index, "entity": entity.to_string(), "surface": surface.to_string() })
}

/// An entity in JSON: `"DE 7"` or `"#531"`.
pub fn entity(e: &EntityRef) -> Value {
    Value::String(e.to_string())
}
