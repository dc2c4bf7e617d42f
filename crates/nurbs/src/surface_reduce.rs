//! Removal of every removable knot of a surface within a tolerance, per direction
//! (the surface form of [`NurbsCurve::remove_knots_within`](crate::NurbsCurve::remove_knots_within),
//! after Piegl & Tiller §9.5 with A5.8 on all rows of the net at once).
//!
//! The deviation bound is measured afresh against the original, as for curves (see the
//! `reduce` module): the reduced surface is refined back onto the original knot vectors
//! (A5.4 per row, then per column) and the largest difference of homogeneous control
//! points bounds the distance between the two surfaces everywhere (the tensor-product
//! B-spline basis is non-negative and sums to one); for rational surfaces the bound is
//! `(max|ΔAᵢⱼ| + max|Pᵢⱼ|·max|ΔWᵢⱼ|) / min ŵᵢⱼ`.

use crate::algo::Hom;
use crate::reduce::{deviation_bound, refine_onto};
use crate::{KnotRemoval, NurbsSurface, Surface};

/// The net of `s` on the knot vectors `(tu, tv)`, which contain its own; `None` when they
/// do not.
fn net_on(s: &NurbsSurface, tu: &[f64], tv: &[f64]) -> Option<Vec<Hom>> {
    let p = s.u_degree();
    let mut cols = Vec::with_capacity(s.n_v());
    for col in s.u_rows() {
        cols.push(refine_onto(p, s.u_knots().as_slice(), &col, tu)?);
    }
    let wide = s.with_u_rows(p, tu.to_vec(), &cols);
    let q = s.v_degree();
    let mut net = Vec::with_capacity(wide.n_u() * tv.len());
    for row in wide.v_rows() {
        net.extend(refine_onto(q, wide.v_knots().as_slice(), &row, tv)?);
    }
    Some(net)
}

impl NurbsSurface {
    /// Removes every interior knot copy, in u and in v, that can go while the surface
    /// stays within `tol` (model units) of the original, and returns how many went and
    /// the bound reached (module docs).
    ///
    /// Greedy: u first, then v; at each distinct interior knot as many copies as A5.8
    /// removes within `tol` are taken at once, and fewer if the bound measured against
    /// the original exceeds `tol`; passes repeat until nothing more goes. Knots of
    /// multiplicity above the degree (C⁻¹ joints) stay. Cost: one refinement of the
    /// whole net per trial, `O(n_u·n_v·p)`.
    ///
    /// # Tolerance
    ///
    /// `tol` bounds the distance between the original and the result at every
    /// parameter pair (not only at the control points). A `tol` of a few ulps of the
    /// model size removes exactly the copies that carry no information: those of a
    /// surface whose continuity at a knot exceeds what its multiplicity says, such as
    /// the C^k joints of [`composed_with`](Self::composed_with).
    pub fn remove_knots_within(&mut self, tol: f64) -> KnotRemoval {
        let original = self.homogeneous();
        let rational = self.is_rational();
        let tu = self.u_knots().as_slice().to_vec();
        let tv = self.v_knots().as_slice().to_vec();
        let bound_of = |s: &NurbsSurface| {
            net_on(s, &tu, &tv).map_or(f64::INFINITY, |back| deviation_bound(&original, &back, rational))
        };
        let mut current = self.clone();
        let mut result = KnotRemoval { removed: 0, bound: 0.0 };
        if tol.is_nan() || tol < 0.0 {
            return result;
        }
        for direction in [true, false] {
            loop {
                let mut changed = false;
                let (p, knots) = if direction {
                    (current.u_degree(), current.u_knots().clone())
                } else {
                    (current.v_degree(), current.v_knots().clone())
                };
                let (values, mults) = knots.distinct();
                let d = knots.domain(p);
                for (v, m) in values.into_iter().zip(mults) {
                    if !(v > *d.start() && v < *d.end()) || m > p {
                        continue;
                    }
                    let mut want = m;
                    while want > 0 {
                        let mut trial = current.clone();
                        let t = if direction {
                            trial.remove_u_knot(v, want, tol)
                        } else {
                            trial.remove_v_knot(v, want, tol)
                        };
                        if t == 0 {
                            break;
                        }
                        let bound = bound_of(&trial);
                        if bound <= tol {
                            current = trial;
                            result = KnotRemoval { removed: result.removed + t, bound };
                            changed = true;
                            break;
                        }
                        want = t - 1;
                    }
                }
                if !changed {
                    break;
                }
            }
        }
        debug_assert!(current.domain() == self.domain());
        *self = current;
        result
    }
}
