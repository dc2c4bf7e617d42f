//! Faces closed in u measure their own closing seam: the blade samples report it (closed
//! exactly: a clamped closed surface's first and last pole rows coincide), and a blade
//! whose closing seam was opened by 1 mm is caught with that gap; the seam survives a
//! written and re-read file.

use cadmorph_model::{CadDocument, Model};
use cadmorph_nurbs::{NurbsSurface, Side};
use cadmorph_seam::EdgeReport;
use cadmorph_testkit::sample;

fn open(name: &str) -> Model {
    let bytes = std::fs::read(sample(name)).unwrap();
    let doc: Box<dyn CadDocument> = if name.ends_with(".stp") {
        Box::new(cadmorph_step::Document::parse(&bytes).unwrap())
    } else {
        Box::new(cadmorph_iges::Document::parse(&bytes).unwrap())
    };
    Model::new(doc).unwrap()
}

fn closing(edges: &[EdgeReport]) -> &EdgeReport {
    let mut it = edges.iter().filter(|e| e.a.patch == e.b.patch);
    let e = it.next().expect("a closing seam");
    assert!(it.next().is_none(), "one closing seam");
    assert_eq!((e.a.side, e.b.side), (Some(Side::UMin), Some(Side::UMax)));
    e
}

/// Largest distance between the first and the last u row of poles: the closing seam's
/// gap, exactly, for a surface clamped in u.
fn row_gap(s: &NurbsSurface) -> f64 {
    (0..s.n_v()).map(|j| (s.control_point(0, j) - s.control_point(s.n_u() - 1, j)).norm()).fold(0.0, f64::max)
}

#[test]
fn the_blades_report_their_closing_seam() {
    for name in ["blade.igs", "blade.stp"] {
        let m = open(name);
        let r = m.seams(200);
        assert_eq!(r.edges.len(), 1, "{name}:\n{}", r.table());
        let e = closing(&r.edges);
        let s = &m.patches()[0].surface;
        assert_eq!(row_gap(s), 0.0, "{name}");
        assert!(e.gap_matched.max <= 1e-12 && e.gap_closest.max <= 1e-12, "{name}:\n{}", r.table());
        // The closing seam is the trailing edge, a crease: the sections' wedge angle.
        assert!(e.sharp && e.g1_angle_unoriented_deg.max > 10.0 && e.g1_angle_unoriented_deg.max < 30.0, "{name}");
        // Its length is the blade's span along the trailing edge (sections at z 0.25 .. 1 m).
        assert!(e.length > 0.75 && e.length < 0.9, "{name}: {}", e.length);
    }
}

#[test]
fn a_blade_with_a_1_mm_gap_in_its_closing_seam_is_caught() {
    for name in ["blade.igs", "blade.stp"] {
        let mut m = open(name);
        let mut s = m.patches()[0].surface.clone();
        // Open the seam: the last row of poles (the u_max boundary, exactly, for a clamped
        // surface) moves 1 mm chordwise, away from the first.
        let (nu, nv) = (s.n_u(), s.n_v());
        for j in 0..nv {
            s.control_points_mut()[(nu - 1) * nv + j].x += 1e-3;
        }
        assert!((row_gap(&s) - 1e-3).abs() < 1e-12);
        m.set_patch_surface(0, s).unwrap();
        // Measured in memory and in the written file read back.
        for (what, r) in [("memory", m.seams(200)), ("file", m.verify().unwrap().seams)] {
            let e = closing(&r.edges);
            assert!((e.gap_matched.max - 1e-3).abs() < 1e-9, "{name}, {what}:\n{}", r.table());
            assert!(e.gap_closest.max > 0.5e-3 && e.gap_closest.max <= 1e-3 + 1e-9, "{name}, {what}:\n{}", r.table());
            assert!((r.max_gap_matched - 1e-3).abs() < 1e-9);
        }
    }
}
