//! 104 hyperbola and parabola arcs and 140 offset surfaces: closed forms, and OCCT's
//! reading of the same entities (`#[ignore]`d without the OCCT venv).
//!
//! The sample `tests/data/conics_offset.igs` is written by [`build`] (regenerate with
//! `CADMORPH_REGEN_SAMPLES=1 cargo test -p cadmorph-iges --test conic_offset`):
//!
//! | DE | entity |
//! | --- | --- |
//! | 1 | 104 form 2: `x² − 4y² − 4 = 0`, `z = 0.5`, from `(4.25, −1.875)` to `(2.5, 0.75)` |
//! | 3 | 104 form 3: `y² − 4x = 0`, `z = 0`, from `(4, −4)` to `(2.25, 3)` |
//! | 5 | 124 rotation by 30° about `(1, 2, 2)/3` and translation `(1, −2, 3)` |
//! | 7 | 104 form 2 as DE 1, under the 124 of DE 5 |
//! | 9 | 104 form 3: `y² + 2y − 8x + 17 = 0` (vertex `(2, −1)`), from `(4, 3)` to `(2.5, −3)` |
//! | 11 | 128 (dependent): a sphere patch of radius 2, 90° × 60°, rational biquadratic |
//! | 13 | 140: the patch offset by 0.5 |
//! | 15 | 128 (dependent): a bicubic polynomial bump, 2 × 2 spans |
//! | 17 | 140: the bump offset by −0.3 |
//! | 19, 21 | 116, 123 (dependent): centre `(1, 1, 1)` and axis `(0, 0.6, 0.8)` of the torus |
//! | 23 | 198 (dependent): torus of radii 3 and 1 |
//! | 25 | 140: the torus offset by 0.25 |
//!
//! (OCCT does not make a face of a 140 over a whole 196 sphere: `BRepLib_MakeFace` fails on
//! the offset's poles, so the sphere's exact offset is checked against its closed form
//! only, in a separate document, [`sphere_doc`].)

use std::f64::consts::{FRAC_PI_2, FRAC_PI_3};

use cadmorph_iges::write::DocumentBuilder;
use cadmorph_iges::{Document, EntityId, Status, Units, Value, View};
use cadmorph_nurbs::analytic::{AnalyticSurface, Placement, Sphere};
use cadmorph_nurbs::{Curve, CurveProject, KnotVector, NurbsSurface, Surface};
use nalgebra::{Matrix4, Point3, Rotation3, Unit, Vector3};

const SAMPLE: &str = "tests/data/conics_offset.igs";

/// The hyperbola `x² − 4y² − 4 = 0`.
const HYPERBOLA: [f64; 6] = [1.0, 0.0, -4.0, 0.0, 0.0, -4.0];
/// The parabola `y² − 4x = 0`.
const PARABOLA: [f64; 6] = [0.0, 0.0, 1.0, -4.0, 0.0, 0.0];
/// The parabola `(y + 1)² = 8 (x − 2)`.
const SHIFTED_PARABOLA: [f64; 6] = [0.0, 0.0, 1.0, -8.0, 2.0, 17.0];

fn reals(xs: &[f64]) -> Vec<Value> {
    xs.iter().map(|&x| Value::Real(x)).collect()
}

fn conic(k: [f64; 6], z: f64, start: [f64; 2], end: [f64; 2]) -> Vec<Value> {
    let mut v = vec![Value::Integer(104)];
    v.extend(reals(&k));
    v.extend(reals(&[z, start[0], start[1], end[0], end[1]]));
    v
}

/// The 124 of the sample.
fn matrix() -> Matrix4<f64> {
    let axis = Unit::new_normalize(Vector3::new(1.0, 2.0, 2.0));
    let mut m = Rotation3::from_axis_angle(&axis, 30f64.to_radians()).to_homogeneous();
    m[(0, 3)] = 1.0;
    m[(1, 3)] = -2.0;
    m[(2, 3)] = 3.0;
    m
}

fn sphere_patch() -> NurbsSurface {
    let s = Sphere::try_new(Placement::standard(), 2.0).unwrap();
    s.to_nurbs(0.0..=FRAC_PI_2, 0.0..=FRAC_PI_3).unwrap().surface
}

fn bump() -> NurbsSurface {
    let k = KnotVector::try_new(vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0]).unwrap();
    let mut pts = Vec::new();
    for i in 0..5 {
        for j in 0..5 {
            let (x, y) = (i as f64, j as f64);
            let z = if (1..4).contains(&i) && (1..4).contains(&j) { 1.0 + 0.25 * (x - y) } else { 0.0 };
            pts.push(Point3::new(x, y, z));
        }
    }
    NurbsSurface::try_new((3, 3), (k.clone(), k), (5, 5), pts, None).unwrap()
}

