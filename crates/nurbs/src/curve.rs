//! NURBS curves.

use std::ops::RangeInclusive;

use nalgebra::{Point3, Vector3};

use crate::algo::{self, Hom};
use crate::basis::{basis_funs_into, ders_basis_funs_into};
use crate::{Curve, Error, KnotVector, Result, MAX_DEGREE};

/// A B-spline or NURBS curve `C(t) = Σ Nᵢ,ₚ(t) wᵢ Pᵢ / Σ Nᵢ,ₚ(t) wᵢ`.
///
/// Non-rational curves (`weights() == None`) take a fast path that never divides.
/// The knot vector may be clamped or not; the domain is `[u_p, u_{m−p}]`.
///
/// # Examples
///
/// A quarter circle of radius 1 as a rational quadratic:
///
/// ```
/// use cadmorph_nurbs::{Curve, KnotVector, NurbsCurve};
/// use nalgebra::Point3;
/// let w = std::f64::consts::FRAC_1_SQRT_2;
/// let arc = NurbsCurve::try_new(
///     2,
///     KnotVector::try_new(vec![0., 0., 0., 1., 1., 1.]).unwrap(),
///     vec![Point3::new(1., 0., 0.), Point3::new(1., 1., 0.), Point3::new(0., 1., 0.)],
///     Some(vec![1.0, w, 1.0]),
/// )
/// .unwrap();
/// for i in 0..=10 {
///     let p = arc.eval(i as f64 / 10.0);
///     assert!((p.coords.norm() - 1.0).abs() < 1e-15);
/// }
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsCurve {
    degree: usize,
    knots: KnotVector,
    control_points: Vec<Point3<f64>>,
    weights: Option<Vec<f64>>,
}

pub(crate) fn check_points(points: &[Point3<f64>]) -> Result<()> {
    for (index, p) in points.iter().enumerate() {
        if let Some(&value) = p.coords.iter().find(|c| !c.is_finite()) {
            return Err(Error::NotFinite { what: "control point", index, value });
        }
    }
    Ok(())
}

/// Checks the weights: as many as control points, finite, and positive, or zero
/// where `allow_zero` (a control point at infinity, The NURBS Book §7.3).
pub(crate) fn check_weights(weights: &[f64], n: usize, allow_zero: bool) -> Result<()> {
    if weights.len() != n {
        return Err(Error::WeightCount { weights: weights.len(), control_points: n });
    }
    for (index, &value) in weights.iter().enumerate() {
        if !value.is_finite() {
            return Err(Error::NotFinite { what: "weight", index, value });
        }
        if value < 0.0 || (value == 0.0 && !allow_zero) {
            return Err(Error::NonPositiveWeight { index, value });
        }
    }
    Ok(())
}

/// The homogeneous point `(w·x, w·y, w·z, w)` of a control point, or `(x, y, z, 0)`
/// for a weight of zero: a point at infinity stores its direction (The NURBS Book
/// §7.3, infinite control points) in place of a Cartesian position.
#[inline(always)]
pub(crate) fn hom_of(p: &Point3<f64>, w: f64) -> Hom {
    let s = if w == 0.0 { 1.0 } else { w };
    Hom::new(p.x * s, p.y * s, p.z * s, w)
}

pub(crate) fn to_hom(points: &[Point3<f64>], weights: Option<&[f64]>) -> Vec<Hom> {
    match weights {
        Some(w) => points.iter().zip(w).map(|(p, &w)| hom_of(p, w)).collect(),
        None => points.iter().map(|p| Hom::new(p.x, p.y, p.z, 1.0)).collect(),
    }
}

/// The inverse of [`to_hom`]: Cartesian points (directions where `w = 0`) and weights.
pub(crate) fn from_hom(pw: &[Hom], rational: bool) -> (Vec<Point3<f64>>, Option<Vec<f64>>) {
    let points = pw
        .iter()
        .map(|h| {
            let s = if h.w == 0.0 { 1.0 } else { h.w };
            Point3::new(h.x / s, h.y / s, h.z / s)
        })
        .collect();
    let weights = rational.then(|| pw.iter().map(|h| h.w).collect());
    (points, weights)
}

