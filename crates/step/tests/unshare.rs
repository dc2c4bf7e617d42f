//! Repeated parts given their own copies (`Document::unshare`): the placed faces stay the
//! same faces at the same places, in the same order, and the placements that move no
//! longer share a surface with any other placement.

use std::collections::{HashMap, HashSet};

use cadmorph_nurbs::Surface;
use cadmorph_step::{Document, EntityId, Face};

fn load(name: &str) -> Document {
    Document::parse(&std::fs::read(cadmorph_testkit::sample(name)).unwrap()).unwrap()
}

/// World points of every placed face on a 5×5 grid of its domain, in face order.
fn world_points(doc: &Document) -> Vec<[f64; 3]> {
    let faces = doc.faces().unwrap();
    let mut out = Vec::new();
    for f in &faces {
        let w = doc.face_nurbs(f).unwrap();
        let (u, v) = w.surface.domain();
        let (u0, u1, v0, v1) = (*u.start(), *u.end(), *v.start(), *v.end());
        for i in 0..5 {
            for j in 0..5 {
                let p = w.surface.eval(u0 + (u1 - u0) * i as f64 / 4.0, v0 + (v1 - v0) * j as f64 / 4.0);
                out.push([p.x, p.y, p.z]);
            }
        }
    }
    out
}

fn placed(faces: &[Face]) -> Vec<(EntityId, usize)> {
    faces.iter().map(|f| (f.id, f.occurrence)).collect()
}

/// Surfaces used by faces at two different placements (transforms).
fn shared_surfaces(faces: &[Face], only: impl Fn(usize) -> bool) -> usize {
    let mut users: HashMap<u64, Vec<usize>> = HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        users.entry(f.surface.0).or_default().push(i);
    }
    users
        .values()
        .filter(|us| us.iter().any(|&i| only(i)) && us.iter().any(|&i| faces[i].transform != faces[us[0]].transform))
        .count()
}

fn check_all_moved(name: &str, faces_expected: usize) {
    let mut doc = load(name);
    let before = doc.faces().unwrap();
    assert_eq!(before.len(), faces_expected, "{name}");
    assert!(shared_surfaces(&before, |_| true) > 0, "{name}: the sample repeats a part");
    let points = world_points(&doc);
    let moved: HashSet<_> = placed(&before).into_iter().collect();
    let copies = doc.unshare(&moved).unwrap();
    assert!(copies > 0, "{name}");
    let after = doc.faces().unwrap();
    assert_eq!(after.len(), before.len(), "{name}");
    for (a, b) in before.iter().zip(&after) {
        assert_eq!(a.transform, b.transform, "{name}: face {} placed elsewhere", a.id);
        assert_eq!(a.kind, b.kind, "{name}");
    }
    assert_eq!(world_points(&doc), points, "{name}: the copies are the same faces at the same places");
    assert_eq!(shared_surfaces(&after, |_| true), 0, "{name}: a surface still serves two placements");
    // What is written reads back as the same faces; a second pass has nothing to copy.
    let mut again = Document::parse(&doc.write()).unwrap();
    assert_eq!(placed(&again.faces().unwrap()), placed(&after), "{name}");
    assert_eq!(world_points(&again), points, "{name}");
    let all: HashSet<_> = placed(&after).into_iter().collect();
    assert_eq!(again.unshare(&all).unwrap(), 0, "{name}");
}

#[test]
fn every_placement_of_a_moved_part_gets_its_own_copy() {
    check_all_moved("assembly_ap214.stp", 30);
    check_all_moved("assembly_ap203.stp", 30);
    check_all_moved("assembly_catia.stp", 30);
    check_all_moved("assembly_colors.stp", 30);
    check_all_moved("mapped_item.stp", 35);
    check_all_moved("mapped_item_root.stp", 42);
}

#[test]
fn placements_that_move_nothing_keep_sharing_and_nothing_moved_changes_nothing() {
    let mut doc = load("assembly_ap214.stp");
    let bytes = doc.write();
    assert_eq!(doc.unshare(&HashSet::new()).unwrap(), 0);
    assert_eq!(doc.write(), bytes, "no copy, no change");
    // Move only the second placement of the first repeated face.
    let before = doc.faces().unwrap();
    let twice = before.iter().find(|f| f.occurrence == 1).unwrap().clone();
    let moved = HashSet::from([(twice.id, 1)]);
    assert_eq!(doc.unshare(&moved).unwrap(), 1);
    let after = doc.faces().unwrap();
    // The moved placement's faces have new ids; the others are the file's.
    let changed: Vec<usize> = (0..before.len()).filter(|&i| before[i].id != after[i].id).collect();
    assert!(!changed.is_empty());
    let moved_at = before.iter().position(|f| f.id == twice.id && f.occurrence == 1).unwrap();
    assert!(changed.contains(&moved_at));
    assert_eq!(shared_surfaces(&after, |i| changed.contains(&i)), 0);
    // Every face of the copied placement is a copy; other placements keep their ids.
    let unchanged = before.len() - changed.len();
    assert!(unchanged > 0 && changed.iter().all(|&i| after[i].transform == before[i].transform));
}

#[test]
fn a_broken_occurrence_is_an_error_naming_it_and_changes_nothing() {
    // The second plate's PRODUCT_DEFINITION_SHAPE no longer names its occurrence: the
    // copy cannot be given to the occurrence, so nothing is copied.
    let text = std::fs::read_to_string(cadmorph_testkit::sample("assembly_ap214.stp")).unwrap();
    let old = "#479 = PRODUCT_DEFINITION_SHAPE('Placement','Placement of an item',#480";
    assert!(text.contains(old));
    let bad = text.replace(old, "#479 = PRODUCT_DEFINITION_SHAPE('Placement','Placement of an item',$");
    let mut doc = Document::parse(bad.as_bytes()).unwrap();
    let moved: HashSet<_> = placed(&doc.faces().unwrap()).into_iter().collect();
    let e = doc.unshare(&moved).unwrap_err().to_string();
    assert!(e.contains("#479") && e.contains("assembly usage occurrence"), "{e}");
    assert_eq!(doc.write(), bad.as_bytes(), "nothing changed");
}