/// The sample's text: curves, surfaces or both (the DE numbers of the table above are
/// those of both; curves only keeps DE 1–9, surfaces only starts at DE 1).
fn build(curves: bool, surfaces: bool) -> Vec<u8> {
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261122.050000").file_name("conics_offset.igs");
    let dependent = Status { subordinate: 1, ..Status::default() };
    let definition = Status { subordinate: 1, entity_use: 2, ..Status::default() };
    let mut transformed = None;
    if curves {
        b.add_entity(2, Status::default(), conic(HYPERBOLA, 0.5, [4.25, -1.875], [2.5, 0.75]));
        b.add_entity(3, Status::default(), conic(PARABOLA, 0.0, [4.0, -4.0], [2.25, 3.0]));
        let m = matrix();
        let mut v = vec![Value::Integer(124)];
        for r in 0..3 {
            v.extend(reals(&[m[(r, 0)], m[(r, 1)], m[(r, 2)], m[(r, 3)]]));
        }
        let t = b.add_entity(0, definition, v);
        let h = b.add_entity(2, Status::default(), conic(HYPERBOLA, 0.5, [4.25, -1.875], [2.5, 0.75]));
        transformed = Some((h, t));
        b.add_entity(3, Status::default(), conic(SHIFTED_PARABOLA, -1.0, [4.0, 3.0], [2.5, -3.0]));
    }
    if surfaces {
        let offset = |base: EntityId, d: f64| {
            let mut v = vec![Value::Integer(140)];
            v.extend(reals(&[0.0, 0.0, 0.0, d]));
            v.push(Value::Integer(i64::from(base.0)));
            v
        };
        let s = b.add_surface(&sphere_patch());
        b.set_status(s, dependent);
        b.add_entity(0, Status::default(), offset(s, 0.5));
        let s = b.add_surface(&bump());
        b.set_status(s, dependent);
        b.add_entity(0, Status::default(), offset(s, -0.3));
        let mut v = vec![Value::Integer(116)];
        v.extend(reals(&[1.0, 1.0, 1.0]));
        let c = b.add_entity(0, dependent, v);
        let mut v = vec![Value::Integer(123)];
        v.extend(reals(&[0.0, 0.6, 0.8]));
        let ax = b.add_entity(0, dependent, v);
        let mut v = vec![Value::Integer(198), Value::Integer(i64::from(c.0)), Value::Integer(i64::from(ax.0))];
        v.extend(reals(&[3.0, 1.0]));
        let t = b.add_entity(0, dependent, v);
        b.add_entity(0, Status::default(), offset(t, 0.25));
    }
    let mut bytes = b.to_bytes();
    if let Some((h, t)) = transformed {
        set_transform(&mut bytes, h, t);
    }
    bytes
}

/// A 196 sphere of radius 1.5 about `(1, 1, 1)` (DE 3) and a 140 offsetting it by `d` (DE 5).
fn sphere_doc(d: f64) -> Document {
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261122.050000");
    let dependent = Status { subordinate: 1, ..Status::default() };
    let c = b.add_entity(0, dependent, vec![Value::Integer(116), Value::Real(1.0), Value::Real(1.0), Value::Real(1.0)]);
    let sp = b.add_entity(0, dependent, vec![Value::Integer(196), Value::Integer(i64::from(c.0)), Value::Real(1.5)]);
    let mut v = vec![Value::Integer(140)];
    v.extend(reals(&[0.0, 0.0, 0.0, d]));
    v.push(Value::Integer(i64::from(sp.0)));
    b.add_entity(0, Status::default(), v);
    Document::parse(&b.to_bytes()).unwrap()
}

/// Writes `t` into directory field 7 of entity `id` (columns 49–56 of its first D line).
fn set_transform(bytes: &mut [u8], id: EntityId, t: EntityId) {
    let text = String::from_utf8(bytes.to_vec()).unwrap();
    let mut at = 0;
    for line in text.split_inclusive('\n') {
        if line.len() >= 80 && &line[72..73] == "D" && line[73..80].trim().parse::<u32>() == Ok(id.0) {
            bytes[at + 48..at + 56].copy_from_slice(format!("{:>8}", t.0).as_bytes());
            return;
        }
        at += line.len();
    }
    panic!("no D line for DE {}", id.0);
}

fn sample() -> Document {
    Document::parse(&std::fs::read(SAMPLE).unwrap()).unwrap()
}

#[test]
fn sample_file_is_current() {
    let bytes = build(true, true);
    if std::env::var_os("CADMORPH_REGEN_SAMPLES").is_some() {
        std::fs::create_dir_all("tests/data").unwrap();
        std::fs::write(SAMPLE, &bytes).unwrap();
    }
    assert_eq!(std::fs::read(SAMPLE).unwrap(), bytes, "regenerate with CADMORPH_REGEN_SAMPLES=1");
    let doc = sample();
    assert_eq!(doc.transform(EntityId(7)).unwrap(), matrix());
}

/// `|Q| / |∇Q|` at `(x, y)`: the distance from the conic to first order.
fn conic_distance(k: &[f64; 6], x: f64, y: f64) -> f64 {
    let q = k[0] * x * x + k[1] * x * y + k[2] * y * y + k[3] * x + k[4] * y + k[5];
    let gx = 2.0 * k[0] * x + k[1] * y + k[3];
    let gy = k[1] * x + 2.0 * k[2] * y + k[4];
    q.abs() / gx.hypot(gy)
}

