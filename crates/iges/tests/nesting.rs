//! Curves and surfaces nested in one another without end (issue 13: `scripts/fuzz 600
//! iges_document` died of a stack overflow after 7.7 M runs, which libFuzzer cannot save).
//! A 142 with only a parameter curve is converted through its surface, and a 108, 118,
//! 120 or 122 through its curves: each kind counted its own depth from zero, so a cycle
//! through two kinds recursed until the stack ran out. Now one depth and one visit count
//! cover the whole conversion, and such files end with an error naming an entity.

use std::time::{Duration, Instant};

use cadmorph_iges::write::DocumentBuilder;
use cadmorph_iges::{Document, EntityId, Error, Status, Units, Value};
use cadmorph_nurbs::{KnotVector, NurbsCurve, NurbsSurface};
use nalgebra::Point3;

const NESTED: &str = "curves and surfaces nesting deeper than 64 (or a reference cycle)";

fn int(v: u32) -> Value {
    Value::Integer(i64::from(v))
}

fn real(v: f64) -> Value {
    Value::Real(v)
}

/// The DE number of the `k`-th entity (0-based) a builder adds.
fn de(k: u32) -> u32 {
    2 * k + 1
}

/// A parameter-space line from (0.2, 0.2) to (0.8, 0.6): the parameter curve of the 142s.
fn param_line() -> NurbsCurve {
    NurbsCurve::try_new(
        1,
        KnotVector::try_new(vec![0.0, 0.0, 1.0, 1.0]).unwrap(),
        vec![Point3::new(0.2, 0.2, 0.0), Point3::new(0.8, 0.6, 0.0)],
        None,
    )
    .unwrap()
}

/// A 142 on `surface` with only the parameter curve `param` (IGES 5.3 §4.11: CRTN, SPTR,
/// BPTR, CPTR, PREF).
fn on_surface(surface: u32, param: u32) -> Vec<Value> {
    vec![int(142), int(1), int(surface), int(param), int(0), int(1)]
}

/// Runs `f` on a thread with a 64 MB stack: a debug build's frames are many times a
/// release build's, and the limit must stop the recursion, not the test thread's 2 MB.
fn on_big_stack<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    std::thread::Builder::new().stack_size(64 << 20).spawn(f).unwrap().join().unwrap()
}

fn assert_nested(e: &Error, cycle: &[u32]) {
    match e {
        Error::Unsupported { de, reason, .. } => {
            assert_eq!(*reason, NESTED, "{e}");
            assert!(cycle.contains(de), "DE {de} is not one of {cycle:?}: {e}");
        }
        other => panic!("expected the nesting limit, got {other}"),
    }
    assert!(e.to_string().starts_with("entity DE "), "{e}");
}

#[test]
fn reference_cycles_through_curves_and_surfaces_are_refused() {
    // Each cycle: a 142 (DE 3) whose surface (DE 5) is converted through that same 142.
    let cases: Vec<(&str, Vec<Value>)> = vec![
        // 108 plane bounded by the 142 (A, B, C, D, PTR, X, Y, Z, SIZE).
        (
            "108",
            vec![
                int(108),
                real(0.0),
                real(0.0),
                real(1.0),
                real(0.0),
                int(de(1)),
                real(0.0),
                real(0.0),
                real(0.0),
                real(1.0),
            ],
        ),
        // 120 revolution with the 142 as its generatrix (and as its axis).
        ("120", vec![int(120), int(de(1)), int(de(1)), real(0.0), real(1.0)]),
        // 118 ruled surface between the 142 and itself.
        ("118", vec![int(118), int(de(1)), int(de(1)), int(0), int(0)]),
        // 122 tabulated cylinder along the 142.
        ("122", vec![int(122), int(de(1)), real(0.0), real(0.0), real(1.0)]),
    ];
    for (kind, surface) in cases {
        let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261202.170000");
        let p = b.add_curve(&param_line());
        let c = b.add_entity(0, Status::default(), on_surface(de(2), p.0));
        let s = b.add_entity(0, Status::default(), surface);
        assert_eq!((c, s), (EntityId(de(1)), EntityId(de(2))));
        let bytes = b.to_bytes();
        let (curve, surf) = on_big_stack(move || {
            let doc = Document::parse(&bytes).unwrap();
            (doc.curve(c).map(|_| ()), doc.surface(s).map(|_| ()))
        });
        assert_nested(&curve.expect_err(kind), &[c.0, s.0]);
        assert_nested(&surf.expect_err(kind), &[c.0, s.0]);
    }
}

#[test]
fn deep_chains_are_refused_and_shallow_ones_convert() {
    // 100 000 composite curves (102), each holding the next, over one line: refused at the
    // 64th, whatever the length. The same chain of 60 converts to the line.
    for (links, ok) in [(100_000u32, false), (60, true)] {
        let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261202.170000");
        let line = b.add_entity(
            0,
            Status::default(),
            vec![int(110), real(0.0), real(0.0), real(0.0), real(1.0), real(2.0), real(3.0)],
        );
        let mut top = line;
        for _ in 0..links {
            top = b.add_entity(0, Status::default(), vec![int(102), int(1), int(top.0)]);
        }
        let bytes = b.to_bytes();
        let r = on_big_stack(move || Document::parse(&bytes).unwrap().curve(top).map(|c| c.len()));
        if ok {
            assert_eq!(r.unwrap(), 1, "{links} links");
        } else {
            let e = r.unwrap_err();
            assert_nested(&e, &[top.0 - 2 * 64, top.0 - 2 * 63, top.0 - 2 * 65]);
        }
    }
}

#[test]
fn a_wide_graph_of_curves_on_ruled_surfaces_is_cut_off_by_one_visit_count() {
    // Level k: a 118 ruled between two copies of a 142 on the level k − 1 surface; level 0
    // a bilinear 128. 30 levels visit 2^30 entities when every surface starts its own count
    // (it never ended); one count for the whole conversion stops at 100 000 visits.
    let mut b = DocumentBuilder::new(Units::Millimetre).timestamp("20261202.170000");
    let p = b.add_curve(&param_line());
    let mut surface = b.add_surface(&NurbsSurface::bilinear([
        [0.0, 0.0, 0.0],
        [10.0, 0.0, 0.0],
        [0.0, 10.0, 0.0],
        [10.0, 10.0, 1.0],
    ]));
    for _ in 0..30 {
        let c = b.add_entity(0, Status::default(), on_surface(surface.0, p.0));
        surface = b.add_entity(0, Status::default(), vec![int(118), int(c.0), int(c.0), int(0), int(0)]);
    }
    let bytes = b.to_bytes();
    let start = Instant::now();
    let r = on_big_stack(move || Document::parse(&bytes).unwrap().surface(surface).map(|_| ()));
    let e = r.unwrap_err();
    assert!(
        matches!(e, Error::Unsupported { reason, .. } if reason.starts_with("more than 100000 curve and surface entities")),
        "{e}"
    );
    assert!(start.elapsed() < Duration::from_secs(120), "took {:?}", start.elapsed());
}
