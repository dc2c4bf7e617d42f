//! A profile's NURBS curve: through every point, round (C2) at the leading edge.

use cadmorph_blade::{naca, NacaOptions, Profile};
use cadmorph_nurbs::Curve;

#[test]
fn curve_through_points_with_a_round_leading_edge() {
    let csv = std::fs::read_to_string(
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples/blade/bladex/boeing_707.csv"),
    )
    .unwrap();
    let boeing = Profile::from_csv(&csv).unwrap();
    for p in [naca("2412", NacaOptions::default()).unwrap(), naca("23112", NacaOptions::default()).unwrap(), boeing] {
        let c = p.to_curve(3).unwrap();
        let n = p.xup.len();
        for (i, (x, y)) in p.xup.iter().zip(&p.yup).enumerate() {
            let q = c.curve.eval(c.params[n - 1 - i]);
            assert!((q.x - x).hypot(q.y - y) < 1e-12, "upper {i}");
        }
        for (i, (x, y)) in p.xdown.iter().zip(&p.ydown).enumerate() {
            let q = c.curve.eval(c.params[n - 1 + i]);
            assert!((q.x - x).hypot(q.y - y) < 1e-12, "lower {i}");
        }
        // Round leading edge: the two sides, split there, meet with the same tangent.
        let (a, b) = c.curve.split(c.leading_edge).unwrap();
        let ta = a.derivs(c.leading_edge, 1)[1].normalize();
        let tb = b.derivs(c.leading_edge, 1)[1].normalize();
        assert!((ta - tb).norm() < 1e-12, "kink at the leading edge: {ta} vs {tb}");
        // And it is the leading edge: the tangent there runs across the chord (normal to
        // the camber line, tilted by the camber slope: 19° for the reflex 23112).
        assert!(ta.y.abs() > 0.9, "{ta}");
    }
}
