//! What the CLI's test files share: the binary, the workspace root, a scratch folder
//! removed when the test ends, and the shipped JSON Schema.

#![allow(dead_code)] // each test file uses its own part

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The workspace root, where the `samples/` paths of the commands start.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs the binary in the workspace root.
pub fn cadmorph(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cadmorph")).args(args).current_dir(root()).output().expect("the binary runs")
}

/// Standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A scratch folder under the system's temporary folder, removed when it is dropped (also
/// when the test fails and unwinds).
pub struct Scratch(PathBuf);

impl Scratch {
    /// A fresh, empty folder named after the test and the process.
    pub fn new(name: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("cadmorph-cli-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("a scratch folder");
        Scratch(d)
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.0
    }

    /// A path in the folder, as a string for a command line.
    pub fn path(&self, name: &str) -> String {
        self.0.join(name).to_string_lossy().into_owned()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The shipped schema, compiled.
pub fn validator() -> jsonschema::Validator {
    let text = std::fs::read_to_string(root().join("crates/cli/schema/cadmorph.schema.json")).expect("the schema file");
    let schema: serde_json::Value = serde_json::from_str(&text).expect("the schema is JSON");
    jsonschema::validator_for(&schema).expect("the schema compiles")
}

/// The errors of `doc` against the schema, one line each (empty: valid).
pub fn schema_errors(v: &jsonschema::Validator, doc: &serde_json::Value) -> Vec<String> {
    v.iter_errors(doc).map(|e| format!("{} at {}", e, e.instance_path)).collect()
}
