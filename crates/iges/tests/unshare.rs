//! `Document::unshare_subfigures`: a 308 definition placed by several 408 instances gets a
//! copy per instance, nested definitions included, so that no surface entity serves two
//! placements; every placed face stays where it was, the file reads back the same, and a
//! document without moved faces is left untouched.

use std::collections::{HashMap, HashSet};

use cadmorph_iges::{Document, EntityId, FaceRef};
use cadmorph_nurbs::Surface;
use cadmorph_testkit::sample;

fn read(name: &str) -> (Vec<u8>, Document) {
    let bytes = std::fs::read(sample(name)).unwrap();
    let doc = Document::parse(&bytes).unwrap();
    (bytes, doc)
}

/// Every placed face's model-space surface, evaluated on a 5 × 5 grid.
fn placed_points(doc: &Document, faces: &[FaceRef]) -> Vec<Vec<[f64; 3]>> {
    faces
        .iter()
        .map(|f| {
            let s = doc.face_surface(f).unwrap().surface;
            cadmorph_testkit::grid(&s, 5)
                .into_iter()
                .map(|(u, v)| {
                    let p = s.eval(u, v);
                    [p.x, p.y, p.z]
                })
                .collect()
        })
        .collect()
}

#[test]
fn every_instance_gets_its_own_copy_and_every_face_stays_in_place() {
    let (_, mut doc) = read("subfigure.igs");
    let before = doc.try_faces().unwrap();
    assert_eq!(before.len(), 28);
    let points = placed_points(&doc, &before);
    let n_read = doc.len();
    let moved: HashSet<(EntityId, u32)> = before.iter().map(|f| (f.face, f.occurrence)).collect();
    // PAIR's two instances (one copy, whose nested instances place PART again); then
    // PART's four instances, all moving (three copies).
    assert_eq!(doc.unshare_subfigures(&moved).unwrap(), 4);
    assert!(doc.len() > n_read);
    let after = doc.try_faces().unwrap();
    assert_eq!(after.len(), before.len());
    assert_eq!(placed_points(&doc, &after), points, "a placed face moved");
    // No surface serves two placements any more; the faces of the first placement are
    // the original entities.
    let mut by_surface: HashMap<EntityId, usize> = HashMap::new();
    for f in &after {
        *by_surface.entry(f.surface).or_default() += 1;
        assert_eq!(f.occurrence, 0, "face DE {} is still placed more than once", f.face.0);
    }
    assert!(by_surface.values().all(|&n| n == 1));
    assert!(after.iter().filter(|f| f.face.0 as usize <= 2 * n_read).count() >= 7);
    // Written and read again: the same entities, faces and places.
    let again = Document::parse(&doc.write()).unwrap();
    assert_eq!(again.len(), doc.len());
    let faces_again = again.try_faces().unwrap();
    assert_eq!(faces_again, after);
    assert_eq!(placed_points(&again, &faces_again), points);
    // Once unshared, nothing is left to copy.
    let mut again = again;
    assert_eq!(again.unshare_subfigures(&faces_again.iter().map(|f| (f.face, f.occurrence)).collect()).unwrap(), 0);
}

#[test]
fn no_moved_face_no_copy_and_the_file_is_unchanged() {
    for name in ["subfigure.igs", "subfigure_uninstanced.igs", "hull3.igs"] {
        let (bytes, mut doc) = read(name);
        assert_eq!(doc.unshare_subfigures(&HashSet::new()).unwrap(), 0, "{name}");
        assert!(doc.write() == bytes, "{name}");
        // A definition instanced once (or not at all) needs no copy either.
        if name != "subfigure.igs" {
            let all: HashSet<(EntityId, u32)> =
                doc.try_faces().unwrap().iter().map(|f| (f.face, f.occurrence)).collect();
            assert_eq!(doc.unshare_subfigures(&all).unwrap(), 0, "{name}");
            assert!(doc.write() == bytes, "{name}");
        }
    }
}

#[test]
fn placements_that_do_not_move_keep_sharing() {
    // The four placements of PART, in the order `try_faces` lists them: (outer instance,
    // inner instance) = (1, a), (1, b), (2, a), (2, b). Only the first moves.
    let (_, mut doc) = read("subfigure.igs");
    let before = doc.try_faces().unwrap();
    let points = placed_points(&doc, &before);
    let first: HashSet<(EntityId, u32)> = before.iter().filter(|f| f.occurrence == 0).map(|f| (f.face, 0)).collect();
    assert_eq!(first.len(), 7);
    // PAIR for the first outer instance, then PART for its inner instance a: two copies
    // (copying PART first would have carried the unmoved (2, a) along).
    assert_eq!(doc.unshare_subfigures(&first).unwrap(), 2);
    let after = doc.try_faces().unwrap();
    assert_eq!(after.len(), 28);
    assert_eq!(placed_points(&doc, &after), points, "a placed face moved");
    let block = |k: usize| -> HashSet<EntityId> { after[7 * k..7 * k + 7].iter().map(|f| f.surface).collect() };
    let (moved, others) = (block(0), [block(1), block(2), block(3)]);
    assert!(others.iter().all(|o| o.is_disjoint(&moved)), "the moved placement shares a surface");
    // The unmoved placements (1, b) and (2, b) still share the original PART; (2, a)
    // shares it too.
    assert_eq!(others[0], others[1]);
    assert_eq!(others[1], others[2]);
    let again = Document::parse(&doc.write()).unwrap();
    assert_eq!(again.try_faces().unwrap(), after);
}

#[test]
fn a_record_that_does_not_read_leaves_the_document_as_it_was() {
    // A trim (142) of the plate whose model-space curve points past the directory: the
    // faces read (they do not follow it), the copy of the part cannot.
    let text = std::fs::read_to_string(sample("subfigure.igs")).unwrap();
    let bad = text.replacen("142,0,5,0,9,2;   ", "142,0,5,0,9999,2;", 1);
    assert_ne!(bad, text);
    let mut doc = Document::parse(bad.as_bytes()).unwrap();
    let moved: HashSet<(EntityId, u32)> = doc.try_faces().unwrap().iter().map(|f| (f.face, f.occurrence)).collect();
    let err = doc.unshare_subfigures(&moved).unwrap_err();
    assert!(err.to_string().contains("9999"), "{err}");
    assert!(doc.write() == bad.as_bytes(), "the document changed");
}
