//! The STEP reader on arbitrary bytes: parsing never panics, an accepted document writes
//! back byte for byte, and its units, faces, world NURBS and edge curves never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(doc) = cadmorph_step::Document::parse(data) {
        assert!(doc.write() == data, "unchanged round trip differs");
        let _ = doc.units();
        let _ = doc.entity_counts();
        for i in doc.instances().take(256) {
            let _ = i.body();
            let _ = doc.point(i.id());
            let _ = doc.bspline_curve(i.id());
            let _ = doc.bspline_surface(i.id());
        }
        if let Ok(faces) = doc.faces() {
            for f in faces.iter().take(64) {
                let _ = doc.face_nurbs(f);
            }
            if let Ok(edges) = doc.edges(&faces) {
                for e in edges.iter().take(128) {
                    let _ = doc.edge_curve(e);
                }
            }
        }
    }
});
