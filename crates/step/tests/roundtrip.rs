//! Unchanged documents are written back byte for byte.

use std::path::PathBuf;

#[path = "../benches/generate.rs"]
mod generate;

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

/// `faces_nurbs` (parallel from 64 faces) gives each face exactly what `face_nurbs` gives
/// it, in order: on every sample (up to 42 faces, one thread) and on the generated
/// 300-face file of the benches (several threads).
#[test]
fn faces_nurbs_is_face_nurbs_of_each_face() {
    let mut files: Vec<(String, Vec<u8>)> = cadmorph_testkit::samples_with_suffix(".stp")
        .into_iter()
        .map(|n| {
            let bytes = std::fs::read(cadmorph_testkit::sample(&n)).unwrap();
            (n, bytes)
        })
        .collect();
    files.push(("faces300 (generated)".into(), generate::faces300()));
    for (name, bytes) in files {
        let doc = Document::parse(&bytes).unwrap();
        let faces = doc.faces().unwrap();
        let batch = doc.faces_nurbs(&faces);
        assert_eq!(batch.len(), faces.len(), "{name}");
        for (f, w) in faces.iter().zip(batch) {
            assert_eq!(w.ok(), doc.face_nurbs(f).ok(), "{name}: face {:?}", f.id);
        }
    }
}

/// The generated files of the benches (8.7 and 2.8 MB: read in parallel pieces) are
/// written back byte for byte, with their faces and poles.
#[test]
fn generated_large_files_round_trip() {
    for (bytes, faces, poles) in [(generate::hull3(), 3, 90_000), (generate::faces300(), 300, 300 * 64)] {
        let doc = Document::parse(&bytes).unwrap();
        assert_eq!(doc.write(), bytes);
        let f = doc.faces().unwrap();
        assert_eq!(f.len(), faces);
        let n: usize = doc.faces_nurbs(&f).into_iter().map(|w| w.unwrap().surface.control_points().len()).sum();
        assert_eq!(n, poles);
    }
}
