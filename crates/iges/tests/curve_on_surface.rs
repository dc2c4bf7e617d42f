//! A trimming curve given only in the surface's parameter space (issue 13: a 142 whose
//! model-space curve is absent): the face converts, and its model-space curve is rebuilt
//! as OCCT does, as the surface along the parameter curve.

use cadmorph_iges::write::DocumentBuilder;
use cadmorph_iges::{Document, EntityId, Status, Units, Value};
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Curve, KnotVector, NurbsCurve, Surface};

/// The sample B-spline surface trimmed by a loop drawn in its parameter space only.
fn trimmed_by_parameter_curve() -> (Document, EntityId, NurbsCurve) {
    let doc = Document::parse(&std::fs::read(cadmorph_testkit::sample("bspline_surface.igs")).unwrap()).unwrap();
    let surface = doc.surface(EntityId(1)).unwrap().surface;
    let (ud, vd) = surface.domain();
    let (u0, u1, v0, v1) = (*ud.start(), *ud.end(), *vd.start(), *vd.end());
    // A closed quadratic loop inside the domain (a rounded quadrilateral).
    let at = |a: f64, b: f64| Point3::new(u0 + a * (u1 - u0), v0 + b * (v1 - v0), 0.0);
    let poles = vec![at(0.2, 0.2), at(0.8, 0.1), at(0.9, 0.8), at(0.3, 0.9), at(0.2, 0.2)];
    let knots = KnotVector::try_new(vec![0.0, 0.0, 0.0, 0.3, 0.6, 1.0, 1.0, 1.0]).unwrap();
    let p = NurbsCurve::try_new(2, knots, poles, None).unwrap();
    let mut b = DocumentBuilder::new(Units::Millimetre);
    let s = b.add_surface(&surface);
    let pc = b.add_curve(&p);
    let dependent = Status { subordinate: 1, ..Status::default() };
    b.set_status(s, dependent);
    b.set_status(pc, dependent);
    // 142: CRTN, SPTR, BPTR, CPTR (0: no model-space curve), PREF (1: parameter space).
    let cos = b.add_entity(
        0,
        dependent,
        vec![
            Value::Integer(142),
            Value::Integer(0),
            Value::Integer(s.0 as i64),
            Value::Integer(pc.0 as i64),
            Value::Integer(0),
            Value::Integer(1),
        ],
    );
    let face = b.add_entity(
        0,
        Status::default(),
        vec![
            Value::Integer(144),
            Value::Integer(s.0 as i64),
            Value::Integer(1),
            Value::Integer(0),
            Value::Integer(cos.0 as i64),
        ],
    );
    let _ = face;
    (b.build(), cos, p)
}

#[test]
fn repro_curve_on_surface_without_model_space_curve_is_rebuilt_on_the_surface() {
    let (doc, cos, p) = trimmed_by_parameter_curve();
    let surface = doc.surface(EntityId(1)).unwrap().surface;
    let pieces = doc.curve(cos).expect("the 142 converts");
    let size = surface.control_extent();
    let mut worst = 0.0f64;
    for c in &pieces {
        let d = c.domain();
        for i in 0..=200 {
            let t = d.start() + (d.end() - d.start()) * i as f64 / 200.0;
            // The rebuilt curve and the parameter curve share their parameter.
            let q = p.eval(t);
            let on = surface.eval(q.x, q.y);
            worst = worst.max((c.eval(t) - on).norm());
        }
    }
    assert!(worst <= 1e-8 * size, "rebuilt curve off the surface by {worst:e} (size {size:e})");
    // The face is not skipped.
    let faces = doc.faces();
    assert_eq!(faces.len(), 1);
}
