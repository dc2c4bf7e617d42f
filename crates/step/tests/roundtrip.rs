//! Unchanged documents are written back byte for byte.

use std::path::PathBuf;

use cadmorph_step::Document;

fn step_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> =
        cadmorph_testkit::samples_with_suffix(".stp").into_iter().map(|n| cadmorph_testkit::sample(&n)).collect();
    let shared = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/pygem-testdata");
    for entry in std::fs::read_dir(&shared).expect("shared/pygem-testdata is readable") {
        let p = entry.unwrap().path();
        if matches!(p.extension().and_then(|e| e.to_str()), Some("stp" | "step")) {
            files.push(p);
        }
    }
    files.sort();
    files
}

#[test]
fn unchanged_round_trip_is_byte_identical() {
    let files = step_files();
    assert!(files.len() >= 12, "expected the 8 samples and 4 PyGeM files, found {files:?}");
    for f in files {
        let bytes = std::fs::read(&f).unwrap();
        let doc = Document::parse(&bytes).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(!doc.is_empty());
        assert_eq!(doc.write(), bytes, "{}", f.display());
        let mut streamed = Vec::new();
        doc.write_to(&mut streamed).unwrap();
        assert_eq!(streamed, bytes);
    }
}

#[test]
fn every_file_views_without_error() {
    for f in step_files() {
        let doc = Document::parse(&std::fs::read(&f).unwrap()).unwrap();
        let units = doc.units().unwrap();
        let faces = doc.faces().unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        for face in &faces {
            doc.face_nurbs(face).unwrap_or_else(|e| panic!("{}: face {}: {e}", f.display(), face.id));
        }
        let edges = doc.edges(&faces).unwrap();
        for e in &edges {
            doc.edge_curve(e).unwrap_or_else(|err| panic!("{}: edge {}: {err}", f.display(), e.id));
        }
        eprintln!("{}: {} faces, {} edges, unit {:?}", f.display(), faces.len(), edges.len(), units.length);
    }
}

#[test]
fn header_and_counts() {
    let doc = Document::parse(&std::fs::read(cadmorph_testkit::sample("mixed_solid.stp")).unwrap()).unwrap();
    assert_eq!(doc.schemas(), vec!["AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }".to_owned()]);
    let counts = doc.entity_counts();
    assert_eq!(counts["ADVANCED_FACE"], 14);
    assert_eq!(counts["CYLINDRICAL_SURFACE"], 1);
    assert!(counts.keys().any(|k| k.starts_with("(BOUNDED_SURFACE B_SPLINE_SURFACE") || k.starts_with("(")));
}

/// `faces_nurbs` (parallel from 16 faces) gives each face exactly what `face_nurbs` gives
/// it, in order, on every sample (mapped_item.stp has 35 faces, the assemblies 30).
#[test]
fn faces_nurbs_is_face_nurbs_of_each_face() {
    let mut parallel = 0;
    for name in cadmorph_testkit::samples_with_suffix(".stp") {
        let doc = Document::parse(&std::fs::read(cadmorph_testkit::sample(&name)).unwrap()).unwrap();
        let faces = doc.faces().unwrap();
        let batch = doc.faces_nurbs(&faces);
        assert_eq!(batch.len(), faces.len(), "{name}");
        for (f, w) in faces.iter().zip(batch) {
            assert_eq!(w.ok(), doc.face_nurbs(f).ok(), "{name}: face {:?}", f.id);
        }
        parallel += usize::from(faces.len() >= 16);
    }
    assert!(parallel >= 3, "no sample has enough faces to be converted in parallel");
}
