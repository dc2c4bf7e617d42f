//! The IGES reader on arbitrary bytes: parsing never panics, an accepted document writes
//! back byte for byte, and its typed views and NURBS conversions never panic either.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(doc) = cadmorph_iges::Document::parse(data) {
        assert!(doc.write() == data, "unchanged round trip differs");
        for e in doc.entities() {
            let _ = doc.view(e.id());
        }
        for f in doc.faces() {
            let _ = doc.face_surface(&f);
        }
        for e in doc.entities() {
            let _ = doc.curve(e.id());
        }
    }
});
