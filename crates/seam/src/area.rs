//! Area and enclosed-volume share of a whole (untrimmed) patch, by Gauss–Legendre
//! quadrature on every knot span: what seam repair reports as its change to the shape.

use cadmorph_nurbs::{NurbsSurface, Surface};

/// Gauss–Legendre nodes and weights on [−1, 1], 8 points (exact for polynomials of
/// degree 15; Abramowitz & Stegun, Table 25.4).
const GL8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_2, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (0.960_289_856_497_536_2, 0.101_228_536_290_376_26),
];

/// `(area, volume share)` of the whole patch `s`: `∬ |S_u × S_v| du dv` and
/// `(1/3) ∬ S · (S_u × S_v) du dv` over its parameter domain. The volume shares of the
/// faces of a closed, consistently oriented shell add up to the volume it encloses
/// (divergence theorem), so the change of the shares of the faces an edit touched is
/// the change of the enclosed volume when the shell stays closed.
///
/// # Tolerance
///
/// Eight points per knot span in each direction: exact for non-rational patches up to
/// bicubic in the volume share, and converging fast (the integrands are smooth on each
/// span) elsewhere.
pub fn area_and_volume(s: &NurbsSurface) -> (f64, f64) {
    let (ud, vd) = s.domain();
    let breaks = |k: &cadmorph_nurbs::KnotVector, lo: f64, hi: f64| -> Vec<f64> {
        let mut b: Vec<f64> = k.distinct().0.into_iter().filter(|x| *x > lo && *x < hi).collect();
        b.insert(0, lo);
        b.push(hi);
        b
    };
    let ub = breaks(s.u_knots(), *ud.start(), *ud.end());
    let vb = breaks(s.v_knots(), *vd.start(), *vd.end());
    let (mut area, mut volume) = (0.0, 0.0);
    for uw in ub.windows(2) {
        let (uc, uh) = ((uw[0] + uw[1]) / 2.0, (uw[1] - uw[0]) / 2.0);
        for vw in vb.windows(2) {
            let (vc, vh) = ((vw[0] + vw[1]) / 2.0, (vw[1] - vw[0]) / 2.0);
            for (xu, wu) in GL8 {
                for (xv, wv) in GL8 {
                    let d = s.eval_d1(uc + uh * xu, vc + vh * xv);
                    let n = d.du.cross(&d.dv);
                    let w = wu * wv * uh * vh;
                    area += w * n.norm();
                    volume += w * d.point.coords.dot(&n) / 3.0;
                }
            }
        }
    }
    (area, volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The six faces of the box [0, 2] x [0, 3] x [0, 5] as bilinear patches with
    /// outward normals (`S_u × S_v` pointing out): areas 2 (6 + 10 + 15) = 62, volume 30.
    #[test]
    fn a_box_has_its_area_and_its_volume() {
        let (a, b, c) = (2.0, 3.0, 5.0);
        let p = |x: f64, y: f64, z: f64| [x, y, z];
        // Corners P00, P10, P01, P11: u runs along the first edge, v along the second,
        // ordered so that u × v points out of the box.
        let faces = [
            [p(0., 0., 0.), p(0., b, 0.), p(a, 0., 0.), p(a, b, 0.)], // z = 0, normal -z
            [p(0., 0., c), p(a, 0., c), p(0., b, c), p(a, b, c)],     // z = c, normal +z
            [p(0., 0., 0.), p(a, 0., 0.), p(0., 0., c), p(a, 0., c)], // y = 0, normal -y
            [p(0., b, 0.), p(0., b, c), p(a, b, 0.), p(a, b, c)],     // y = b, normal +y
            [p(0., 0., 0.), p(0., 0., c), p(0., b, 0.), p(0., b, c)], // x = 0, normal -x
            [p(a, 0., 0.), p(a, b, 0.), p(a, 0., c), p(a, b, c)],     // x = a, normal +x
        ];
        let (mut area, mut volume) = (0.0, 0.0);
        for f in faces {
            let (x, y) = area_and_volume(&NurbsSurface::bilinear(f));
            area += x;
            volume += y;
        }
        assert!((area - 62.0).abs() < 1e-12, "{area}");
        assert!((volume - 30.0).abs() < 1e-12, "{volume}");
    }

    /// A quarter of a unit cylinder's mantle (rational, exact): area π/2 · height.
    #[test]
    fn a_rational_quarter_cylinder_has_its_area() {
        use cadmorph_nurbs::math::Point3;
        use cadmorph_nurbs::KnotVector;
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let ring = [(1.0, 0.0, 1.0), (1.0, 1.0, w), (0.0, 1.0, 1.0)];
        let mut pts = Vec::new();
        let mut ws = Vec::new();
        for (x, y, wt) in ring {
            for z in [0.0, 2.0] {
                pts.push(Point3::new(x, y, z));
                ws.push(wt);
            }
        }
        let s = NurbsSurface::try_new(
            (2, 1),
            (KnotVector::clamped_uniform(2, 3), KnotVector::clamped_uniform(1, 2)),
            (3, 2),
            pts,
            Some(ws),
        )
        .unwrap();
        let (area, _) = area_and_volume(&s);
        assert!((area - std::f64::consts::PI).abs() < 1e-9, "{area}");
    }
}
