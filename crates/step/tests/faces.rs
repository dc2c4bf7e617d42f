//! What `Document::faces` says of each face's surface agrees with the surface
//! `Document::face_nurbs` builds, although the face list reads B-spline surfaces only up
//! to their control points' references.

#[path = "../benches/generate.rs"]
mod generate;

use cadmorph_step::{Document, SurfaceKind};

/// Every sample and the generated large files.
fn documents() -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = cadmorph_testkit::samples_with_suffix(".stp")
        .into_iter()
        .map(|n| (n.clone(), std::fs::read(cadmorph_testkit::sample(&n)).unwrap()))
        .collect();
    out.push(("hull3_200x150".into(), generate::hull3()));
    out.push(("faces300".into(), generate::faces300()));
    out
}

#[test]
fn bspline_kinds_are_those_of_the_converted_surfaces() {
    let mut checked = 0;
    for (name, bytes) in documents() {
        let doc = Document::parse(&bytes).unwrap();
        let faces = doc.faces().unwrap();
        for (f, world) in faces.iter().zip(doc.faces_nurbs(&faces)) {
            let SurfaceKind::BSpline { u_degree, v_degree, n_u, n_v, rational } = f.kind else { continue };
            let s = world.unwrap_or_else(|e| panic!("{name}: face {:?}: {e}", f.id)).surface;
            assert_eq!(
                (u_degree, v_degree, n_u, n_v, rational),
                (s.u_degree(), s.v_degree(), s.n_u(), s.n_v(), s.is_rational()),
                "{name}: face {:?}",
                f.id
            );
            checked += 1;
        }
    }
    assert!(checked > 300, "{checked} B-spline faces");
}

#[test]
fn a_control_point_that_is_not_a_point_makes_the_surface_other() {
    let bytes = std::fs::read(cadmorph_testkit::sample("bspline_surface.stp")).unwrap();
    let text = String::from_utf8(bytes).unwrap();
    let point = "#41 = CARTESIAN_POINT('',(20.,15.,5.784095468231));";
    assert!(text.contains(point));
    let broken = text.replace(point, "#41 = DIRECTION('',(0.,0.,1.));");
    let doc = Document::parse(broken.as_bytes()).unwrap();
    let faces = doc.faces().unwrap();
    assert_eq!(faces.len(), 1);
    assert_eq!(faces[0].kind, SurfaceKind::Other("B_SPLINE_SURFACE_WITH_KNOTS".into()));
    let err = doc.face_nurbs(&faces[0]).unwrap_err().to_string();
    assert!(err.contains("#41"), "{err}");
    // The intact file lists it as the bicubic it is.
    let doc = Document::parse(text.as_bytes()).unwrap();
    assert!(matches!(doc.faces().unwrap()[0].kind, SurfaceKind::BSpline { .. }));
}

/// `Document::faces_nurbs` (each face entity converted once, then placed for each of its
/// occurrences) gives exactly `Document::face_nurbs` of every face, assemblies included.
#[test]
fn faces_nurbs_is_face_nurbs_of_each_face() {
    let mut placed = 0;
    for (name, bytes) in documents() {
        let doc = Document::parse(&bytes).unwrap();
        let faces = doc.faces().unwrap();
        for (f, w) in faces.iter().zip(doc.faces_nurbs(&faces)) {
            assert_eq!(w, doc.face_nurbs(f), "{name}: face {:?} occurrence {}", f.id, f.occurrence);
            placed += usize::from(f.occurrence > 0);
        }
    }
    assert!(placed > 20, "{placed} faces placed more than once");
}
