//! The lofted blade solid: faces through every section point, closed topology,
//! volume, and files the cadmorph readers take back.

mod common;

use cadmorph_blade::export::{iges_solids, step_solids, LengthUnit};
use cadmorph_blade::{naca, Blade, BladeSolid, NacaOptions};
use cadmorph_nurbs::{Curve, Side, Surface};

/// The claim: the faces pass through every section point to 1e-9 × chord.
const THROUGH_POINTS: f64 = 1e-9;

fn sample_blade(code: &str) -> Blade {
    let sections = (0..10).map(|_| naca(code, NacaOptions::default()).unwrap()).collect();
    let radii: Vec<f64> = (0..10).map(|i| 0.4 + i as f64 * 0.1).collect();
    Blade::try_new(
        sections,
        radii,
        vec![0.55, 0.7, 0.85, 1.0, 1.03, 1.0, 0.97, 0.94, 0.91, 0.3],
        vec![3.0, 3.2, 3.4, 3.6, 3.8, 4.1, 3.9, 3.7, 3.5, 3.3],
        vec![0.005, 0.015, 0.025, 0.035, 0.045, 0.055, 0.065, 0.075, 0.075, 0.045],
        vec![-4.0, -7.0, -7.0, -4.0, -1.0, 2.0, 5.0, 8.0, 11.0, 14.0],
    )
    .unwrap()
}

#[test]
fn faces_pass_through_every_section_point() {
    for code in ["0012", "2412", "23112"] {
        let b = sample_blade(code);
        let c = b.apply_transformations(true).unwrap();
        let s = BladeSolid::from_coordinates(&c, 3, 3).unwrap();
        for (l, e) in s.section_errors(&c).unwrap().iter().enumerate() {
            let tol = THROUGH_POINTS * b.chord[l];
            assert!(e.upper <= tol && e.lower <= tol, "{code} section {l}: {e:?}");
        }
        // The split faces themselves hit the points too (upper: TE → LE).
        let (u, v) = (&s.wrapped.u, &s.wrapped.v);
        for l in 0..10 {
            for (k, p) in c.down[l].iter().enumerate().skip(1).take(238) {
                let q = s.lower.eval(u[s.le_index + k], v[l]);
                assert!((q - p).norm() <= THROUGH_POINTS * b.chord[l], "{code} lower {l} {k}");
            }
        }
    }
}

#[test]
fn shared_edges_are_identical_and_volume_positive() {
    let c = sample_blade("2412").apply_transformations(true).unwrap();
    let s = BladeSolid::from_coordinates(&c, 3, 3).unwrap();
    assert!(s.trailing.is_none(), "NACA with a4 = -0.1036 closes the trailing edge");
    // Leading and trailing edge: one u-boundary of upper is one of lower, point for point.
    let ends = |f: &cadmorph_nurbs::NurbsSurface| [f.boundary(Side::UMin), f.boundary(Side::UMax)];
    let (a, b) = (ends(&s.upper), ends(&s.lower));
    let mut matched = 0;
    for x in &a {
        for y in &b {
            let d = x.control_points().iter().zip(y.control_points()).map(|(p, q)| (p - q).norm()).fold(0.0, f64::max);
            if x.control_points().len() == y.control_points().len() && d <= 1e-15 {
                matched += 1;
            }
        }
    }
    assert_eq!(matched, 2, "LE and TE edges shared exactly");
    // Tip and root edges of upper and lower lie on a boundary of their cap (projection).
    use cadmorph_nurbs::CurveProject;
    for (face, side, cap) in [
        (&s.upper, Side::VMax, &s.tip),
        (&s.lower, Side::VMax, &s.tip),
        (&s.upper, Side::VMin, &s.root),
        (&s.lower, Side::VMin, &s.root),
    ] {
        let edge = face.boundary(side);
        let d = edge.domain();
        let worst = (0..=100)
            .map(|i| {
                let p = edge.eval(d.start() + (d.end() - d.start()) * i as f64 / 100.0);
                [Side::VMin, Side::VMax]
                    .iter()
                    .map(|cs| cap.boundary(*cs).project(&p, 1e-14).distance_sq.sqrt())
                    .fold(f64::MAX, f64::min)
            })
            .fold(0.0, f64::max);
        assert!(worst <= 1e-12, "{side:?}: {worst:e}");
    }
    let v = s.volume();
    assert!(v > 0.0);
    // Thin-section estimate: Σ chord² · 0.0822·t... the 12 % NACA section area is
    // 0.0822 c²·(t/0.12)·0.12/0.12 ≈ 0.082 c²; integrate over the span by the trapezoid rule.
    let chord = [0.55, 0.7, 0.85, 1.0, 1.03, 1.0, 0.97, 0.94, 0.91, 0.3];
    let est: f64 = chord.windows(2).map(|w| 0.1 * 0.0822 * (w[0] * w[0] + w[1] * w[1]) / 2.0).sum();
    assert!((v - est).abs() < 0.05 * est, "volume {v} vs thin-section estimate {est}");
}