/// Relative deviation of the curve of a 104 from its conic (in definition space, the
/// 124 undone), its plane, and its end points; and the curve's size.
fn conic_errors(doc: &Document, id: EntityId) -> (f64, f64, f64) {
    let View::ConicArc(c) = doc.view(id).unwrap() else { panic!() };
    let curve = doc.curve_joined(id).unwrap();
    let inv = doc.transform(id).unwrap().try_inverse().unwrap();
    let pts = curve.control_points();
    let size = pts.iter().map(|p| (p - pts[0]).norm()).fold(0.0, f64::max);
    let d = curve.domain();
    let mut on = 0.0f64;
    let mut plane = 0.0f64;
    for i in 0..=1000 {
        let t = d.start() + (d.end() - d.start()) * f64::from(i) / 1000.0;
        let p = inv.transform_point(&curve.eval(t));
        on = on.max(conic_distance(&c.coefficients, p.x, p.y) / size);
        plane = plane.max((p.z - c.z).abs() / size);
    }
    let s = inv.transform_point(&curve.eval(*d.start()));
    let e = inv.transform_point(&curve.eval(*d.end()));
    let ends =
        (s - Point3::new(c.start[0], c.start[1], c.z)).norm().max((e - Point3::new(c.end[0], c.end[1], c.z)).norm());
    (on, plane, ends / size)
}

#[test]
fn conic_arcs_lie_on_their_conics() {
    let doc = sample();
    let mut worst = 0.0f64;
    for de in [1, 3, 7, 9] {
        let (on, plane, ends) = conic_errors(&doc, EntityId(de));
        println!("104 DE {de}: conic {on:e}, plane {plane:e}, ends {ends:e}");
        assert!(on <= 1e-12 && plane <= 1e-12 && ends <= 1e-12, "DE {de}: {on:e} {plane:e} {ends:e}");
        worst = worst.max(on).max(plane).max(ends);
        let c = doc.curve_joined(EntityId(de)).unwrap();
        let form = doc.entity(EntityId(de)).unwrap().form();
        // Hyperbolas rational with weights in (1, 1.5], parabolas polynomial.
        match form {
            2 => assert!(c.weights().unwrap().iter().all(|w| (1.0..=1.5).contains(w))),
            _ => assert!(!c.is_rational()),
        }
    }
    println!("worst relative deviation {worst:e}");
}

#[test]
fn conic_arcs_appear_in_info() {
    let doc = sample();
    for de in [1, 3, 7, 9] {
        assert!(doc.curve(EntityId(de)).is_ok());
    }
    // Every face (the three 140s) converts.
    let info = doc.surfaces();
    assert_eq!(info.iter().map(|i| i.entity_type).collect::<Vec<_>>(), vec![140, 140, 140]);
    for i in &info {
        assert!(i.nurbs.is_ok(), "{i:?}");
    }
}

/// Largest deviation from a sphere of radius `r` about `c`, over a grid of the surface.
fn sphere_deviation(s: &NurbsSurface, c: Point3<f64>, r: f64) -> f64 {
    let (ud, vd) = s.domain();
    let mut worst = 0.0f64;
    for i in 0..=50 {
        for j in 0..=50 {
            let u = ud.start() + (ud.end() - ud.start()) * f64::from(i) / 50.0;
            let v = vd.start() + (vd.end() - vd.start()) * f64::from(j) / 50.0;
            worst = worst.max(((s.eval(u, v) - c).norm() - r).abs());
        }
    }
    worst
}

#[test]
fn offsets_match_closed_forms() {
    // 196 sphere offset: exact, a sphere of radius 2.25.
    let doc = sphere_doc(0.75);
    let exact = doc.offset_surface(EntityId(5), None).unwrap();
    assert!(exact.exact);
    let e = sphere_deviation(&exact.surface.surface, Point3::new(1.0, 1.0, 1.0), 2.25);
    println!("196 offset (exact): {e:e}");
    assert!(e <= 1e-14);
    // The same offset approximated from the sphere's exact NURBS agrees within tolerance.
    let base = doc.surface(EntityId(3)).unwrap();
    let fit = cadmorph_iges::convert::offset::approximate_offset(&base.surface, 0.75, 1e-6).unwrap();
    let e = sphere_deviation(&fit.surface, Point3::new(1.0, 1.0, 1.0), 2.25);
    println!("196 offset approximated from its B-spline (poles included): {e:e} (check grid {:e})", fit.max_error);
    assert!(e <= 2e-6);
    // 198 torus offset: exact, minor radius 1.25 about the circle of radius 3.
    let doc = sample();
    let exact = doc.offset_surface(EntityId(25), None).unwrap();
    assert!(exact.exact);
    let (o, z) = (Point3::new(1.0, 1.0, 1.0), Vector3::new(0.0, 0.6, 0.8));
    let s = &exact.surface.surface;
    let (ud, vd) = s.domain();
    let mut e = 0.0f64;
    for i in 0..=40 {
        for j in 0..=40 {
            let u = ud.start() + (ud.end() - ud.start()) * f64::from(i) / 40.0;
            let v = vd.start() + (vd.end() - vd.start()) * f64::from(j) / 40.0;
            let q = s.eval(u, v) - o;
            let h = q.dot(&z);
            let rho = (q - z * h).norm();
            e = e.max(((rho - 3.0).hypot(h) - 1.25).abs());
        }
    }
    println!("198 offset (exact): {e:e}");
    assert!(e <= 1e-14);
    // 128 sphere patch offset: approximated, a sphere of radius 2.5, in the base's parameters.
    let approx = doc.offset_surface(EntityId(13), None).unwrap();
    assert!(!approx.exact);
    let size = cadmorph_iges::convert::offset::size(&sphere_patch());
    assert!(approx.tolerance == 1e-6 * size && approx.max_error <= approx.tolerance);
    let e = sphere_deviation(&approx.surface.surface, Point3::origin(), 2.5);
    println!("128 sphere patch offset: {e:e} (tolerance {:e}, check grid {:e})", approx.tolerance, approx.max_error);
    assert!(e <= approx.tolerance);
    let base = sphere_patch();
    let (u, v) = (0.3, 0.7);
    let p = approx.surface.surface.eval(u, v);
    assert!((p.coords - base.eval(u, v).coords * 1.25).norm() <= approx.tolerance);
    // An explicit tolerance.
    let tight = doc.offset_surface(EntityId(13), Some(1e-9)).unwrap();
    assert!(tight.max_error <= 1e-9 && sphere_deviation(&tight.surface.surface, Point3::origin(), 2.5) <= 1e-9);
}

