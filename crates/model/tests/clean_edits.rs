//! A morph leaves no dead instances in a STEP file: the old edge curves, the old control
//! points of rewritten surfaces and the placements of analytic surfaces that became
//! B-splines are gone; every instance the input had that is still used, and every root
//! the input had (products, contexts), is still there.

use std::collections::{BTreeMap, BTreeSet};

use cadmorph_model::{CadDocument, Model, MorphOptions};
use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::Ffd;
use cadmorph_testkit::sample;

/// `id -> referenced ids` of every instance of a STEP file.
fn graph(bytes: &[u8]) -> BTreeMap<u64, Vec<u64>> {
    let doc = cadmorph_step::Document::parse(bytes).unwrap();
    doc.instances()
        .map(|i| {
            let text = String::from_utf8_lossy(i.text()).into_owned();
            // The references: every `#n` after the `=`.
            let body = &text[text.find('=').unwrap()..];
            let refs = body
                .split('#')
                .skip(1)
                .filter_map(|s| s.chars().take_while(char::is_ascii_digit).collect::<String>().parse().ok())
                .collect();
            (i.id().0, refs)
        })
        .collect()
}

fn unreferenced(g: &BTreeMap<u64, Vec<u64>>) -> BTreeSet<u64> {
    let used: BTreeSet<u64> = g.values().flatten().copied().collect();
    g.keys().copied().filter(|k| !used.contains(k)).collect()
}

/// A 3x3x3 FFD around the mixed solid, its centre node moved 5 % of the diagonal.
fn bump() -> Ffd {
    let mut f =
        Ffd::try_new([3, 3, 3], Point3::new(-35.0, -25.0, -10.0), Vector3::new(70.0, 50.0, 40.0), Vector3::zeros())
            .unwrap();
    f.mu_mut().set(1, 1, 1, [0.0322, 0.0451, 0.0564]);
    f
}

#[test]
fn a_morphed_step_file_carries_no_orphans_and_keeps_everything_else() {
    let bytes = std::fs::read(sample("mixed_solid.stp")).unwrap();
    let before = graph(&bytes);
    let doc: Box<dyn CadDocument> = Box::new(cadmorph_step::Document::parse(&bytes).unwrap());
    let mut m = Model::new(doc).unwrap();
    let out = m.morph(&bump(), &MorphOptions::default()).unwrap();
    assert!(out.faces_rewritten > 0 && out.curves_rewritten > 0);
    let written = m.to_bytes();
    let after = graph(&written);
    // No new roots: what nothing references in the output, nothing referenced in the input.
    let roots_before = unreferenced(&before);
    let roots_after = unreferenced(&after);
    assert!(roots_after.is_subset(&roots_before), "orphans left: {:?}", roots_after.difference(&roots_before));
    // The input's roots are all kept.
    assert_eq!(roots_after, roots_before);
    // Every input instance still reachable from the roots in the output is kept with its
    // id, and the ones removed are exactly those the output no longer reaches.
    let reach = |g: &BTreeMap<u64, Vec<u64>>, from: &BTreeSet<u64>| {
        let mut seen = BTreeSet::new();
        let mut work: Vec<u64> = from.iter().copied().collect();
        while let Some(k) = work.pop() {
            if seen.insert(k) {
                work.extend(g.get(&k).into_iter().flatten().copied());
            }
        }
        seen
    };
    let reached = reach(&after, &roots_after);
    assert_eq!(reached.len(), after.len(), "everything written is reachable");
    let removed: BTreeSet<u64> = before.keys().copied().filter(|k| !after.contains_key(k)).collect();
    assert!(!removed.is_empty(), "the morph replaced curves and planes: their old instances go");
    // The 8 planes and the cylinder became B-splines: their placements went with them,
    // and the edges' LINE / CIRCLE / ELLIPSE curves were replaced by traced B-splines.
    let names = |b: &[u8]| -> BTreeMap<String, usize> {
        cadmorph_step::Document::parse(b).unwrap().entity_counts().into_iter().collect()
    };
    let (nb, na) = (names(&bytes), names(&written));
    println!("before {nb:?}\nafter {na:?}\nremoved {}", removed.len());
    for gone in ["PLANE", "CYLINDRICAL_SURFACE", "CIRCLE", "ELLIPSE", "SEAM_CURVE"] {
        assert_eq!(na.get(gone), None, "{gone}");
    }
    // The lines left are pcurves of the B-spline faces (kept: their parameters hold),
    // at most one per pcurve; the 3D lines of the edges were all replaced.
    assert!(na["LINE"] < nb["LINE"] && na["LINE"] <= na["PCURVE"], "{} lines", na["LINE"]);
    assert_eq!(na.get("ADVANCED_FACE"), nb.get("ADVANCED_FACE"));
    assert_eq!(na.get("EDGE_CURVE"), nb.get("EDGE_CURVE"));
    assert_eq!(na.get("VERTEX_POINT"), nb.get("VERTEX_POINT"));
    // And it reads back as the same model.
    let back = cadmorph_step::Document::parse(&written).unwrap();
    let m2 = Model::new(Box::new(back) as Box<dyn CadDocument>).unwrap();
    assert_eq!(m2.patches().len(), m.patches().len());
    assert_eq!(m2.seams(50).edges.len(), m.seams(50).edges.len());
}

#[test]
fn an_unedited_step_file_is_written_byte_for_byte() {
    let bytes = std::fs::read(sample("mixed_solid.stp")).unwrap();
    let doc: Box<dyn CadDocument> = Box::new(cadmorph_step::Document::parse(&bytes).unwrap());
    let mut m = Model::new(doc).unwrap();
    m.morph(&cadmorph_morph::Affine::identity(), &MorphOptions::default()).unwrap();
    assert_eq!(m.to_bytes(), bytes);
}
