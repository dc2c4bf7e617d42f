//! Area and enclosed-volume share of a whole (untrimmed) patch, by Gauss–Legendre
//! quadrature on every knot span: what seam repair reports as its change to the shape.

use cadmorph_nurbs::{NurbsSurface, Surface};

/// Gauss–Legendre nodes and weights on [−1, 1], 8 points (exact for polynomials of
/// degree 15; Abramowitz & Stegun, Table 25.4).
const GL8: [(f64, f64); 8] = [
    (-0.960_289_856_497_536_2, 0.101_228_536_290_376_26),
    (-0.796_666_477_413_626_7, 0.222_381_034_453_374_47),
    (-0.525_532_409_916_329_0, 0.313_706_645_877_887_3),
    (-0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329_0, 0.313_706_645_877_887_3),
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
