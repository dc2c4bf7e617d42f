//! Unchanged round trips are byte-identical on every IGES file of `samples/` and of the
//! shared PyGeM test data; every entity of a known type has a typed view.

use std::path::PathBuf;

use cadmorph_iges::{Document, View};

/// The shared PyGeM test data, beside the repository (`../shared/pygem-testdata`).
fn pygem_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/pygem-testdata")
}

fn iges_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> =
        cadmorph_testkit::samples_with_suffix(".igs").into_iter().map(|n| cadmorph_testkit::sample(&n)).collect();
    let mut pygem: Vec<PathBuf> = std::fs::read_dir(pygem_dir())
        .expect("../shared/pygem-testdata beside the repository")
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("igs" | "iges")))
        .collect();
    pygem.sort();
    assert!(pygem.len() >= 6, "expected the six PyGeM IGES files, found {}", pygem.len());
    files.extend(pygem);
    files
}

#[test]
fn unchanged_round_trip_is_byte_identical() {
    let files = iges_files();
    assert!(files.len() >= 16);
    for path in files {
        let bytes = std::fs::read(&path).unwrap();
        let doc = Document::parse(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(!doc.is_edited());
        assert!(doc.write() == bytes, "{} differs after a round trip", path.display());
        doc.check_terminate().unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

#[test]
fn every_known_entity_has_a_view() {
    for path in iges_files() {
        let doc = Document::parse(&std::fs::read(&path).unwrap()).unwrap();
        for e in doc.entities() {
            let view = doc.view(e.id()).unwrap_or_else(|err| panic!("{}: {err}", path.display()));
            assert!(!matches!(view, View::Unknown { .. }), "{}: {} has no view", path.display(), e.id());
        }
        assert!(doc.unknown_entities().is_empty());
    }
}
