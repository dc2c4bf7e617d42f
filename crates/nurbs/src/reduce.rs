//! Data reduction on curves: degree reduction with an error bound (after Piegl &
//! Tiller A5.11) and removal of every removable knot within a tolerance (after the
//! knot removal with an accumulated error bound of Piegl & Tiller ch. 9,
//! approximation to within a specified accuracy; done greedily here).
//!
//! Both report a deviation bound that does not come from the steps that produced the
//! new curve but is computed afresh against the original: the new curve is brought
//! back, exactly, onto the original's degree and knot vector (A5.9 elevation, A5.4
//! refinement), and the largest difference of homogeneous control points bounds the
//! distance between the two curves everywhere (the B-spline basis is non-negative and
//! sums to one). For a rational curve `C = A/W`, `Ĉ = Â/Ŵ`:
//! `C − Ĉ = (A − Â + C·(Ŵ − W)) / Ŵ`, so
//! `|C − Ĉ| ≤ (max|ΔAᵢ| + max|Pᵢ|·max|ΔWᵢ|) / min ŵᵢ`, which is the bound reported
//! (positive weights only; with a weight of zero no bound exists and nothing is done).

use crate::algo::{self, Hom};
use crate::{Curve, Error, NurbsCurve, NurbsSurface, Result};

/// What [`NurbsCurve::remove_knots_within`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KnotRemoval {
    /// Knot copies removed.
    pub removed: usize,
    /// A bound on the distance between the original and the new curve (model units);
    /// `0` when nothing was removed.
    pub bound: f64,
}

/// Degree reduction of one Bézier segment from degree `p = q.len() − 1` to `p − 1`
/// (Piegl & Tiller §5.6, the Bézier step of A5.11): the reduced points are found from both ends by
/// inverting degree elevation `Qᵢ = αᵢ Rᵢ₋₁ + (1 − αᵢ) Rᵢ`, `αᵢ = i/p`, and for odd `p`
/// the two estimates of the middle point are averaged.
pub(crate) fn bezier_reduce(q: &[Hom]) -> Vec<Hom> {
    let p = q.len() - 1;
    let alpha = |i: usize| i as f64 / p as f64;
    let mut r = vec![Hom::zeros(); p];
    r[0] = q[0];
    r[p - 1] = q[p];
    // Left recursion for i ≤ left_end, right recursion for i ≥ right_start.
    let (left_end, right_start) = if p.is_multiple_of(2) { ((p - 2) / 2, p / 2) } else { ((p - 1) / 2, (p - 1) / 2) };
    for i in 1..=left_end.min(p - 1) {
        r[i] = (q[i] - r[i - 1] * alpha(i)) / (1.0 - alpha(i));
    }
    let middle_left = r[left_end];
    for i in (right_start.max(1)..p - 1).rev() {
        r[i] = (q[i + 1] - r[i + 1] * (1.0 - alpha(i + 1))) / alpha(i + 1);
    }
    if p % 2 == 1 && left_end > 0 && left_end < p - 1 {
        r[left_end] = (middle_left + r[left_end]) * 0.5;
    }
    r
}

/// Degree elevation of one Bézier segment by one (Piegl & Tiller eq. (5.36)):
/// `Qᵢ = αᵢ Pᵢ₋₁ + (1 − αᵢ) Pᵢ`, `αᵢ = i/(p+1)`. Brings a [`bezier_reduce`]d segment back
/// onto the original's degree, where the two can be compared point by point.
pub(crate) fn bezier_elevate(r: &[Hom]) -> Vec<Hom> {
    let d = r.len();
    (0..=d)
        .map(|i| match i {
            0 => r[0],
            _ if i == d => r[d - 1],
            _ => {
                let a = i as f64 / d as f64;
                r[i - 1] * a + r[i] * (1.0 - a)
            }
        })
        .collect()
}

/// The bound of the module docs between homogeneous nets `a` (the original) and `b`
/// on the same basis. `rational` says whether the weights take part.
pub(crate) fn deviation_bound(a: &[Hom], b: &[Hom], rational: bool) -> f64 {
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    let (mut ea, mut ew) = (0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        ea = ea.max((x.xyz() - y.xyz()).norm());
        ew = ew.max((x.w - y.w).abs());
    }
    if !rational {
        return ea;
    }
    let wmin_a = a.iter().map(|h| h.w).fold(f64::INFINITY, f64::min);
    let wmin_b = b.iter().map(|h| h.w).fold(f64::INFINITY, f64::min);
    if !(wmin_a > 0.0 && wmin_b > 0.0) {
        return f64::INFINITY;
    }
    let pmax = a.iter().map(|h| (h.xyz() / h.w).norm()).fold(0.0, f64::max);
    let bound = (ea + pmax * ew) / wmin_b;
    if bound.is_nan() {
        f64::INFINITY
    } else {
        bound
    }
}

