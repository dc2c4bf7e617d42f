//! One test body per property, run over both formats (nalgebra's `gen_tests!` style):
//! each body is generic over the document type, and the macro instantiates it for
//! `cadmorph_iges::Document` on the `.igs` samples and `cadmorph_step::Document` on the
//! `.stp` ones. The model names no format, so the same body must hold for both.

use cadmorph_model::{Model, MorphOptions, ReadDocument};
use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::{from_fn, Affine, Deformation, Ffd};
use cadmorph_nurbs::{Curve, Surface};
use cadmorph_seam::SeamRefineOptions;
use cadmorph_testkit::sample;

fn open<D: ReadDocument>(name: &str) -> Model<D> {
    Model::<D>::open(&sample(name)).unwrap()
}

/// The model of what `m` wrote, read back by the format's own reader.
fn reread<D: ReadDocument>(m: &Model<D>) -> Model<D> {
    Model::<D>::from_bytes(&m.to_bytes()).unwrap()
}

/// A smooth non-affine law over the model's box: a bulge of 1 % of the model size that
/// grows along x and bends in y and z.
fn bulge<D: cadmorph_model::CadDocument>(m: &Model<D>) -> impl Deformation {
    let b = cadmorph_nurbs::Aabb::from_points(m.patches().iter().flat_map(|p| p.surface.control_points())).unwrap();
    let (lo, ext, size) = (b.min, (b.max - b.min).map(|e| e.max(1e-9)), m.size());
    from_fn(move |p: &Point3<f64>| {
        let q = (p - lo).component_div(&ext);
        let s = (std::f64::consts::PI * q.x).sin();
        p + 0.01 * size * Vector3::new(0.3 * s * q.y, s * (0.5 + q.y * q.y), s * q.z * q.z + 0.2 * q.x * q.x)
    })
}

/// Largest distance from 17 points over `b.range` of each bound curve to the patch of
/// face `face_of(b)`, by projections started from the previous point's answer.
fn curve_to_face_gap<D: cadmorph_model::CadDocument>(
    m: &Model<D>,
    which: impl Fn(usize, &cadmorph_brep::BoundCurve) -> Vec<usize>,
) -> (f64, usize) {
    let size = m.size();
    let (mut worst, mut n) = (0.0f64, 0);
    for (k, b) in m.bound_curves().iter().enumerate() {
        for face in which(k, b) {
            let s = &m.patches()[face].surface;
            let mut near = None;
            n += 1;
            for i in 0..=16 {
                let t = b.range.0 + (b.range.1 - b.range.0) * i as f64 / 16.0;
                let p = b.curve.eval(t);
                let pr = s.project_near(&p, near, 1e-13 * size, 1e-6 * size);
                near = Some((pr.u, pr.v));
                worst = worst.max(pr.distance_sq.sqrt());
            }
        }
    }
    (worst, n)
}

/// A morph that moves nothing rewrites nothing: the document is the input, byte for byte.
fn identity_morph_is_byte_identical<D: ReadDocument>(ext: &str) {
    for name in ["hull3", "hull3_defect", "mixed_solid", "blade", "bspline_surface", "nurbs_cylinder"] {
        let file = format!("{name}.{ext}");
        let bytes = std::fs::read(sample(&file)).unwrap();
        let mut m = Model::<D>::from_bytes(&bytes).unwrap();
        let o = m.morph(&Affine::identity(), &MorphOptions::default()).unwrap();
        assert_eq!((o.faces_rewritten, o.curves_rewritten), (0, 0), "{file}");
        assert!(m.to_bytes() == bytes, "{file} changed under the identity");
    }
}

/// After a non-affine morph, every edge (bound curve) of the written file lies within
/// `1e-7 ×` the model size of its morphed faces: of both faces where the edge is an
/// iso-boundary with the faces' knots (hull, blade, cylinder), and of the face it was
/// traced on for the solid's trims and B-rep edges.
fn edges_stay_on_their_morphed_faces<D: ReadDocument>(ext: &str) {
    for name in ["hull3", "blade", "nurbs_cylinder"] {
        let file = format!("{name}.{ext}");
        let mut m = open::<D>(&file);
        let law = bulge(&m);
        m.morph(&law, &MorphOptions::default()).unwrap();
        let back = reread(&m);
        let faces_of = |_: usize, b: &cadmorph_brep::BoundCurve| {
            back.bound_curves().iter().filter(|c| c.edge.is_some() && c.edge == b.edge).map(|c| c.face).collect()
        };
        let (gap, n) = curve_to_face_gap(&back, faces_of);
        assert!(gap <= 1e-7 * back.size(), "{file}: {n} edge-face pairs, worst {gap:e}");
    }
    // The solid: trims and B-rep edges of planes, cylinders, a cone and a loft, each
    // curve on the face it was traced on (its other face is the seam, which the
    // refinement tests hold).
    let solid = format!("mixed_solid.{ext}");
    let mut m = open::<D>(&solid);
    let law = bulge(&m);
    let moved = m.morph(&law, &MorphOptions::default()).unwrap();
    assert!(moved.curves_rewritten > 0, "{solid}");
    let back = reread(&m);
    let first = |k: usize, b: &cadmorph_brep::BoundCurve| {
        let first = back.bound_curves().iter().position(|c| c.target.is_some() && c.target == b.target);
        if first == Some(k) || b.target.is_none() {
            vec![b.face]
        } else {
            vec![]
        }
    };
    let (gap, n) = curve_to_face_gap(&back, first);
    assert!(n > 0);
    assert!(gap <= 1e-7 * back.size(), "{solid}: {n} curves, worst {gap:e}");
}

