//! A trimming curve given only in the surface's parameter space (issue 13: a 142 whose
//! model-space curve is absent): the face converts, and its model-space curve is rebuilt
//! as OCCT does, as the surface along the parameter curve.

use cadmorph_iges::write::DocumentBuilder;
use cadmorph_iges::{Document, EntityId, Status, Units, Value};
use cadmorph_nurbs::math::Point3;
use cadmorph_nurbs::{Curve, CurveProject, KnotVector, NurbsCurve, Surface};

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

/// `text` with every one-line 142 record's model-space curve pointer set to 0 (and its
/// preference to the parameter curve), padded to the record's columns; the 142 DEs.
fn without_model_curves(text: &str) -> (String, Vec<EntityId>) {
    let mut ids = Vec::new();
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            let data = line.get(..64).unwrap_or("");
            if line.len() >= 73 && &line[72..73] == "P" && data.starts_with("142,") && data.trim_end().ends_with(';') {
                let f: Vec<&str> = data.trim_end().trim_end_matches(';').split(',').collect();
                if f.len() == 6 && f[3] != "0" && f[4] != "0" {
                    ids.push(EntityId(line[64..72].trim().parse().unwrap()));
                    let new = format!("142,{},{},{},0,1;", f[1], f[2], f[3]);
                    return format!("{new:<64}{}", &line[64..]);
                }
            }
            line.to_owned()
        })
        .collect();
    (lines.join("\n") + "\n", ids)
}

/// The 142 trims of PyGeM's pipes and the shaft lie on 120 surfaces of revolution (and
/// planes); rebuilt from their parameter curves alone, through the 120's IGES parameter
/// space (generatrix t, angle θ, §4.18), they are the files' own model-space curves.
#[test]
fn parameter_curves_on_revolutions_rebuild_the_model_curves() {
    let pygem = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/pygem-testdata");
    let mut compared = 0;
    for path in [
        pygem.join("test_pipe.igs"),
        pygem.join("test_pipe.iges"),
        pygem.join("test_pipe_hollow.iges"),
        cadmorph_testkit::sample("shaft.igs"),
    ] {
        let text = std::fs::read_to_string(&path).unwrap().replace("\r\n", "\n");
        let original = Document::parse(text.as_bytes()).unwrap();
        let (changed, ids) = without_model_curves(&text);
        let rebuilt = Document::parse(changed.as_bytes()).unwrap();
        assert!(!ids.is_empty(), "{}", path.display());
        for id in ids {
            let on_revolution = matches!(original.view(id).unwrap(), cadmorph_iges::View::CurveOnSurface(c)
                if original.entity(c.surface).unwrap().entity_type() == 120);
            if !on_revolution {
                continue;
            }
            let (a, b) = (original.curve(id).unwrap(), rebuilt.curve(id).unwrap());
            assert_eq!(a.len(), b.len(), "{} DE {}: pieces", path.display(), id.0);
            let pts: Vec<Point3<f64>> = a.iter().flat_map(|c| c.control_points().iter().copied()).collect();
            let size = pts.iter().map(|p| (p - pts[0]).norm()).fold(0.0, f64::max).max(1e-300);
            // The pieces' parameters differ (arc angle and line length against parameter
            // space lengths): compare each piece's point sets, both ways, by projection.
            let mut worst = 0.0f64;
            for (pa, pb) in a.iter().zip(&b) {
                for (x, y) in [(pa, pb), (pb, pa)] {
                    let d = x.domain();
                    for k in 0..=20 {
                        let p = x.eval(d.start() + f64::from(k) / 20.0 * (d.end() - d.start()));
                        worst = worst.max(y.project(&p, 1e-14 * size).distance_sq.sqrt() / size);
                    }
                }
                let ends = (pa.eval(*pa.domain().start()) - pb.eval(*pb.domain().start())).norm() / size;
                worst = worst.max(ends);
            }
            println!("{} 142 DE {}: {worst:e} of the curve's size", path.display(), id.0);
            assert!(worst <= 1e-6, "{} DE {}: {worst:e}", path.display(), id.0);
            compared += 1;
        }
    }
    assert!(compared >= 12, "{compared}");
}