/// Brings `(p, knots, pw)` onto the finer knot vector `target` (same degree, `knots`
/// a sub-multiset of `target`) by A5.4; `None` if `knots` is not contained in it or a
/// value to insert would exceed multiplicity `p`.
pub(crate) fn refine_onto(p: usize, knots: &[f64], pw: &[Hom], target: &[f64]) -> Option<Vec<Hom>> {
    let mut x = Vec::new();
    let mut i = 0;
    for &k in target {
        if i < knots.len() && knots[i] == k {
            i += 1;
        } else {
            x.push(k);
        }
    }
    if i != knots.len() {
        return None;
    }
    let d = (target[p], target[target.len() - 1 - p]);
    for &v in &x {
        let m = target.iter().filter(|&&k| k == v).count();
        if m > p || !(v > d.0 && v < d.1) {
            return None;
        }
    }
    let (refined, qw) = algo::refine(p, knots, pw, &x);
    (refined.len() == target.len()).then_some(qw)
}

/// Degree reduction by one (the steps of [`NurbsCurve::reduce_degree`]) of curves that
/// share the clamped knot vector `ks` of degree `p`: the rows of a surface net in one
/// direction, or a curve alone. The knot copies are removed from all rows at once
/// (A5.8 on the net), within `tol_h` in homogeneous space. Returns the new knots, the
/// new rows and the bound of the module docs over all rows, measured against the
/// original elevated back; [`Error::Tolerance`] when a knot does not go or the bound
/// exceeds `tol`.
pub(crate) fn reduce_rows(
    p: usize,
    ks: &[f64],
    rows: &[Vec<Hom>],
    tol_h: f64,
    rational: bool,
    tol: f64,
) -> Result<(Vec<f64>, Vec<Vec<Hom>>, f64)> {
    let kv = crate::KnotVector::try_new(ks.to_vec())?;
    let (values, mults) = kv.distinct();
    let last = values.len() - 1;
    let mut x = Vec::new();
    for (&v, &m) in values[1..last].iter().zip(&mults[1..last]) {
        x.extend(std::iter::repeat_n(v, p.saturating_sub(m)));
    }
    let q = p - 1;
    let mut knots = Vec::new();
    let mut reduced_rows = Vec::with_capacity(rows.len());
    for pw in rows {
        let (refined, bez) = algo::refine(p, ks, pw, &x);
        let starts = algo::bezier_starts(p, &refined, &values);
        knots = vec![values[0]; p];
        let mut pts: Vec<Hom> = Vec::new();
        for (i, &first) in starts.iter().enumerate() {
            let reduced = bezier_reduce(&bez[first..=first + p]);
            if i == 0 {
                pts.extend_from_slice(&reduced);
            } else if mults[i] > p {
                // A C⁻¹ joint stays one: multiplicity q + 1, the end points apart.
                knots.extend(std::iter::repeat_n(values[i], p));
                pts.extend_from_slice(&reduced);
            } else {
                knots.extend(std::iter::repeat_n(values[i], q));
                pts.extend_from_slice(&reduced[1..]);
            }
        }
        knots.extend(std::iter::repeat_n(values[last], p));
        reduced_rows.push(pts);
    }
    for i in 1..last {
        let m = mults[i];
        if m >= p {
            continue;
        }
        let need = p - m;
        let r = knots.partition_point(|&k| k <= values[i]) - 1;
        let removed = algo::remove_knot(q, &mut knots, &mut reduced_rows, r, q, need, tol_h);
        if removed < need {
            return Err(Error::Tolerance { operation: "degree reduction", bound: f64::INFINITY, tol });
        }
    }
    // Elevated back, and knots of multiplicity 1 (which leave the reduced form
    // entirely) put back: the difference to the original bounds the deviation.
    let (mut original, mut back_all) = (Vec::new(), Vec::new());
    for (pw, pts) in rows.iter().zip(&reduced_rows) {
        let (back_knots, back) = algo::elevate_degree(q, &knots, pts, 1);
        match refine_onto(p, &back_knots, &back, ks) {
            Some(b) => back_all.extend(b),
            None => return Err(Error::Tolerance { operation: "degree reduction", bound: f64::INFINITY, tol }),
        }
        original.extend_from_slice(pw);
    }
    let bound = deviation_bound(&original, &back_all, rational);
    if bound.is_nan() || tol.is_nan() || bound > tol {
        return Err(Error::Tolerance { operation: "degree reduction", bound, tol });
    }
    Ok((knots, reduced_rows, bound))
}