#[test]
fn offset_of_a_polar_bspline_sphere_and_degenerate_bases() {
    // A full sphere as a B-spline (poles at v = ±π/2): offsets with the limit normal.
    let s = Sphere::try_new(Placement::standard(), 1.0).unwrap();
    let full = s.to_nurbs(0.0..=std::f64::consts::TAU, -FRAC_PI_2..=FRAC_PI_2).unwrap().surface;
    let fit = cadmorph_iges::convert::offset::approximate_offset(&full, 0.5, 1e-6).unwrap();
    let e = sphere_deviation(&fit.surface, Point3::origin(), 1.5);
    println!("full B-spline sphere offset: {e:e}");
    assert!(e <= 2e-6);
    // A patch collapsed to a point has no normal: a clear error naming the 140.
    let k = KnotVector::try_new(vec![0.0, 0.0, 1.0, 1.0]).unwrap();
    let dot = NurbsSurface::try_new((1, 1), (k.clone(), k), (2, 2), vec![Point3::new(1.0, 2.0, 3.0); 4], None).unwrap();
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261122.050000");
    let base = b.add_surface(&dot);
    b.set_status(base, Status { subordinate: 1, ..Status::default() });
    let off = b.add_entity(
        0,
        Status::default(),
        vec![
            Value::Integer(140),
            Value::Real(0.0),
            Value::Real(0.0),
            Value::Real(1.0),
            Value::Real(1.0),
            Value::Integer(1),
        ],
    );
    let doc = Document::parse(&b.to_bytes()).unwrap();
    let err = cadmorph_brep::chain(&doc.surface(off).unwrap_err());
    assert!(err.contains("DE 3") && err.contains("normal"), "{err}");
    // A distance through the centre of a sphere.
    let doc = sphere_doc(-2.0);
    let err = cadmorph_brep::chain(&doc.surface(EntityId(5)).unwrap_err());
    assert!(err.contains("DE 5") && err.contains("radius"), "{err}");
}

// ---------------------------------------------------------------------------------------
// OCCT
// ---------------------------------------------------------------------------------------

fn occt_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("cadmorph-iges-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn xyz(v: &serde_json::Value) -> Vector3<f64> {
    let a = v.as_array().unwrap();
    Vector3::new(a[0].as_f64().unwrap(), a[1].as_f64().unwrap(), a[2].as_f64().unwrap())
}

#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn occt_reads_the_sample_as_valid() {
    let path = std::fs::canonicalize(SAMPLE).unwrap();
    let (code, out) = cadmorph_testkit::harness::validate(&path, None);
    assert_eq!(code, 0, "{out}");
    assert_eq!(out["read_ok"], true, "{out}");
    assert_eq!(out["transfer_ok"], true, "{out}");
    assert_eq!(out["valid"], true, "{out}");
    let classes: Vec<&str> = out["faces"].as_array().unwrap().iter().map(|f| f["class"].as_str().unwrap()).collect();
    assert_eq!(classes.len(), 3, "{out}");
    println!("OCCT faces: {classes:?}, edges {}", out["topology"]["edges"]);
}