/// Applies the affine map `m` to `points`.
///
/// # Panics
///
/// If the last row of `m` is not `0 0 0 1`.
pub(crate) fn transform_points(points: &mut [Point3<f64>], m: &nalgebra::Matrix4<f64>) {
    assert!(
        m.row(3) == nalgebra::RowVector4::new(0.0, 0.0, 0.0, 1.0),
        "transform_by takes an affine map; its last row was {}",
        m.row(3)
    );
    for p in points {
        *p = m.transform_point(p);
    }
}

/// Binomial coefficient as f64 (small arguments).
pub(crate) fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    let k = k.min(n - k);
    (0..k).fold(1.0, |b, i| b * (n - i) as f64 / (i + 1) as f64)
}

impl NurbsCurve {
    /// Builds a curve of degree `degree`, checking everything.
    ///
    /// A weight may be zero: that control point is a point at infinity and
    /// `control_points[i]` holds its direction, the vector part of the homogeneous
    /// point `(x, y, z, 0)` (The NURBS Book §7.3; Splipy stores such points too). The
    /// curve is then evaluated in homogeneous form ([`eval_homogeneous`](Self::eval_homogeneous));
    /// only where all weight falls on such points (`w(t) = 0`) is the curve itself at
    /// infinity, and [`try_eval`](Self::try_eval) refuses there.
    ///
    /// # Errors
    ///
    /// [`Error::Degree`], [`Error::TooFewControlPoints`], [`Error::KnotCount`],
    /// [`Error::Multiplicity`], [`Error::NotFinite`], [`Error::WeightCount`],
    /// [`Error::NonPositiveWeight`].
    pub fn try_new(
        degree: usize,
        knots: KnotVector,
        control_points: Vec<Point3<f64>>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self> {
        knots.check_for(degree, control_points.len(), "")?;
        check_points(&control_points)?;
        if let Some(w) = &weights {
            check_weights(w, control_points.len(), true)?;
        }
        Ok(Self { degree, knots, control_points, weights })
    }

    /// Like [`try_new`](Self::try_new).
    ///
    /// # Panics
    ///
    /// If the data is invalid.
    pub fn new(degree: usize, knots: KnotVector, control_points: Vec<Point3<f64>>, weights: Option<Vec<f64>>) -> Self {
        Self::try_new(degree, knots, control_points, weights).expect("invalid NURBS curve")
    }

    /// A periodic curve in the OCCT/IGES form: one period of poles, distinct knots of
    /// one period and their multiplicities (first and last equal). The result is the
    /// equivalent unclamped curve whose first `degree` poles repeat at the end.
    ///
    /// # Errors
    ///
    /// Those of [`KnotVector::periodic`] and [`try_new`](Self::try_new).
    pub fn try_periodic(
        degree: usize,
        values: &[f64],
        mults: &[usize],
        poles: Vec<Point3<f64>>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self> {
        let knots = KnotVector::periodic(degree, values, mults)?;
        let n_period = knots.len() - 2 * degree - 1;
        if poles.len() != n_period {
            return Err(Error::Periodic { reason: "pole count differs from the sum of one period of multiplicities" });
        }
        let mut pts = poles;
        let wrap: Vec<_> = pts[..degree.min(pts.len())].to_vec();
        if wrap.len() < degree {
            return Err(Error::Periodic { reason: "fewer poles than the degree" });
        }
        pts.extend(wrap);
        let weights = weights.map(|mut w| {
            let ww: Vec<f64> = w.iter().take(degree).copied().collect();
            w.extend(ww);
            w
        });
        Self::try_new(degree, knots, pts, weights)
    }

    /// Applies the affine map `m` (a homogeneous 4×4 matrix whose last row is
    /// `0 0 0 1`) to the control points, in place. Weights are kept: an affine map
    /// commutes with the rational combination, so `c.transformed(m).eval(t) == m · c.eval(t)`.
    ///
    /// # Panics
    ///
    /// If the last row of `m` is not `0 0 0 1` (a projective map would change the weights).
    ///
    /// A control point at infinity (weight 0) is a direction: it takes the linear part
    /// of `m` only.
    pub fn transform_by(&mut self, m: &nalgebra::Matrix4<f64>) {
        crate::curve::transform_points(&mut self.control_points, m);
        if let Some(w) = &self.weights {
            let translation = m.fixed_view::<3, 1>(0, 3).into_owned();
            for (p, _) in self.control_points.iter_mut().zip(w).filter(|(_, &w)| w == 0.0) {
                p.coords -= translation;
            }
        }
    }

    /// A copy with the affine map `m` applied; see [`transform_by`](Self::transform_by).
    pub fn transformed(&self, m: &nalgebra::Matrix4<f64>) -> Self {
        let mut c = self.clone();
        c.transform_by(m);
        c
    }

    /// The degree `p`.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The knot vector.
    pub fn knots(&self) -> &KnotVector {
        &self.knots
    }

    /// The control points (Cartesian, not multiplied by the weights).
    pub fn control_points(&self) -> &[Point3<f64>] {
        &self.control_points
    }

    /// Mutable control points: a deformation moves these and keeps the weights.
    pub fn control_points_mut(&mut self) -> &mut [Point3<f64>] {
        &mut self.control_points
    }

    /// The weights, `None` for a non-rational curve.
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }

    /// Whether the curve has weights.
    pub fn is_rational(&self) -> bool {
        self.weights.is_some()
    }

    /// Homogeneous control points `(w·x, w·y, w·z, w)`.
    pub(crate) fn homogeneous(&self) -> Vec<Hom> {
        to_hom(&self.control_points, self.weights.as_deref())
    }

    pub(crate) fn from_parts(degree: usize, knots: Vec<f64>, pw: &[Hom], rational: bool) -> Self {
        let (control_points, weights) = from_hom(pw, rational);
        Self { degree, knots: KnotVector::new_unchecked(knots), control_points, weights }
    }

    fn check_inside(&self, u: f64) -> Result<()> {
        let d = self.domain();
        if !(u >= *d.start() && u <= *d.end()) {
            return Err(Error::OutsideDomain { value: u, start: *d.start(), end: *d.end() });
        }
        Ok(())
    }

    /// Inserts the knot `u` `times` times (Piegl & Tiller A5.1); the geometry does not
    /// change. Returns how many copies were actually inserted: the multiplicity is
    /// capped at `p + 1` strictly inside the domain and at `p` on its ends.
    ///
    /// At multiplicity `p + 1` the control point `C(u)` is doubled and the curve falls
    /// apart into two pieces joined only by position: it is C⁻¹ there in the sense of
    /// the basis (moving one of the two doubled points opens a gap), as geomdl, verb and
    /// Splipy allow. Evaluation at `u` itself takes the piece on the right.
    ///
    /// # Errors
    ///
    /// [`Error::OutsideDomain`] if `u` is outside the domain.
    pub fn insert_knot(&mut self, u: f64, times: usize) -> Result<usize> {
        self.check_inside(u)?;
        let (k, s) = algo::insertion_span(self.knots.as_slice(), u);
        let r = times.min(max_insertion(self.knots.domain(self.degree), self.degree, u).saturating_sub(s));
        if r == 0 {
            return Ok(0);
        }
        let (knots, pw) = algo::insert_knot_full(self.degree, self.knots.as_slice(), &self.homogeneous(), u, k, s, r);
        *self = Self::from_parts(self.degree, knots, &pw, self.is_rational());
        Ok(r)
    }

    /// Inserts all knots of `x` at once (Piegl & Tiller A5.4). `x` need not be sorted;
    /// every value must lie inside the domain and no knot may end up with a
    /// multiplicity above the degree.
    ///
    /// # Errors
    ///
    /// [`Error::OutsideDomain`], [`Error::NotFinite`], [`Error::Multiplicity`].
    pub fn refine(&mut self, x: &[f64]) -> Result<()> {
        let x = prepare_refinement(&self.knots, self.degree, x)?;
        let (knots, pw) = algo::refine(self.degree, self.knots.as_slice(), &self.homogeneous(), &x);
        *self = Self::from_parts(self.degree, knots, &pw, self.is_rational());
        Ok(())
    }

    /// Removes the knot `u` up to `times` times while the curve moves by at most `tol`
    /// (model units) (Piegl & Tiller A5.8). Returns how many copies were removed.
    ///
    /// # Tolerance
    ///
    /// For rational curves the homogeneous test is scaled as Piegl & Tiller (5.30)
    /// advise, `tol·w_min / (1 + |P|_max)`, which bounds the Cartesian deviation by `tol`.
    pub fn remove_knot(&mut self, u: f64, times: usize, tol: f64) -> usize {
        let ks = self.knots.as_slice();
        let r = match ks.iter().rposition(|&k| k == u) {
            Some(r) => r,
            None => return 0,
        };
        let s = ks[..=r].iter().rev().take_while(|&&k| k == u).count();
        let p = self.degree;
        // Only interior knots can be removed.
        if r <= p || r + p + 1 >= ks.len() || r < p + s - 1 || ks[r - s + 1] <= ks[p] {
            return 0;
        }
        let tol = homogeneous_tol(tol, &self.control_points, self.weights.as_deref());
        let mut knots = ks.to_vec();
        let mut rows = vec![self.homogeneous()];
        let t = algo::remove_knot(p, &mut knots, &mut rows, r, s, times.min(s), tol);
        if t > 0 {
            *self = Self::from_parts(p, knots, &rows[0], self.is_rational());
        }
        t
    }

    /// Raises the degree by `t` without changing the geometry (Piegl & Tiller A5.9).
    ///
    /// An unclamped curve stays unclamped: it is clamped, elevated and unclamped again
    /// (A12.1) onto outer knots whose runs each gain `t` copies, like the interior
    /// ones. A periodic curve (from [`try_periodic`](Self::try_periodic)) therefore
    /// comes back periodic, its first `p + t` control points repeating at the end.
    ///
    /// # Errors
    ///
    /// [`Error::Degree`] if the new degree exceeds [`MAX_DEGREE`].
    pub fn elevate_degree(&mut self, t: usize) -> Result<()> {
        if self.degree + t > MAX_DEGREE {
            return Err(Error::Degree { degree: self.degree + t });
        }
        if t == 0 {
            return Ok(());
        }
        let p = self.degree;
        let (knots, pw) = if self.knots.is_clamped(p) {
            algo::elevate_degree(p, self.knots.as_slice(), &self.homogeneous(), t)
        } else {
            crate::unclamp::elevate_unclamped(p, self.knots.as_slice(), &self.homogeneous(), t)
        };
        *self = Self::from_parts(p + t, knots, &pw, self.is_rational());
        Ok(())
    }

    /// The same curve with a clamped knot vector on the same domain (knots inserted at
    /// the domain ends, the outer control points dropped). A clamped curve comes back
    /// unchanged.
    pub fn clamped(&self) -> Self {
        let p = self.degree;
        if self.knots.is_clamped(p) {
            return self.clone();
        }
        let (knots, pw) = clamp_hom(p, self.knots.as_slice(), &self.homogeneous());
        Self::from_parts(p, knots, &pw, self.is_rational())
    }

    /// The Bézier segments of the curve, in order (Piegl & Tiller A5.6 by knot
    /// refinement to full interior multiplicity). Each segment has knots
    /// `[a; p+1] ∪ [b; p+1]` over its own interval.
    pub fn bezier_segments(&self) -> Vec<NurbsCurve> {
        let c = self.clamped();
        let p = c.degree;
        let (values, mults) = c.knots.distinct();
        let mut x = Vec::new();
        for (&v, &m) in values[1..values.len() - 1].iter().zip(&mults[1..mults.len() - 1]) {
            x.extend(std::iter::repeat_n(v, p.saturating_sub(m)));
        }
        let (refined, pw) = algo::refine(p, c.knots.as_slice(), &c.homogeneous(), &x);
        let starts = algo::bezier_starts(p, &refined, &values);
        values
            .windows(2)
            .zip(starts)
            .map(|(w, first)| {
                let mut knots = vec![w[0]; p + 1];
                knots.extend(std::iter::repeat_n(w[1], p + 1));
                Self::from_parts(p, knots, &pw[first..=first + p], c.is_rational())
            })
            .collect()
    }

    /// The part of the curve on `[t0, t1]`, same parameterisation: split at each end that
    /// lies inside the domain by more than 1e-12 of its length (an end within that of the
    /// domain's end, or outside it, keeps the curve's own end; `t1` not above `t0` keeps
    /// the upper part).
    ///
    /// # Errors
    ///
    /// Those of [`split`](Self::split).
    pub fn segment(&self, t0: f64, t1: f64) -> Result<Self> {
        let d = self.domain();
        let (a, b) = (*d.start(), *d.end());
        let eps = crate::tol::KNOT_EQUALITY * (b - a).abs().max(1.0);
        let mut out = self.clone();
        if t0 > a + eps && t0 < b - eps {
            out = out.split(t0)?.1;
        }
        if t1 < b - eps && t1 > t0 + eps {
            out = out.split(t1)?.0;
        }
        Ok(out)
    }

    /// Splits the curve at `t` into the parts on `[a, t]` and `[t, b]`.
    ///
    /// `c.split(t).0.eval(u)` is the same point as `c.eval(u)` for `u ≤ t`, and
    /// `.1.eval(u)` for `u ≥ t`. A knot of multiplicity `p + 1` at `t` (a C⁻¹ joint, see
    /// [`insert_knot`](Self::insert_knot)) is split without change: the left part ends
    /// on the left piece's last control point, the right part starts on the other.
    ///
    /// # Errors
    ///
    /// [`Error::OutsideDomain`] unless `t` is strictly inside the domain.
    pub fn split(&self, t: f64) -> Result<(Self, Self)> {
        let d = self.domain();
        if !(t > *d.start() && t < *d.end()) {
            return Err(Error::OutsideDomain { value: t, start: *d.start(), end: *d.end() });
        }
        let mut c = self.clamped();
        // A knot within rounding of `t` is where it splits (else the split would leave a
        // span of a few ulps, whose basis derivatives are noise).
        let eps = crate::tol::KNOT_EQUALITY * (d.end() - d.start()).abs().max(1.0);
        let t = c
            .knots
            .as_slice()
            .iter()
            .copied()
            .find(|&k| (k - t).abs() <= eps && k > *d.start() && k < *d.end())
            .unwrap_or(t);
        let p = c.degree;
        let present = c.knots.as_slice().iter().filter(|&&k| k == t).count();
        c.insert_knot(t, p.saturating_sub(present))?;
        let ks = c.knots.as_slice();
        let a = ks.partition_point(|&k| k < t);
        let s = ks.iter().filter(|&&k| k == t).count();
        let hom = c.homogeneous();
        let mut left_knots = ks[..a].to_vec();
        left_knots.extend(std::iter::repeat_n(t, p + 1));
        let mut right_knots = vec![t; p + 1];
        right_knots.extend_from_slice(&ks[a + s..]);
        let n_left = left_knots.len() - p - 1;
        let n_right = right_knots.len() - p - 1;
        let left = Self::from_parts(p, left_knots, &hom[..n_left], c.is_rational());
        let right = Self::from_parts(p, right_knots, &hom[hom.len() - n_right..], c.is_rational());
        Ok((left, right))
    }

    /// The same curve traversed the other way: `r.eval(a + b − t) == c.eval(t)`.
    pub fn reversed(&self) -> Self {
        Self {
            degree: self.degree,
            knots: self.knots.reversed(),
            control_points: self.control_points.iter().rev().copied().collect(),
            weights: self.weights.as_ref().map(|w| w.iter().rev().copied().collect()),
        }
    }

    /// The homogeneous point `Cʷ(t) = Σ Nᵢ,ₚ(t) Pᵢʷ = (w·x, w·y, w·z, w)` (Piegl &
    /// Tiller Eq. 4.5, A4.1 before its division). It is finite everywhere, also where
    /// the curve passes through infinity (`w(t) = 0`, possible with zero weights); for
    /// a non-rational curve `w = 1`.
    pub fn eval_homogeneous(&self, t: f64) -> nalgebra::Vector4<f64> {
        let p = self.degree;
        let ks = self.knots.as_slice();
        let span = crate::knots::find_span(ks, p, t);
        let mut n = vec![0.0; p + 1];
        let mut left = vec![0.0; p + 1];
        let mut right = vec![0.0; p + 1];
        basis_funs_into(ks, span, t, p, &mut n, &mut left, &mut right);
        let first = span - p;
        let w = self.weights.as_deref();
        (0..=p).fold(Hom::zeros(), |acc, j| {
            acc + hom_of(&self.control_points[first + j], w.map_or(1.0, |w| w[first + j])) * n[j]
        })
    }

    /// The point `C(t)`, refused where the curve is at infinity.
    ///
    /// # Errors
    ///
    /// [`Error::AtInfinity`] where the homogeneous weight `w(t)` is zero (only
    /// possible with zero weights, see [`try_new`](Self::try_new)).
    pub fn try_eval(&self, t: f64) -> Result<Point3<f64>> {
        let h = self.eval_homogeneous(t);
        if h.w == 0.0 {
            return Err(Error::AtInfinity { parameter: t });
        }
        Ok(Point3::from(h.xyz() / h.w))
    }

    /// Evaluation with stack buffers for degrees up to 15.
    fn eval_impl(&self, u: f64) -> Point3<f64> {
        let p = self.degree;
        let ks = self.knots.as_slice();
        let span = crate::knots::find_span(ks, p, u);
        let mut n = [0.0; 16];
        let mut left = [0.0; 16];
        let mut right = [0.0; 16];
        let mut nv;
        let mut lv;
        let mut rv;
        let (n, left, right): (&mut [f64], &mut [f64], &mut [f64]) = if p < 16 {
            (&mut n, &mut left, &mut right)
        } else {
            nv = vec![0.0; p + 1];
            lv = vec![0.0; p + 1];
            rv = vec![0.0; p + 1];
            (&mut nv, &mut lv, &mut rv)
        };
        basis_funs_into(ks, span, u, p, n, left, right);
        let first = span - p;
        match &self.weights {
            None => {
                let mut acc = Vector3::zeros();
                for j in 0..=p {
                    acc += self.control_points[first + j].coords * n[j];
                }
                Point3::from(acc)
            }
            Some(w) => {
                let mut acc = Hom::zeros();
                for j in 0..=p {
                    acc += hom_of(&self.control_points[first + j], w[first + j]) * n[j];
                }
                Point3::from(acc.xyz() / acc.w)
            }
        }
    }
}

/// The highest multiplicity knot insertion may reach at `u`: `p + 1` strictly inside
/// the domain (the spline splits there), `p` on its ends (a `(p + 1)`-th copy would
/// leave an empty end piece).
pub(crate) fn max_insertion(domain: RangeInclusive<f64>, p: usize, u: f64) -> usize {
    if u > *domain.start() && u < *domain.end() {
        p + 1
    } else {
        p
    }
}

/// Sorts the refinement knots, checks they are inside the domain and that no
/// multiplicity exceeds the degree.
pub(crate) fn prepare_refinement(knots: &KnotVector, p: usize, x: &[f64]) -> Result<Vec<f64>> {
    let d = knots.domain(p);
    for (index, &value) in x.iter().enumerate() {
        if !value.is_finite() {
            return Err(Error::NotFinite { what: "knot", index, value });
        }
        if !(value > *d.start() && value < *d.end()) {
            return Err(Error::OutsideDomain { value, start: *d.start(), end: *d.end() });
        }
    }
    let mut x = x.to_vec();
    x.sort_by(f64::total_cmp);
    let mut i = 0;
    while i < x.len() {
        let v = x[i];
        let added = x[i..].iter().take_while(|&&k| k == v).count();
        let multiplicity = added + knots.as_slice().iter().filter(|&&k| k == v).count();
        if multiplicity > p {
            return Err(Error::Multiplicity { value: v, multiplicity, max: p });
        }
        i += added;
    }
    Ok(x)
}

/// Piegl & Tiller (5.30): a homogeneous tolerance that bounds the Cartesian error by `tol`.
pub(crate) fn homogeneous_tol(tol: f64, points: &[Point3<f64>], weights: Option<&[f64]>) -> f64 {
    match weights {
        None => tol,
        Some(w) => {
            let wmin = w.iter().copied().fold(f64::INFINITY, f64::min);
            let pmax = points.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
            tol * wmin / (1.0 + pmax)
        }
    }
}

impl Curve for NurbsCurve {
    fn domain(&self) -> RangeInclusive<f64> {
        self.knots.domain(self.degree)
    }