impl NurbsSurface {
    /// Lowers the u degree by one if the surface moves by at most `tol` (model units),
    /// and returns a bound on how far it moved: [`NurbsCurve::reduce_degree`] (Piegl &
    /// Tiller A5.11, §5.6) on every column of the net at once, the knot copies removed
    /// from all columns together (A5.8 on the net), the bound measured against the
    /// original as the module docs say (the tensor-product basis is non-negative and sums
    /// to one). The surface is clamped first.
    ///
    /// # Errors
    ///
    /// As [`NurbsCurve::reduce_degree`]; the surface is then left as it was.
    pub fn reduce_u_degree(&mut self, tol: f64) -> Result<f64> {
        let p = self.u_degree();
        if p < 2 {
            return Err(Error::Degree { degree: 0 });
        }
        let c = self.clamped();
        let tol_h = crate::curve::homogeneous_tol(tol, c.control_points(), c.weights());
        let (knots, cols, bound) = reduce_rows(p, c.u_knots().as_slice(), &c.u_rows(), tol_h, c.is_rational(), tol)?;
        *self = c.with_u_rows(p - 1, knots, &cols);
        Ok(bound)
    }

    /// Lowers the v degree by one; see [`reduce_u_degree`](Self::reduce_u_degree).
    ///
    /// # Errors
    ///
    /// As [`reduce_u_degree`](Self::reduce_u_degree).
    pub fn reduce_v_degree(&mut self, tol: f64) -> Result<f64> {
        let mut t = self.transposed();
        let bound = t.reduce_u_degree(tol)?;
        *self = t.transposed();
        Ok(bound)
    }
}

impl NurbsCurve {
    /// Lowers the degree by one if the curve moves by at most `tol` (model units), and
    /// returns a bound on how far it moved. The curve is clamped first (the result is
    /// clamped on the same domain).
    ///
    /// The steps are those of Piegl & Tiller A5.11, done one after the other instead
    /// of interleaved: Bézier decomposition (A5.6), reduction of each segment (§5.6),
    /// and removal (A5.8) of the knot copies the decomposition added, so
    /// that every interior knot of multiplicity `m` comes out with `m − 1` (degree
    /// elevation adds one, so `reduce ∘ elevate` is the identity). The bound is then
    /// measured as the module docs say, against the curve elevated back.
    ///
    /// # Errors
    ///
    /// [`Error::Degree`] for a curve of degree 1; [`Error::Tolerance`] if a knot
    /// cannot be removed within `tol`, a reduced weight is not positive (no bound
    /// exists then), or the bound exceeds `tol`. The curve is then left as it was.
    pub fn reduce_degree(&mut self, tol: f64) -> Result<f64> {
        let p = self.degree();
        if p < 2 {
            return Err(Error::Degree { degree: 0 });
        }
        let c = self.clamped();
        let rational = c.is_rational();
        let ks = c.knots().as_slice().to_vec();
        let tol_h = crate::curve::homogeneous_tol(tol, c.control_points(), c.weights());
        let (knots, mut rows, bound) = reduce_rows(p, &ks, &[c.homogeneous()], tol_h, rational, tol)?;
        let pts = rows.pop().expect("one row");
        *self = NurbsCurve::from_parts(p - 1, knots, &pts, rational);
        Ok(bound)
    }

    /// Removes every interior knot copy that can go while the curve stays within `tol`
    /// (model units) of the original (data reduction, after Piegl & Tiller §9.5).
    ///
    /// Greedy: the distinct interior knots are tried in order, one copy at a time
    /// (A5.8), and a removal is kept only if the bound of the module docs, measured
    /// against the original curve, stays within `tol`; passes repeat until nothing more
    /// goes. Knots of multiplicity `p + 1` are left alone. Cost: one refinement of the
    /// whole curve per trial, `O(n²·p)` for `n` control points.
    pub fn remove_knots_within(&mut self, tol: f64) -> KnotRemoval {
        let p = self.degree();
        let original_knots = self.knots().as_slice().to_vec();
        let original = self.homogeneous();
        let rational = self.is_rational();
        let mut current = self.clone();
        let mut result = KnotRemoval { removed: 0, bound: 0.0 };
        loop {
            let mut changed = false;
            let (values, mults) = current.knots().distinct();
            let d = current.domain();
            for (v, m) in values.into_iter().zip(mults) {
                if !(v > *d.start() && v < *d.end()) || m > p {
                    continue;
                }
                let mut trial = current.clone();
                if trial.remove_knot(v, 1, tol) == 0 {
                    continue;
                }
                let bound = refine_onto(p, trial.knots().as_slice(), &trial.homogeneous(), &original_knots)
                    .map_or(f64::INFINITY, |back| deviation_bound(&original, &back, rational));
                if bound <= tol {
                    current = trial;
                    result = KnotRemoval { removed: result.removed + 1, bound };
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        *self = current;
        result
    }
}