/// OCCT's points of each 104 (as Geom_Hyperbola / Geom_Parabola trimmed) lie on cadmorph's
/// curve, and the end points agree.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn conic_arcs_match_occt() {
    let dir = occt_dir("conics");
    let file = dir.join("conics.igs");
    std::fs::write(&file, build(true, false)).unwrap();
    let req = dir.join("request.json");
    let t: Vec<f64> = (0..=20).map(|i| f64::from(i) / 20.0).collect();
    std::fs::write(&req, serde_json::json!({"t": t, "normalized": true}).to_string()).unwrap();
    let (code, out) = cadmorph_testkit::harness::validate(&file, Some(&req));
    assert_eq!(code, 0, "{out}");
    let doc = Document::parse(&std::fs::read(&file).unwrap()).unwrap();
    let curves = out["free_curves"].as_array().unwrap();
    let ids = [1, 3, 7, 9];
    assert_eq!(curves.len(), ids.len(), "{out}");
    let mut worst = 0.0f64;
    for (de, oc) in ids.iter().zip(curves) {
        let class = oc["class"].as_str().unwrap();
        let form = doc.entity(EntityId(*de)).unwrap().form();
        assert_eq!(class, if form == 2 { "Geom_Hyperbola" } else { "Geom_Parabola" }, "DE {de}");
        let c = doc.curve_joined(EntityId(*de)).unwrap();
        let pts = c.control_points();
        let size = pts.iter().map(|p| (p - pts[0]).norm()).fold(0.0, f64::max);
        let evals = oc["evals"].as_array().unwrap();
        let View::ConicArc(arc) = doc.view(EntityId(*de)).unwrap() else { panic!() };
        let inv = doc.transform(EntityId(*de)).unwrap().try_inverse().unwrap();
        let occt_off: f64 = evals
            .iter()
            .map(|ev| {
                let p = inv.transform_point(&Point3::from(xyz(&ev["p"])));
                conic_distance(&arc.coefficients, p.x, p.y) / size
            })
            .fold(0.0, f64::max);
        if arc.coefficients[3..] != PARABOLA[3..] && form == 3 {
            // OCCT's IGESGeom_ConicArc::ComputedDefinition puts the vertex of a parabola
            // with D, E, F not those of y² = 4fx at the wrong place (signs of its centre
            // formula): its curve is not on the file's conic, so there is nothing to compare.
            println!("104 DE {de} ({class}): OCCT's points are {occt_off:.2e} (relative) off the conic; skipped");
            assert!(occt_off > 1e-3, "OCCT reads the shifted parabola right now: compare it");
            continue;
        }
        assert!(occt_off <= 1e-12, "DE {de}: OCCT's points {occt_off:e} off the conic");
        for ev in evals {
            let p = Point3::from(xyz(&ev["p"]));
            let e = c.project(&p, 1e-13 * size).distance_sq.sqrt() / size;
            worst = worst.max(e);
            assert!(e <= 1e-9, "DE {de} ({class}) at t = {}: {e:e}", ev["t"]);
        }
        // The same two end points (OCCT may run a hyperbola the other way).
        let d = c.domain();
        let (a, b) = (c.eval(*d.start()), c.eval(*d.end()));
        let (oa, ob) = (Point3::from(xyz(&evals[0]["p"])), Point3::from(xyz(&evals[evals.len() - 1]["p"])));
        let same = (a - oa).norm().max((b - ob).norm());
        let swapped = (a - ob).norm().max((b - oa).norm());
        let e = same.min(swapped) / size;
        worst = worst.max(e);
        assert!(e <= 1e-9, "DE {de} end points: {e:e}");
        println!("104 DE {de} ({class}): ends {e:e}, {} OCCT points on the curve", evals.len());
    }
    println!("worst relative deviation from OCCT {worst:e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// OCCT's Geom_OffsetSurface evaluated on each 140 face against cadmorph's NURBS at the
/// same (u, v) through the ParamMaps.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn offsets_match_occt() {
    let dir = occt_dir("offsets");
    let file = dir.join("offsets.igs");
    std::fs::write(&file, build(false, true)).unwrap();
    let req = dir.join("request.json");
    let f = [0.0, 0.1, 0.25, 0.5, 0.7, 0.9, 1.0];
    let uv: Vec<[f64; 2]> = f.iter().flat_map(|&u| f.iter().map(move |&v| [u, v])).collect();
    std::fs::write(&req, serde_json::json!({"uv": uv, "normalized": true}).to_string()).unwrap();
    let (code, out) = cadmorph_testkit::harness::validate(&file, Some(&req));
    assert_eq!(code, 0, "{out}");
    let doc = Document::parse(&std::fs::read(&file).unwrap()).unwrap();
    let faces = doc.faces();
    let occt = out["faces"].as_array().unwrap();
    assert_eq!(faces.len(), occt.len(), "{out}");
    for (face, of) in faces.iter().zip(occt) {
        let class = of["class"].as_str().unwrap();
        let off = doc.offset_surface(face.surface, None).unwrap();
        let s = &off.surface;
        let size = cadmorph_iges::convert::offset::size(&s.surface);
        // Exact offsets agree to the evaluation tolerance, approximations to their own.
        let tol = if off.exact { 1e-9 * size } else { off.tolerance };
        let is_torus = matches!(doc.view(face.surface), Ok(View::OffsetSurface(o))
            if doc.entity(o.surface).unwrap().entity_type() == 198);
        let mut worst = 0.0f64;
        for ev in of["evals"].as_array().unwrap() {
            let (u, v) = (ev["u"].as_f64().unwrap(), ev["v"].as_f64().unwrap());
            // cadmorph's torus runs v over [−π, π], OCCT's over [0, 2π].
            let v = if is_torus && v > std::f64::consts::PI { v - std::f64::consts::TAU } else { v };
            let (a, b) = s.nurbs_params(u, v);
            let e = (s.surface.eval(a, b).coords - xyz(&ev["p"])).norm();
            worst = worst.max(e);
            assert!(e <= tol, "DE {} ({class}) at ({u}, {v}): {e:e} > {tol:e}", face.surface.0);
        }
        println!(
            "140 DE {} vs OCCT {class}: worst {worst:e} ({:.1e} of size), exact {}, tolerance {:e}",
            face.surface.0,
            worst / size,
            off.exact,
            off.tolerance
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sphere_helper_is_what_the_sample_says() {
    // The sample's sphere patch is one rational biquadratic Bézier patch (no interior knots).
    let s = sphere_patch();
    assert_eq!((s.u_degree(), s.v_degree(), s.n_u(), s.n_v()), (2, 2, 3, 3));
    let p = Sphere::try_new(Placement::standard(), 2.0).unwrap().eval(0.5, 0.5);
    assert!((p.coords.norm() - 2.0).abs() < 1e-15);
}

/// 120 revolutions with an exact offset: a cone-like revolution of a line about the z
/// axis (offset DE 7, by 0.3) and a torus-like revolution of a half circle about the y
/// axis (offset DE 15, by −0.2).
/// `sign` multiplies both distances.
fn revolutions(sign: f64) -> Vec<u8> {
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261122.050000");
    let dependent = Status { subordinate: 1, ..Status::default() };
    let ptr = |id: EntityId| Value::Integer(i64::from(id.0));
    let line = |b: &mut DocumentBuilder, p: [f64; 3], q: [f64; 3]| {
        let mut v = vec![Value::Integer(110)];
        v.extend(reals(&p));
        v.extend(reals(&q));
        b.add_entity(0, dependent, v)
    };
    let offset = |b: &mut DocumentBuilder, base: EntityId, d: f64| {
        let mut v = vec![Value::Integer(140)];
        v.extend(reals(&[0.0, 0.0, 0.0, d]));
        v.push(ptr(base));
        b.add_entity(0, Status::default(), v)
    };
    let axis = line(&mut b, [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    let gen = line(&mut b, [1.0, 0.0, 0.0], [2.0, 0.0, 3.0]);
    let mut v = vec![Value::Integer(120), ptr(axis), ptr(gen)];
    v.extend(reals(&[0.0, 5.0]));
    let rev = b.add_entity(0, dependent, v);
    offset(&mut b, rev, 0.3 * sign);
    let axis = line(&mut b, [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let mut v = vec![Value::Integer(100)];
    v.extend(reals(&[0.0, 3.0, 0.0, 3.0, -1.0, 3.0, 1.0]));
    let arc = b.add_entity(0, dependent, v);
    let mut v = vec![Value::Integer(120), ptr(axis), ptr(arc)];
    v.extend(reals(&[0.5, 4.0]));
    let rev = b.add_entity(0, dependent, v);
    offset(&mut b, rev, -0.2 * sign);
    b.to_bytes()
}

/// Largest deviation over a grid of `s` of `f(point)` from 0.
fn grid_max(s: &NurbsSurface, f: impl Fn(Point3<f64>) -> f64) -> f64 {
    let (ud, vd) = s.domain();
    let mut worst = 0.0f64;
    for i in 0..=40 {
        for j in 0..=40 {
            let u = ud.start() + (ud.end() - ud.start()) * f64::from(i) / 40.0;
            let v = vd.start() + (vd.end() - vd.start()) * f64::from(j) / 40.0;
            worst = worst.max(f(s.eval(u, v)).abs());
        }
    }
    worst
}

#[test]
fn revolution_offsets_are_exact() {
    let doc = Document::parse(&revolutions(1.0)).unwrap();
    // Line (1, 0, 0)–(2, 0, 3) about z: in the meridian (ρ, z) the offset lies at 0.3 from
    // the line ρ = 1 + z/3.
    let cone = doc.offset_surface(EntityId(7), None).unwrap();
    assert!(cone.exact);
    let e = grid_max(&cone.surface.surface, |p| {
        let (rho, z) = (p.x.hypot(p.y), p.z);
        ((3.0 * rho - z - 3.0) / 10f64.sqrt()).abs() - 0.3
    });
    println!("120 line offset (exact): {e:e}");
    assert!(e <= 1e-14);
    // Half circle about (3, 0) of radius 1 in the xy plane, about y: the offset is a torus
    // tube of radius 0.8 or 1.2.
    let torus = doc.offset_surface(EntityId(15), None).unwrap();
    assert!(torus.exact);
    let tube = |p: Point3<f64>| (p.x.hypot(p.z) - 3.0).hypot(p.y);
    let r = tube(torus.surface.surface.eval(1.0, 0.3));
    assert!((r - 0.8).abs() < 1e-12 || (r - 1.2).abs() < 1e-12, "{r}");
    let e = grid_max(&torus.surface.surface, |p| tube(p) - r);
    println!("120 arc offset (exact): tube radius {r}, {e:e}");
    assert!(e <= 1e-14);
    // Same side as the approximation from the base's NURBS (its normal), within its tolerance.
    for (de, base) in [(7, 5), (15, 13)] {
        let exact = doc.offset_surface(EntityId(de), None).unwrap().surface.surface;
        let b = doc.surface(EntityId(base)).unwrap().surface;
        // The 120's NURBS normal is the IGES normal S_t × S_θ (built as OCCT builds it).
        let d = if de == 7 { 0.3 } else { -0.2 };
        let fit = cadmorph_iges::convert::offset::approximate_offset(&b, d, 1e-6).unwrap();
        let (u, v) = (0.7, 0.4);
        let (ud, vd) = b.domain();
        let (u, v) = (ud.start() + u * (ud.end() - ud.start()), vd.start() + v * (vd.end() - vd.start()));
        let e = (exact.eval(u, v) - fit.surface.eval(u, v)).norm();
        assert!(e <= 1e-6, "DE {de}: exact vs approximated {e:e}");
    }
}

/// OCCT's Geom_OffsetSurface points of the revolution offsets lie on cadmorph's exact
/// offsets (by projection: the generatrix arc's parameter is not OCCT's angle).
///
/// OCCT's IGES reader builds these 120s about the reversed axis, starting from the end
/// angle: its `Geom_SurfaceOfRevolution` normal is then IGES's `S_t × S_θ` (generatrix
/// parameter first); cadmorph builds its NURBS the same way, and both offset to that side.
/// OCCT also makes the 140's face over the offset's natural bounds (the full turn) rather
/// than the 120's angles: its points beyond those angles are not on the IGES surface and
/// are skipped.
#[test]
#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]
fn revolution_offsets_match_occt() {
    use cadmorph_nurbs::SurfaceProject;
    let dir = occt_dir("revolutions");
    let file = dir.join("revolutions.igs");
    std::fs::write(&file, revolutions(1.0)).unwrap();
    let req = dir.join("request.json");
    let f = [0.0, 0.2, 0.5, 0.8, 1.0];
    let uv: Vec<[f64; 2]> = f.iter().flat_map(|&u| f.iter().map(move |&v| [u, v])).collect();
    std::fs::write(&req, serde_json::json!({"uv": uv, "normalized": true}).to_string()).unwrap();
    let (code, out) = cadmorph_testkit::harness::validate(&file, Some(&req));
    assert_eq!(code, 0, "{out}");
    assert_eq!(out["valid"], true, "{out}");
    let doc = Document::parse(&revolutions(1.0)).unwrap();
    let faces = doc.faces();
    let occt = out["faces"].as_array().unwrap();
    assert_eq!(faces.len(), occt.len(), "{out}");
    for (face, of) in faces.iter().zip(occt) {
        let s = doc.offset_surface(face.surface, None).unwrap().surface.surface;
        let size = cadmorph_iges::convert::offset::size(&s);
        let mut worst = 0.0f64;
        let evals = of["evals"].as_array().unwrap();
        let View::OffsetSurface(o) = doc.view(face.surface).unwrap() else { panic!() };
        let View::SurfaceOfRevolution(r) = doc.view(o.surface).unwrap() else { panic!() };
        let mut compared = 0;
        for ev in evals {
            if ev["u"].as_f64().unwrap() > r.end_angle - r.start_angle + 1e-12 {
                continue;
            }
            let p = Point3::from(xyz(&ev["p"]));
            let proj = s.project(&p, 1e-13 * size);
            let e = proj.distance_sq.sqrt() / size;
            worst = worst.max(e);
            assert!(e <= 1e-9, "DE {}: {e:e}", face.surface.0);
            // The same normals (the same parameterisation of the 120).
            let n = s.normal(proj.u, proj.v).unwrap().into_inner();
            assert!(n.dot(&xyz(&ev["n"])) > 1.0 - 1e-9, "DE {}: normals", face.surface.0);
            compared += 1;
        }
        println!(
            "140 DE {} vs OCCT {}: worst {worst:e} of size over {compared} points in the 120's angles",
            face.surface.0, of["class"]
        );
        assert!(compared >= 15);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn surface_cycles_end_with_errors() {
    // A 144 whose surface is itself (this overflowed the stack before the chain check).
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261122.050000");
    let z = Value::Integer(0);
    let a = b.add_entity(0, Status::default(), vec![Value::Integer(144), Value::Integer(1), z.clone(), z.clone(), z]);
    let doc = Document::parse(&b.to_bytes()).unwrap();
    let err = doc.surface(a).unwrap_err().to_string();
    assert!(err.contains("loops or is longer"), "{err}");
    assert!(doc.surfaces().iter().all(|i| i.nurbs.is_err()));
    // Chains of 144s over a 128: 8 links convert (within the stack of a test thread in a
    // debug build), 9 do not.
    for (links, ok) in [(8, true), (9, false)] {
        let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261122.050000");
        let mut cur = b.add_surface(&bump());
        b.set_status(cur, Status { subordinate: 1, ..Status::default() });
        for k in 0..links {
            let z = Value::Integer(0);
            let status =
                if k + 1 == links { Status::default() } else { Status { subordinate: 1, ..Status::default() } };
            cur = b.add_entity(
                0,
                status,
                vec![Value::Integer(144), Value::Integer(i64::from(cur.0)), z.clone(), z.clone(), z],
            );
        }
        let doc = Document::parse(&b.to_bytes()).unwrap();
        assert_eq!(doc.surface(cur).is_ok(), ok, "{links} links");
    }
}

#[test]
fn offset_cycles_and_chains_end_with_errors() {
    // A 140 whose base is itself, and two 140s pointing at each other.
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261122.050000");
    let v = |base: i64| {
        vec![
            Value::Integer(140),
            Value::Real(0.0),
            Value::Real(0.0),
            Value::Real(1.0),
            Value::Real(1.0),
            Value::Integer(base),
        ]
    };
    let a = b.add_entity(0, Status::default(), v(1));
    let c = b.add_entity(0, Status::default(), v(5));
    let d = b.add_entity(0, Status::default(), v(3));
    let doc = Document::parse(&b.to_bytes()).unwrap();
    for id in [a, c, d] {
        let err = doc.surface(id).unwrap_err().to_string();
        assert!(err.contains("loops or is longer"), "{err}");
    }
    // A 140 of a 140 of a sphere: the outer one is approximated, on the sphere of radius 2.5.
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261122.050000");
    let dependent = Status { subordinate: 1, ..Status::default() };
    let c = b.add_entity(0, dependent, vec![Value::Integer(116), Value::Real(0.0), Value::Real(0.0), Value::Real(0.0)]);
    let sp = b.add_entity(0, dependent, vec![Value::Integer(196), Value::Integer(i64::from(c.0)), Value::Real(1.5)]);
    let mut w = v(i64::from(sp.0));
    w[4] = Value::Real(0.5);
    let inner = b.add_entity(0, dependent, w);
    let mut w = v(i64::from(inner.0));
    w[4] = Value::Real(0.5);
    let outer = b.add_entity(0, Status::default(), w);
    let doc = Document::parse(&b.to_bytes()).unwrap();
    let s = doc.offset_surface(outer, None).unwrap();
    assert!(!s.exact);
    let e = sphere_deviation(&s.surface.surface, Point3::origin(), 2.5);
    assert!(e <= s.tolerance, "{e:e} > {:e}", s.tolerance);
}

/// A 144 face on a 140 over an unbounded 192 cylinder or 194 cone (axis z through the
/// origin, radius 2, cone semi-angle 20°), bounded by a 142 whose model curve runs from
/// z = −1 to z = 3; `d` the offset distance. Returns the document and the 140's DE.
fn bounded_offset(kind: u32, d: f64) -> (Document, EntityId) {
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261122.050000");
    let dep = Status { subordinate: 1, ..Status::default() };
    let ptr = |id: EntityId| Value::Integer(i64::from(id.0));
    let o = b.add_entity(0, dep, vec![Value::Integer(116), Value::Real(0.0), Value::Real(0.0), Value::Real(0.0)]);
    let ax = b.add_entity(0, dep, vec![Value::Integer(123), Value::Real(0.0), Value::Real(0.0), Value::Real(1.0)]);
    let mut v = vec![Value::Integer(i64::from(kind)), ptr(o), ptr(ax), Value::Real(2.0)];
    if kind == 194 {
        v.push(Value::Real(20.0));
    }
    let base = b.add_entity(0, dep, v);
    let mut v = vec![Value::Integer(140)];
    v.extend(reals(&[0.0, 0.0, 0.0, d]));
    v.push(ptr(base));
    let off = b.add_entity(0, dep, v);
    let mut v = vec![Value::Integer(110)];
    v.extend(reals(&[2.5, 0.0, -1.0, 2.5, 0.0, 3.0]));
    let line = b.add_entity(0, dep, v);
    let z = Value::Integer(0);
    let cos =
        b.add_entity(0, dep, vec![Value::Integer(142), z.clone(), ptr(off), z.clone(), ptr(line), Value::Integer(2)]);
    b.add_entity(0, Status::default(), vec![Value::Integer(144), ptr(off), Value::Integer(1), z, ptr(cos)]);
    (Document::parse(&b.to_bytes()).unwrap(), off)
}

#[test]
fn cylinder_and_cone_offsets_are_exact() {
    for d in [0.5, -0.75] {
        let (doc, off) = bounded_offset(192, d);
        let face = doc.faces().into_iter().find(|f| f.surface == off).unwrap();
        let s = doc.face_surface(&face).unwrap().surface;
        let e = grid_max(&s, |p| p.x.hypot(p.y) - (2.0 + d));
        let (_, vd) = cadmorph_nurbs::Surface::domain(&s);
        println!("192 offset by {d} (exact): {e:e}, axial range {vd:?}");
        assert!(e <= 1e-14 && *vd.start() < -1.0 && *vd.end() > 3.0);
        assert!(doc.offset_surface(off, None).unwrap().exact);
        let (doc, off) = bounded_offset(194, d);
        let face = doc.faces().into_iter().find(|f| f.surface == off).unwrap();
        let s = doc.face_surface(&face).unwrap().surface;
        let a = 20f64.to_radians();
        // Signed distance from the base cone ρ = 2 + z tan a, in the meridian plane.
        let e = grid_max(&s, |p| (p.x.hypot(p.y) - 2.0 - p.z * a.tan()) * a.cos() - d);
        println!("194 offset by {d} (exact): {e:e}");
        assert!(e <= 1e-14);
        assert!(doc.offset_surface(off, None).unwrap().exact);
    }
    // Through the axis: an error naming the 140.
    let (doc, off) = bounded_offset(192, -2.0);
    let err = doc.offset_surface(off, None).unwrap_err().to_string();
    assert!(err.contains(&format!("DE {}", off.0)) && err.contains("radius"), "{err}");
}