    fn eval(&self, t: f64) -> Point3<f64> {
        self.eval_impl(t)
    }

    /// Piegl & Tiller A3.2 on the homogeneous points, then A4.2 for the rational form.
    fn derivs(&self, t: f64, n: usize) -> Vec<Vector3<f64>> {
        let p = self.degree;
        let ks = self.knots.as_slice();
        let span = crate::knots::find_span(ks, p, t);
        let mut nders = vec![vec![0.0; p + 1]; n + 1];
        ders_basis_funs_into(ks, span, t, p, n, &mut nders);
        let first = span - p;
        let mut hders = vec![Hom::zeros(); n + 1];
        let w = self.weights.as_deref();
        for (k, hd) in hders.iter_mut().enumerate() {
            for j in 0..=p {
                let wj = w.map_or(1.0, |w| w[first + j]);
                *hd += hom_of(&self.control_points[first + j], wj) * nders[k][j];
            }
        }
        rational_curve_derivs(&hders)
    }
}

/// A4.2: Cartesian derivatives from homogeneous ones.
pub(crate) fn rational_curve_derivs(hders: &[Hom]) -> Vec<Vector3<f64>> {
    let n = hders.len() - 1;
    let w0 = hders[0].w;
    let mut ck: Vec<Vector3<f64>> = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let mut v = hders[k].xyz();
        for i in 1..=k {
            v -= ck[k - i] * (binomial(k, i) * hders[i].w);
        }
        ck.push(v / w0);
    }
    ck
}

/// Clamps a homogeneous spline to its domain `[u_p, u_{m-p}]`: raises both ends to
/// multiplicity `p` by insertion, then drops the knots and control points outside.
pub(crate) fn clamp_hom(p: usize, knots: &[f64], pw: &[Hom]) -> (Vec<f64>, Vec<Hom>) {
    let (a, b) = (knots[p], knots[knots.len() - 1 - p]);
    let mut knots = knots.to_vec();
    let mut pw = pw.to_vec();
    for end in [a, b] {
        let (k, s) = algo::insertion_span(&knots, end);
        if s < p {
            let (k2, q2) = algo::insert_knot(p, &knots, &pw, end, k, s, p - s);
            knots = k2;
            pw = q2;
        }
    }
    // Last copy of a: the curve starts at control point k_a - p.
    let k_a = knots.iter().rposition(|&k| k == a).expect("a is a knot");
    let f_b = knots.iter().position(|&k| k == b).expect("b is a knot");
    let mut out = vec![a];
    out.extend_from_slice(&knots[k_a - p + 1..f_b + p]);
    out.push(b);
    let pts = pw[k_a - p..f_b].to_vec();
    (out, pts)
}