/// A surface set on a patch is what the patch then holds, in memory and in the file
/// read back, and the face's bound curves are traced onto it.
fn set_then_get_face_surface<D: ReadDocument>(ext: &str) {
    for name in ["hull3", "mixed_solid"] {
        let file = format!("{name}.{ext}");
        let mut m = open::<D>(&file);
        let size = m.size();
        // The largest B-spline face, pushed out along a smooth non-affine field.
        let i = (0..m.patches().len())
            .filter(|&i| !m.patches()[i].kind.is_analytic())
            .max_by_key(|&i| m.patches()[i].surface.control_points().len())
            .unwrap();
        let law = bulge(&m);
        let mut s = m.patches()[i].surface.clone();
        law.deform(s.control_points_mut());
        m.set_patch_surface(i, s.clone()).unwrap();
        assert_eq!(m.patches()[i].surface, s, "{file}: in memory");
        let back = reread(&m);
        let got = &back.patches()[i].surface;
        assert_eq!(got.control_points().len(), s.control_points().len(), "{file}");
        let dev = got.control_points().iter().zip(s.control_points()).map(|(p, q)| (p - q).norm()).fold(0.0, f64::max);
        assert!(dev <= 1e-9 * size, "{file}: read back {dev:e} away");
        assert!(m.verify().unwrap().max_deviation <= 1e-9 * size, "{file}");
        let on_face = |_: usize, b: &cadmorph_brep::BoundCurve| if b.face == i { vec![i] } else { vec![] };
        let (gap, _) = curve_to_face_gap(&back, on_face);
        assert!(gap <= 1e-7 * size, "{file}: a bound curve is {gap:e} off the new surface");
        for (u, v) in cadmorph_testkit::grid(&s, 5) {
            assert!((got.eval(u, v) - s.eval(u, v)).norm() <= 1e-9 * size, "{file}");
        }
    }
}

macro_rules! gen_tests {
    ($($module:ident: $doc:ty, $ext:literal;)*) => {$(
        mod $module {
            #[test]
            fn identity_morph_is_byte_identical() {
                super::identity_morph_is_byte_identical::<$doc>($ext)
            }
            #[test]
            fn edges_stay_on_their_morphed_faces() {
                super::edges_stay_on_their_morphed_faces::<$doc>($ext)
            }
            #[test]
            fn set_then_get_face_surface() {
                super::set_then_get_face_surface::<$doc>($ext)
            }
        }
    )*};
}

gen_tests! {
    iges: cadmorph_iges::Document, "igs";
    step: cadmorph_step::Document, "stp";
}

/// The hull in both formats has the same seams, before and after the bow-dome morph
/// with seam refinement, as the two files describe the same three patches.
#[test]
fn hull_seams_agree_between_iges_and_step() {
    let ffd = Ffd::from_prm(&std::fs::read_to_string(sample("prm/bow_dome.prm")).unwrap()).unwrap();
    let opts = MorphOptions { refine: Some(SeamRefineOptions::new(1.45e-5, 0.01)), ..Default::default() };
    let mut igs = open::<cadmorph_iges::Document>("hull3.igs");
    let mut stp = open::<cadmorph_step::Document>("hull3.stp");
    let compare = |a: &cadmorph_seam::SeamReport, b: &cadmorph_seam::SeamReport, when: &str| {
        assert_eq!(a.edges.len(), b.edges.len(), "{when}");
        for (x, y) in a.edges.iter().zip(&b.edges) {
            assert_eq!((x.a.patch, x.b.patch), (y.a.patch, y.b.patch), "{when}");
            assert!((x.length - y.length).abs() <= 1e-9 * x.length, "{when}: length {} vs {}", x.length, y.length);
            assert!((x.gap_closest.max - y.gap_closest.max).abs() <= 1e-9, "{when}: gap");
            assert!(
                (x.g1_angle_deg.max - y.g1_angle_deg.max).abs() <= 1e-6,
                "{when}: {} vs {}",
                x.g1_angle_deg.max,
                y.g1_angle_deg.max
            );
        }
    };
    compare(&igs.seams(200), &stp.seams(200), "before");
    let a = igs.morph(&ffd, &opts).unwrap();
    let b = stp.morph(&ffd, &opts).unwrap();
    compare(&a.seams_before, &b.seams_before, "before the morph");
    compare(&a.seams_after, &b.seams_after, "after the morph");
    compare(&igs.verify().unwrap().seams, &stp.verify().unwrap().seams, "after, read back");
    assert_eq!(a.control_points_after, b.control_points_after);
    assert_eq!(a.faces_rewritten, b.faces_rewritten);
}