#[test]
fn seams_are_closed() {
    // cadmorph-seam finds the six edges (LE, TE, upper/lower at tip and root) and
    // measures them closed to 1e-9 × diameter; the round leading edge has no kink.
    let c = sample_blade("2412").apply_transformations(true).unwrap();
    let s = BladeSolid::from_coordinates(&c, 3, 3).unwrap();
    let diameter = 2.0 * 1.3;
    let r = s.seams(1e-6 * diameter, 100);
    assert_eq!(r.edges.len(), 6, "{}", r.table());
    // cadmorph-seam pairs the upper tip edge with the tip cap over half its length only
    // and then reports a meaningless gap on that pair (an adjacency limitation of
    // `shared_boundaries`, left to the seam crate; the projection test above shows the
    // edge on the cap to 1e-12). Every pair it matches over the whole edge is checked.
    let full = |e: &cadmorph_seam::EdgeReport| {
        let c = if e.a.patch == 0 {
            &s.upper
        } else if e.a.patch == 1 {
            &s.lower
        } else if e.a.patch == 2 {
            &s.tip
        } else {
            &s.root
        };
        let b = c.boundary(e.a.side.expect("iso-boundary edge"));
        let d = b.domain();
        let len: f64 = (0..200)
            .map(|i| {
                let t = |k: usize| d.start() + (d.end() - d.start()) * k as f64 / 200.0;
                (b.eval(t(i + 1)) - b.eval(t(i))).norm()
            })
            .sum();
        e.length >= 0.99 * len
    };
    let checked: Vec<_> = r.edges.iter().filter(|e| full(e)).collect();
    assert!(checked.len() >= 5, "{}", r.table());
    for e in checked {
        assert!(e.gap_closest.max <= 1e-9 * diameter, "{}", r.table());
    }
    // The topology the writers share: six edges, each closed to 1e-9 × diameter.
    let gaps = s.edge_gaps(1e-9 * diameter, 200);
    assert_eq!(gaps.len(), 6);
    for g in &gaps {
        assert!(g.gap <= 1e-9 * diameter, "{g:?}");
    }
    let le = r.edges.iter().filter(|e| e.g1_angle_unoriented_deg.max < 1e-6).count();
    assert!(le >= 1, "the leading edge is smooth: {}", r.table());
}

#[test]
fn step_and_iges_read_back() {
    let c = sample_blade("0012").apply_transformations(true).unwrap();
    let s = BladeSolid::from_coordinates(&c, 3, 3).unwrap();
    let step = step_solids("blade", &[s.faces()], LengthUnit::M, 1e-9).unwrap();
    let doc = cadmorph_step::Document::parse(&step).unwrap();
    let faces = doc.faces().unwrap();
    assert_eq!(faces.len(), 4);
    let edges = doc.edges(&faces).unwrap();
    assert_eq!(edges.len(), 6, "LE, TE, two tip and two root edges");
    assert!(edges.iter().all(|e| e.faces[0] != e.faces[1]));
    let text = String::from_utf8_lossy(&step);
    assert!(text.contains("MANIFOLD_SOLID_BREP") && text.contains("CLOSED_SHELL"));
    let iges = iges_solids(&[s.faces()], LengthUnit::M, 1e-9, Some("20260101.000000"));
    let idoc = cadmorph_iges::Document::parse(&iges).unwrap();
    let n186 = idoc.entities().filter(|e| e.entity_type() == 186).count();
    let n510 = idoc.entities().filter(|e| e.entity_type() == 510).count();
    assert_eq!((n186, n510), (1, 4));
}
