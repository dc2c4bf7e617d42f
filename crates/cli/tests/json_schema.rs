//! Every `--json` output validates against the shipped JSON Schema
//! (`crates/cli/schema/cadmorph.schema.json`, also printed by `cadmorph schema`), with
//! the `jsonschema` crate; and the schema refuses documents that break it.

mod common;

use common::{cadmorph, schema_errors, stderr, validator, Scratch};
use serde_json::Value;

fn json_of(args: &[&str]) -> Value {
    let out = cadmorph(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{args:?}: not JSON: {e}"))
}

fn assert_valid(v: &jsonschema::Validator, args: &[&str], doc: &Value) {
    let errors = schema_errors(v, doc);
    assert!(errors.is_empty(), "{args:?} does not follow the schema:\n{}", errors.join("\n"));
}

#[test]
fn every_json_output_follows_the_schema() {
    let v = validator();
    let s = Scratch::new("schema");
    let (bow, fitted, refined, converted, morphed) =
        (s.path("bow.prm"), s.path("fit.toml"), s.path("r.stp"), s.path("c.stp"), s.path("m.igs"));
    let mut runs: Vec<Vec<String>> = Vec::new();
    for f in ["hull3.igs", "hull3.stp", "mixed_solid.igs", "mixed_solid.stp", "bspline_curve.igs", "nurbs_arc.stp"] {
        runs.push(vec!["info".into(), format!("samples/{f}"), "--json".into()]);
    }
    let mut more = vec![
        vec!["seams", "samples/hull3.igs", "--json", "--samples", "20"],
        vec!["seams", "samples/mixed_solid.stp", "--json", "--samples", "20"],
        vec!["sample", "samples/nurbs_cylinder.stp", "--grid", "2", "--json"],
        vec!["eval", "samples/hull3.igs.ref.json", "--grid", "2", "--json"],
        vec!["refine", "samples/hull3.igs", "-o", &refined, "--knots", "1", "--json"],
        vec!["convert", "samples/hull3.igs", "-o", &converted, "--json"],
        vec!["ffd", "fit", "samples/hull3.igs", "--lattice", "3x2x2", "-o", &fitted, "--json"],
        vec!["ffd", "show", "samples/prm/bow_dome.prm", "--json"],
        vec!["morph", "samples/hull3.igs", "-o", &morphed, "samples/prm/bow_dome.prm", "--json"],
    ];
    let _ = &bow;
    runs.extend(more.drain(..).map(|r| r.into_iter().map(String::from).collect()));
    let mut kinds = std::collections::BTreeSet::new();
    for r in &runs {
        let args: Vec<&str> = r.iter().map(String::as_str).collect();
        let doc = json_of(&args);
        assert_valid(&v, &args, &doc);
        kinds.insert(doc["schema"].as_str().unwrap().to_owned());
    }
    assert_eq!(kinds.len(), 9, "every kind of document is checked: {kinds:?}");
    // A failing check is a document too.
    let out = cadmorph(&["seams", "samples/hull3_defect.igs", "--tol", "1e-3", "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_valid(&v, &["seams --tol"], &doc);
    assert_eq!(doc["check"]["pass"], false);
    // `cadmorph schema` prints the shipped file.
    let printed = json_of(&["schema"]);
    let shipped: Value = serde_json::from_str(
        &std::fs::read_to_string(common::root().join("crates/cli/schema/cadmorph.schema.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(printed, shipped);
}

#[test]
fn the_schema_refuses_documents_that_break_it() {
    let v = validator();
    let doc = json_of(&["info", "samples/hull3.igs", "--json"]);
    assert!(schema_errors(&v, &doc).is_empty());
    let mut wrong_version = doc.clone();
    wrong_version["schema"] = "cadmorph.info/2".into();
    assert!(!schema_errors(&v, &wrong_version).is_empty());
    let mut undocumented = doc.clone();
    undocumented["faces"][0]["colour"] = "red".into();
    assert!(!schema_errors(&v, &undocumented).is_empty(), "a field the schema does not list is caught");
    let mut bad_entity = doc.clone();
    bad_entity["faces"][0]["entity"] = "face three".into();
    assert!(!schema_errors(&v, &bad_entity).is_empty());
    let mut missing = doc;
    missing.as_object_mut().unwrap().remove("unit");
    assert!(!schema_errors(&v, &missing).is_empty());
}
