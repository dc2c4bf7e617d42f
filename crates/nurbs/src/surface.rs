//! NURBS surfaces.

use std::ops::{Index, RangeInclusive};

use nalgebra::{Point3, Unit, Vector3};

use crate::algo::{self, Hom};
use crate::basis::{basis_funs_into, ders_basis_funs_into};
use crate::curve::{
    binomial, check_points, check_weights, clamp_hom, from_hom, hom_of, homogeneous_tol, max_insertion,
    prepare_refinement, to_hom,
};
use crate::{Error, KnotVector, NurbsCurve, Result, Surface, MAX_DEGREE};

#[cfg(target_arch = "x86_64")]
mod v3;

/// A B-spline or NURBS surface
///
/// ```text
/// S(u,v) = Σᵢ Σⱼ Nᵢ,ₚ(u) Nⱼ,q(v) wᵢⱼ Pᵢⱼ / Σᵢ Σⱼ Nᵢ,ₚ(u) Nⱼ,q(v) wᵢⱼ
/// ```
///
/// The control net is stored row by row: `Pᵢⱼ` is `control_points()[i * n_v + j]`,
/// `i` counting along u (the layout of OCCT's `Poles(i, j)` and of IGES entity 128).
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::{NurbsSurface, Surface};
/// let plane = NurbsSurface::bilinear([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]);
/// assert_eq!(plane.eval(0.5, 0.5).z, 0.0);
/// assert_eq!(plane.normal(0.3, 0.7).unwrap().z, 1.0);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface {
    u_degree: usize,
    v_degree: usize,
    u_knots: KnotVector,
    v_knots: KnotVector,
    n_u: usize,
    n_v: usize,
    control_points: Vec<Point3<f64>>,
    weights: Option<Vec<f64>>,
    /// Reciprocal knot differences of A2.2 per span, derived from the knots (see
    /// [`inverse_denominators`]); they make the hot evaluation paths division-free.
    u_inv: Vec<f64>,
    v_inv: Vec<f64>,
    /// Whether a weight is zero (a control point at infinity): evaluation then takes
    /// the homogeneous general path, the fast paths assume positive weights.
    infinite: bool,
}

/// The reciprocals `1 / (u_{i+r+1} − u_{i+1−j+r})` that A2.2 divides by, for every span
/// `i` and every `1 ≤ j ≤ p`, `0 ≤ r < j`, stored at `i·p(p+1)/2 + j(j−1)/2 + r`.
/// Empty spans (repeated knots) get zeros; evaluation never lands in them.
fn inverse_denominators(knots: &[f64], p: usize) -> Vec<f64> {
    let per = p * (p + 1) / 2;
    let spans = knots.len().saturating_sub(p + 1);
    let mut inv = vec![0.0; spans * per];
    for i in p..spans {
        if knots[i + 1] <= knots[i] {
            continue;
        }
        for j in 1..=p {
            for r in 0..j {
                inv[i * per + j * (j - 1) / 2 + r] = 1.0 / (knots[i + r + 1] - knots[i + 1 + r - j]);
            }
        }
    }
    inv
}

/// A2.2 with the divisions replaced by the precomputed reciprocals of `inv`.
#[inline(always)]
fn basis_funs_inv<const N: usize>(knots: &[f64], inv: &[f64], span: usize, u: f64, p: usize) -> [f64; N] {
    let per = p * (p + 1) / 2;
    let inv = &inv[span * per..span * per + per];
    let mut out = [0.0; N];
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    out[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        let row = j * (j - 1) / 2;
        for r in 0..j {
            let temp = out[r] * inv[row + r];
            out[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        out[j] = saved;
    }
    out
}

/// All partial derivatives of a surface up to a total order `n`:
/// `d[(k, l)] = ∂^(k+l) S / ∂u^k ∂v^l`, with `d[(0, 0)]` the point (as a vector).
/// Entries with `k + l > n` are zero.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceDerivs {
    order: usize,
    d: Vec<Vector3<f64>>,
}

impl SurfaceDerivs {
    /// The highest total order held.
    pub fn order(&self) -> usize {
        self.order
    }

    /// The point `S(u, v)`.
    pub fn point(&self) -> Point3<f64> {
        Point3::from(self.d[0])
    }
}

impl Index<(usize, usize)> for SurfaceDerivs {
    type Output = Vector3<f64>;
    fn index(&self, (k, l): (usize, usize)) -> &Vector3<f64> {
        &self.d[k * (self.order + 1) + l]
    }
}

/// Which side of the parameter rectangle an iso-boundary is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// `u = u₀` (a curve in v).
    UMin,
    /// `u = u₁` (a curve in v).
    UMax,
    /// `v = v₀` (a curve in u).
    VMin,
    /// `v = v₁` (a curve in u).
    VMax,
}

impl Side {
    /// All four sides in the order `UMin, UMax, VMin, VMax`.
    pub const ALL: [Side; 4] = [Side::UMin, Side::UMax, Side::VMin, Side::VMax];
}

/// Point and first partials at one parameter pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePointD1 {
    /// `S(u, v)`.
    pub point: Point3<f64>,
    /// `∂S/∂u`.
    pub du: Vector3<f64>,
    /// `∂S/∂v`.
    pub dv: Vector3<f64>,
}

impl NurbsSurface {
    /// Builds a surface, checking everything. `control_points` is the `n_u × n_v` net
    /// row by row (`i * n_v + j`), `weights` the same layout.
    ///
    /// A weight may be zero: that control point is at infinity and holds a direction,
    /// as for [`NurbsCurve::try_new`]; [`try_eval`](Self::try_eval) refuses the
    /// parameters where the surface itself is at infinity.
    ///
    /// # Errors
    ///
    /// [`Error::NetSize`], and those of [`NurbsCurve::try_new`] per direction.
    pub fn try_new(
        (u_degree, v_degree): (usize, usize),
        (u_knots, v_knots): (KnotVector, KnotVector),
        (n_u, n_v): (usize, usize),
        control_points: Vec<Point3<f64>>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self> {
        Self::check_net((u_degree, v_degree), (&u_knots, &v_knots), (n_u, n_v), control_points.len(), None)?;
        check_points(&control_points)?;
        if let Some(w) = &weights {
            check_weights(w, control_points.len(), true)?;
        }
        let u_inv = inverse_denominators(u_knots.as_slice(), u_degree);
        let v_inv = inverse_denominators(v_knots.as_slice(), v_degree);
        let infinite = has_zero_weight(weights.as_deref());
        Ok(Self { u_degree, v_degree, u_knots, v_knots, n_u, n_v, control_points, weights, u_inv, v_inv, infinite })
    }

    /// The checks of [`try_new`](Self::try_new) that do not need the control points'
    /// coordinates (`try_new` checks the coordinates before the weights): a net of `n_points` points is `n_u × n_v`, the knot
    /// vectors fit the degrees and counts, the weights are as many and valid. For a
    /// reader that lists a file's surfaces before reading their points (the STEP
    /// reader's faces).
    ///
    /// # Errors
    ///
    /// As [`try_new`](Self::try_new), but for non-finite coordinates.
    pub fn check_net(
        (u_degree, v_degree): (usize, usize),
        (u_knots, v_knots): (&KnotVector, &KnotVector),
        (n_u, n_v): (usize, usize),
        n_points: usize,
        weights: Option<&[f64]>,
    ) -> Result<()> {
        if n_u.checked_mul(n_v) != Some(n_points) {
            return Err(Error::NetSize { n_u, n_v, found: n_points });
        }
        u_knots.check_for(u_degree, n_u, "u: ")?;
        v_knots.check_for(v_degree, n_v, "v: ")?;
        if let Some(w) = weights {
            check_weights(w, n_points, true)?;
        }
        Ok(())
    }

    /// Like [`try_new`](Self::try_new).
    ///
    /// # Panics
    ///
    /// If the data is invalid.
    pub fn new(
        degrees: (usize, usize),
        knots: (KnotVector, KnotVector),
        size: (usize, usize),
        control_points: Vec<Point3<f64>>,
        weights: Option<Vec<f64>>,
    ) -> Self {
        Self::try_new(degrees, knots, size, control_points, weights).expect("invalid NURBS surface")
    }

    /// The bilinear patch through four corners `P00, P10, P01, P11` (`Pᵢⱼ` at `u = i`,
    /// `v = j`) on `[0, 1]²`.
    pub fn bilinear(corners: [[f64; 3]; 4]) -> Self {
        let [p00, p10, p01, p11] = corners.map(Point3::from);
        let k = || KnotVector::new_unchecked(vec![0.0, 0.0, 1.0, 1.0]);
        Self::new((1, 1), (k(), k()), (2, 2), vec![p00, p01, p10, p11], None)
    }

    pub(crate) fn from_parts(
        degrees: (usize, usize),
        knots: (Vec<f64>, Vec<f64>),
        size: (usize, usize),
        pw: &[Hom],
        rational: bool,
    ) -> Self {
        let (control_points, weights) = from_hom(pw, rational);
        let infinite = has_zero_weight(weights.as_deref());
        Self {
            infinite,
            u_degree: degrees.0,
            v_degree: degrees.1,
            u_inv: inverse_denominators(&knots.0, degrees.0),
            v_inv: inverse_denominators(&knots.1, degrees.1),
            u_knots: KnotVector::new_unchecked(knots.0),
            v_knots: KnotVector::new_unchecked(knots.1),
            n_u: size.0,
            n_v: size.1,
            control_points,
            weights,
        }
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
        if let Some(w) = self.weights.as_ref().filter(|_| self.infinite) {
            let translation = m.fixed_view::<3, 1>(0, 3).into_owned();
            for (p, _) in self.control_points.iter_mut().zip(w).filter(|(_, &w)| w == 0.0) {
                p.coords -= translation;
            }
        }
    }

    /// The homogeneous point `Sʷ(u, v) = Σ Nᵢ,ₚ(u) Nⱼ,q(v) Pᵢⱼʷ` (Piegl & Tiller
    /// Eq. 4.15 before the division, A4.3): finite everywhere, also where the surface
    /// is at infinity (zero weights); `w = 1` for a non-rational surface.
    pub fn eval_homogeneous(&self, u: f64, v: f64) -> nalgebra::Vector4<f64> {
        let (p, q) = (self.u_degree, self.v_degree);
        let (uk, vk) = (self.u_knots.as_slice(), self.v_knots.as_slice());
        let su = crate::knots::find_span(uk, p, u);
        let sv = crate::knots::find_span(vk, q, v);
        let nu = crate::basis::basis_funs(&self.u_knots, p, u);
        let nv = crate::basis::basis_funs(&self.v_knots, q, v);
        let w = self.weights.as_deref();
        let mut acc = Hom::zeros();
        for (k, &a) in nu.iter().enumerate() {
            for (l, &b) in nv.iter().enumerate() {
                let idx = (su - p + k) * self.n_v + sv - q + l;
                acc += hom_of(&self.control_points[idx], w.map_or(1.0, |w| w[idx])) * (a * b);
            }
        }
        acc
    }

    /// The point `S(u, v)`, refused where the surface is at infinity.
    ///
    /// # Errors
    ///
    /// [`Error::SurfaceAtInfinity`] where the homogeneous weight is zero (only possible
    /// with zero weights).
    pub fn try_eval(&self, u: f64, v: f64) -> Result<Point3<f64>> {
        let h = self.eval_homogeneous(u, v);
        if h.w == 0.0 {
            return Err(Error::SurfaceAtInfinity { u, v });
        }
        Ok(Point3::from(h.xyz() / h.w))
    }

    /// A copy with the affine map `m` applied; see [`transform_by`](Self::transform_by).
    pub fn transformed(&self, m: &nalgebra::Matrix4<f64>) -> Self {
        let mut c = self.clone();
        c.transform_by(m);
        c
    }

    /// Degree in u.
    pub fn u_degree(&self) -> usize {
        self.u_degree
    }
    /// Degree in v.
    pub fn v_degree(&self) -> usize {
        self.v_degree
    }
    /// Knot vector in u.
    pub fn u_knots(&self) -> &KnotVector {
        &self.u_knots
    }
    /// Knot vector in v.
    pub fn v_knots(&self) -> &KnotVector {
        &self.v_knots
    }
    /// Number of control points along u (rows of the net).
    pub fn n_u(&self) -> usize {
        self.n_u
    }
    /// Number of control points along v (columns of the net).
    pub fn n_v(&self) -> usize {
        self.n_v
    }
    /// The control net row by row (`i * n_v + j`), Cartesian.
    pub fn control_points(&self) -> &[Point3<f64>] {
        &self.control_points
    }
    /// The largest distance of a control point from the origin: the size of the model the
    /// surface belongs to, which tolerances on it are taken relative to. It bounds the
    /// distance of every point of the surface from the origin (convex hull).
    pub fn control_extent(&self) -> f64 {
        self.control_points.iter().map(|p| p.coords.norm()).fold(0.0, f64::max)
    }
    /// Mutable control net: a deformation moves these and keeps the weights.
    pub fn control_points_mut(&mut self) -> &mut [Point3<f64>] {
        &mut self.control_points
    }
    /// The control point `Pᵢⱼ`.
    pub fn control_point(&self, i: usize, j: usize) -> Point3<f64> {
        self.control_points[i * self.n_v + j]
    }
    /// The weights (same layout), `None` when not rational.
    pub fn weights(&self) -> Option<&[f64]> {
        self.weights.as_deref()
    }
    /// Whether the surface has weights.
    pub fn is_rational(&self) -> bool {
        self.weights.is_some()
    }

    pub(crate) fn homogeneous(&self) -> Vec<Hom> {
        to_hom(&self.control_points, self.weights.as_deref())
    }

    /// Columns of the homogeneous net: `cols[j][i] = Pwᵢⱼ` (curves in u).
    pub(crate) fn u_rows(&self) -> Vec<Vec<Hom>> {
        let pw = self.homogeneous();
        (0..self.n_v).map(|j| (0..self.n_u).map(|i| pw[i * self.n_v + j]).collect()).collect()
    }

    /// Rows of the homogeneous net: `rows[i][j] = Pwᵢⱼ` (curves in v).
    pub(crate) fn v_rows(&self) -> Vec<Vec<Hom>> {
        let pw = self.homogeneous();
        pw.chunks(self.n_v).map(<[Hom]>::to_vec).collect()
    }

    pub(crate) fn with_u_rows(&self, u_degree: usize, u_knots: Vec<f64>, cols: &[Vec<Hom>]) -> Self {
        let n_u = cols[0].len();
        let mut pw = vec![Hom::zeros(); n_u * self.n_v];
        for (j, col) in cols.iter().enumerate() {
            for (i, h) in col.iter().enumerate() {
                pw[i * self.n_v + j] = *h;
            }
        }
        Self::from_parts(
            (u_degree, self.v_degree),
            (u_knots, self.v_knots.as_slice().to_vec()),
            (n_u, self.n_v),
            &pw,
            self.is_rational(),
        )
    }

    fn with_v_rows(&self, v_degree: usize, v_knots: Vec<f64>, rows: &[Vec<Hom>]) -> Self {
        let n_v = rows[0].len();
        let pw: Vec<Hom> = rows.iter().flatten().copied().collect();
        Self::from_parts(
            (self.u_degree, v_degree),
            (self.u_knots.as_slice().to_vec(), v_knots),
            (self.n_u, n_v),
            &pw,
            self.is_rational(),
        )
    }

    /// Applies a knot-vector operation `f(knots, row) -> (knots', row')` to every curve of
    /// the net in u (the columns), all of which share the u knots, and reassembles the
    /// surface with degree `p`.
    fn map_u_rows(&self, p: usize, f: impl Fn(&[f64], &[Hom]) -> (Vec<f64>, Vec<Hom>)) -> Self {
        let mut knots = Vec::new();
        let cols: Vec<Vec<Hom>> = self
            .u_rows()
            .iter()
            .map(|c| {
                let (k, q) = f(self.u_knots.as_slice(), c);
                knots = k;
                q
            })
            .collect();
        self.with_u_rows(p, knots, &cols)
    }

    /// [`map_u_rows`](Self::map_u_rows) in v: `f` runs on every row of the net.
    fn map_v_rows(&self, q: usize, f: impl Fn(&[f64], &[Hom]) -> (Vec<f64>, Vec<Hom>)) -> Self {
        let mut knots = Vec::new();
        let rows: Vec<Vec<Hom>> = self
            .v_rows()
            .iter()
            .map(|r| {
                let (k, h) = f(self.v_knots.as_slice(), r);
                knots = k;
                h
            })
            .collect();
        self.with_v_rows(q, knots, &rows)
    }

    /// The same surface with clamped knot vectors in both directions (exact; a clamped
    /// surface comes back unchanged).
    pub fn clamped(&self) -> Self {
        let (p, q) = (self.u_degree, self.v_degree);
        let mut c = self.clone();
        if !c.u_knots.is_clamped(p) {
            c = c.map_u_rows(p, |k, h| clamp_hom(p, k, h));
        }
        if !c.v_knots.is_clamped(q) {
            c = c.map_v_rows(q, |k, h| clamp_hom(q, k, h));
        }
        c
    }

    /// The same surface with u and v exchanged: `t.eval(v, u) == s.eval(u, v)`.
    pub fn transposed(&self) -> Self {
        let mut pts = Vec::with_capacity(self.control_points.len());
        let mut w = self.weights.as_ref().map(|_| Vec::with_capacity(self.control_points.len()));
        for j in 0..self.n_v {
            for i in 0..self.n_u {
                pts.push(self.control_points[i * self.n_v + j]);
                if let (Some(w), Some(sw)) = (&mut w, &self.weights) {
                    w.push(sw[i * self.n_v + j]);
                }
            }
        }
        Self {
            u_degree: self.v_degree,
            v_degree: self.u_degree,
            u_knots: self.v_knots.clone(),
            v_knots: self.u_knots.clone(),
            n_u: self.n_v,
            n_v: self.n_u,
            control_points: pts,
            weights: w,
            u_inv: self.v_inv.clone(),
            v_inv: self.u_inv.clone(),
            infinite: self.infinite,
        }
    }

    /// Inserts the knot `u` `times` times in the u direction (A5.1 per column);
    /// returns the copies actually inserted. As for [`NurbsCurve::insert_knot`], the
    /// multiplicity is capped at `p + 1` strictly inside the domain (the surface then
    /// splits into two patches joined only by position along `u`) and `p` on its ends.
    ///
    /// # Errors
    ///
    /// [`Error::OutsideDomain`].
    pub fn insert_u_knot(&mut self, u: f64, times: usize) -> Result<usize> {
        check_in(&self.u_knots, self.u_degree, u)?;
        let p = self.u_degree;
        let (k, s) = algo::insertion_span(self.u_knots.as_slice(), u);
        let r = times.min(max_insertion(self.u_knots.domain(p), p, u).saturating_sub(s));
        if r == 0 {
            return Ok(0);
        }
        *self = self.map_u_rows(p, |knots, c| algo::insert_knot_full(p, knots, c, u, k, s, r));
        Ok(r)
    }

    /// Inserts the knot `v` `times` times in the v direction; see
    /// [`insert_u_knot`](Self::insert_u_knot).
    ///
    /// # Errors
    ///
    /// [`Error::OutsideDomain`].
    pub fn insert_v_knot(&mut self, v: f64, times: usize) -> Result<usize> {
        let mut t = self.transposed();
        let r = t.insert_u_knot(v, times)?;
        *self = t.transposed();
        Ok(r)
    }

    /// Knot refinement in u (Piegl & Tiller A5.5, u direction): inserts every value of
    /// `x` at once.
    ///
    /// # Errors
    ///
    /// As [`NurbsCurve::refine`].
    pub fn refine_u(&mut self, x: &[f64]) -> Result<()> {
        let x = prepare_refinement(&self.u_knots, self.u_degree, x)?;
        if x.is_empty() {
            return Ok(());
        }
        let (n_u, n_v) = (self.n_u, self.n_v);
        let (ub, steps) = algo::refine_plan(self.u_degree, self.u_knots.as_slice(), n_u - 1, &x);
        let (old, d) = self.flat();
        // Block i of the plan is the whole row i of the net: every column at once.
        let width = n_v * d;
        let mut new = vec![0.0; (n_u + x.len()) * width];
        algo::run_plan(&steps, &old, &mut new, width);
        self.set_flat((ub, self.v_knots.as_slice().to_vec()), (n_u + x.len(), n_v), &new, d);
        Ok(())
    }

    /// The net as flat values, point after point in storage order: `x y z` (weight 1,
    /// `d = 3`) or homogeneous `xw yw zw w` (`d = 4`).
    fn flat(&self) -> (Vec<f64>, usize) {
        match &self.weights {
            None => (self.control_points.iter().flat_map(|p| [p.x, p.y, p.z]).collect(), 3),
            Some(_) => (self.homogeneous().iter().flat_map(|h| h.iter().copied()).collect(), 4),
        }
    }

    /// Replaces knots and net by flat values as [`flat`](Self::flat) gives them.
    fn set_flat(&mut self, knots: (Vec<f64>, Vec<f64>), size: (usize, usize), flat: &[f64], d: usize) {
        self.set_flat_at(knots, size, flat, d, |k| k * d);
    }

    /// [`set_flat`](Self::set_flat) with control point `k` (storage order) at
    /// `flat[at(k)..at(k) + d]`.
    fn set_flat_at(
        &mut self,
        knots: (Vec<f64>, Vec<f64>),
        size: (usize, usize),
        flat: &[f64],
        d: usize,
        at: impl Fn(usize) -> usize,
    ) {
        let degrees = (self.u_degree, self.v_degree);
        let n = size.0 * size.1;
        *self = if d == 3 {
            let points = (0..n)
                .map(|k| {
                    let c = &flat[at(k)..at(k) + 3];
                    Point3::new(c[0], c[1], c[2])
                })
                .collect();
            Self {
                u_degree: degrees.0,
                v_degree: degrees.1,
                infinite: false,
                u_inv: inverse_denominators(&knots.0, degrees.0),
                v_inv: inverse_denominators(&knots.1, degrees.1),
                u_knots: KnotVector::new_unchecked(knots.0),
                v_knots: KnotVector::new_unchecked(knots.1),
                n_u: size.0,
                n_v: size.1,
                control_points: points,
                weights: None,
            }
        } else {
            let pw: Vec<Hom> = (0..n)
                .map(|k| {
                    let c = &flat[at(k)..at(k) + 4];
                    Hom::new(c[0], c[1], c[2], c[3])
                })
                .collect();
            Self::from_parts(degrees, knots, size, &pw, true)
        };
    }

    /// Knot refinement in v (Piegl & Tiller A5.5, v direction).
    ///
    /// # Errors
    ///
    /// As [`NurbsCurve::refine`].
    pub fn refine_v(&mut self, x: &[f64]) -> Result<()> {
        let x = prepare_refinement(&self.v_knots, self.v_degree, x)?;
        if x.is_empty() {
            return Ok(());
        }
        let (n_u, n_v) = (self.n_u, self.n_v);
        let (vb, steps) = algo::refine_plan(self.v_degree, self.v_knots.as_slice(), n_v - 1, &x);
        let n_new = n_v + x.len();
        let (old, d) = self.flat();
        // The plan runs on groups of rows gathered column by column (block j of the
        // plan = column j of the group's rows, all at once), in small buffers that stay
        // in cache; each group goes straight to the new net.
        const GROUP: usize = 16;
        let mut points: Vec<Point3<f64>> = Vec::with_capacity(if d == 3 { n_u * n_new } else { 0 });
        let mut hom: Vec<Hom> = Vec::with_capacity(if d == 4 { n_u * n_new } else { 0 });
        let mut g_old = vec![0.0; n_v * GROUP * d];
        let mut g_new = vec![0.0; n_new * GROUP * d];
        for i0 in (0..n_u).step_by(GROUP) {
            let g = GROUP.min(n_u - i0);
            let width = g * d;
            for j in 0..n_v {
                for r in 0..g {
                    let src = ((i0 + r) * n_v + j) * d;
                    g_old[j * width + r * d..j * width + (r + 1) * d].copy_from_slice(&old[src..src + d]);
                }
            }
            algo::run_plan(&steps, &g_old[..n_v * width], &mut g_new[..n_new * width], width);
            // The group's rows, in storage order: appended.
            for r in 0..g {
                for j in 0..n_new {
                    let c = &g_new[j * width + r * d..j * width + (r + 1) * d];
                    if d == 3 {
                        points.push(Point3::new(c[0], c[1], c[2]));
                    } else {
                        hom.push(Hom::new(c[0], c[1], c[2], c[3]));
                    }
                }
            }
        }
        let knots = (self.u_knots.as_slice().to_vec(), vb);
        if d == 3 {
            self.v_inv = inverse_denominators(&knots.1, self.v_degree);
            self.v_knots = KnotVector::new_unchecked(knots.1);
            self.n_v = n_new;
            self.control_points = points;
        } else {
            *self = Self::from_parts((self.u_degree, self.v_degree), knots, (n_u, n_new), &hom, true);
        }
        Ok(())
    }

    /// Removes the u knot `u` up to `times` times while no point of the surface moves
    /// more than `tol` (A5.8 applied to all columns together). Returns the copies removed.
    pub fn remove_u_knot(&mut self, u: f64, times: usize, tol: f64) -> usize {
        let p = self.u_degree;
        let ks = self.u_knots.as_slice();
        let Some(r) = ks.iter().rposition(|&k| k == u) else { return 0 };
        let s = ks[..=r].iter().rev().take_while(|&&k| k == u).count();
        if r <= p || r + p + 1 >= ks.len() || r < p + s - 1 || ks[r - s + 1] <= ks[p] {
            return 0;
        }
        let tol = homogeneous_tol(tol, &self.control_points, self.weights.as_deref());
        let mut knots = ks.to_vec();
        let mut cols = self.u_rows();
        let t = algo::remove_knot(p, &mut knots, &mut cols, r, s, times.min(s), tol);
        if t > 0 {
            *self = self.with_u_rows(p, knots, &cols);
        }
        t
    }

    /// Removes the v knot `v` up to `times` times within `tol`; see
    /// [`remove_u_knot`](Self::remove_u_knot).
    pub fn remove_v_knot(&mut self, v: f64, times: usize, tol: f64) -> usize {
        let mut t = self.transposed();
        let r = t.remove_u_knot(v, times, tol);
        if r > 0 {
            *self = t.transposed();
        }
        r
    }

    /// Raises the u degree by `t` (A5.9 on every column). The geometry does not
    /// change; an unclamped (periodic) u direction stays unclamped, as in
    /// [`NurbsCurve::elevate_degree`] (clamp, elevate, unclamp with A12.1).
    ///
    /// # Errors
    ///
    /// [`Error::Degree`] past [`MAX_DEGREE`].
    pub fn elevate_u_degree(&mut self, t: usize) -> Result<()> {
        if self.u_degree + t > MAX_DEGREE {
            return Err(Error::Degree { degree: self.u_degree + t });
        }
        let p = self.u_degree;
        let clamped = self.u_knots.is_clamped(p);
        *self = self.map_u_rows(p + t, |knots, c| {
            if clamped || t == 0 {
                algo::elevate_degree(p, knots, c, t)
            } else {
                crate::unclamp::elevate_unclamped(p, knots, c, t)
            }
        });
        Ok(())
    }

    /// Raises the v degree by `t`; see [`elevate_u_degree`](Self::elevate_u_degree).
    ///
    /// # Errors
    ///
    /// [`Error::Degree`] past [`MAX_DEGREE`].
    pub fn elevate_v_degree(&mut self, t: usize) -> Result<()> {
        let mut s = self.transposed();
        s.elevate_u_degree(t)?;
        *self = s.transposed();
        Ok(())
    }

    /// The Bézier patches of the surface (Piegl & Tiller A5.7, by refinement to full
    /// interior multiplicity in both directions): `patches[a][b]` covers the `a`-th
    /// non-empty u span and the `b`-th v span, with `(p + 1) × (q + 1)` control points.
    pub fn bezier_patches(&self) -> Vec<Vec<NurbsSurface>> {
        let full = |knots: &KnotVector, p: usize| {
            let (values, mults) = knots.distinct();
            let mut x = Vec::new();
            for (&v, &m) in values[1..values.len() - 1].iter().zip(&mults[1..mults.len() - 1]) {
                x.extend(std::iter::repeat_n(v, p.saturating_sub(m)));
            }
            (values, x)
        };
        let mut c = self.clamped();
        let (p, q) = (c.u_degree, c.v_degree);
        let (uvals, xu) = full(&c.u_knots, p);
        let (vvals, xv) = full(&c.v_knots, q);
        c.refine_u(&xu).expect("interior knots raised to the degree");
        c.refine_v(&xv).expect("interior knots raised to the degree");
        let pw = c.homogeneous();
        let u_starts = algo::bezier_starts(p, c.u_knots.as_slice(), &uvals);
        let v_starts = algo::bezier_starts(q, c.v_knots.as_slice(), &vvals);
        let bez = |a: f64, b: f64, d: usize| {
            let mut k = vec![a; d + 1];
            k.extend(std::iter::repeat_n(b, d + 1));
            k
        };
        uvals
            .windows(2)
            .zip(&u_starts)
            .map(|(uw, &a)| {
                vvals
                    .windows(2)
                    .zip(&v_starts)
                    .map(|(vw, &b)| {
                        let mut net = Vec::with_capacity((p + 1) * (q + 1));
                        for i in a..=a + p {
                            for j in b..=b + q {
                                net.push(pw[i * c.n_v + j]);
                            }
                        }
                        Self::from_parts(
                            (p, q),
                            (bez(uw[0], uw[1], p), bez(vw[0], vw[1], q)),
                            (p + 1, q + 1),
                            &net,
                            c.is_rational(),
                        )
                    })
                    .collect()
            })
            .collect()
    }

    /// Splits at `u = t` into the patches on `[u₀, t]` and `[t, u₁]`.
    ///
    /// # Errors
    ///
    /// [`Error::OutsideDomain`] unless `t` is strictly inside the u domain.
    pub fn split_u(&self, t: f64) -> Result<(Self, Self)> {
        let d = self.u_knots.domain(self.u_degree);
        if !(t > *d.start() && t < *d.end()) {
            return Err(Error::OutsideDomain { value: t, start: *d.start(), end: *d.end() });
        }
        // Split each column as a curve; all columns share the knot vector.
        let p = self.u_degree;
        let mut lk = Vec::new();
        let mut rk = Vec::new();
        let mut lc = Vec::new();
        let mut rc = Vec::new();
        for col in self.u_rows() {
            let (ck, cp) = clamp_hom(p, self.u_knots.as_slice(), &col);
            let c = NurbsCurve::from_parts(p, ck, &cp, true);
            let (l, r) = c.split(t)?;
            lk = l.knots().as_slice().to_vec();
            rk = r.knots().as_slice().to_vec();
            lc.push(l.homogeneous());
            rc.push(r.homogeneous());
        }
        Ok((self.with_u_rows(p, lk, &lc), self.with_u_rows(p, rk, &rc)))
    }

    /// The same surface, closed in u, with its seam moved to `u = c`: the domain becomes
    /// `[c, c + L]` (`L` the u period, `u₁ − u₀`) and `r.eval(u, v) == s.eval(u', v)`
    /// for `u' ≡ u (mod L)` in the old domain. A face whose trimming loops cross the old
    /// seam lies inside the new domain when `c` is outside it.
    ///
    /// Made by splitting at `c` ([`split_u`](Self::split_u), Piegl & Tiller A5.3 to full
    /// multiplicity) and joining the piece `[c, u₁]` to the piece `[u₀, c]` shifted by
    /// `L`; the old seam becomes an interior knot of multiplicity `p` (C0 in the
    /// parameter, as the join of two clamped pieces is). The homogeneous seam rows must
    /// agree up to one common factor (a rational piece scaled by a constant is the same
    /// surface), their points within `tol`. `c` within `1e-12 L` of the seam returns the
    /// surface as it is.
    ///
    /// # Errors
    ///
    /// [`Error::Periodic`] when the surface does not close in u (its first and last
    /// iso-lines differ by more than `tol`, or their weights by more than a common
    /// factor); [`Error::NotFinite`] for a non-finite `c`.
    pub fn reseamed_u(&self, c: f64, tol: f64) -> Result<Self> {
        if !c.is_finite() {
            return Err(Error::NotFinite { what: "seam parameter", index: 0, value: c });
        }
        let d = self.u_knots.domain(self.u_degree);
        let (u0, u1) = (*d.start(), *d.end());
        let period = u1 - u0;
        let c = u0 + (c - u0).rem_euclid(period);
        if c - u0 <= 1e-12 * period || u1 - c <= 1e-12 * period {
            return Ok(self.clone());
        }
        let (a, b) = self.split_u(c)?;
        let (ra, rb) = (a.u_rows(), b.u_rows());
        // The common factor of the seam's homogeneous rows: b ends where a starts.
        let not_closed =
            || Error::Periodic { reason: "the surface does not close in u (first and last iso-lines differ)" };
        let ratio = ra[0][0][3] / rb[0][rb[0].len() - 1][3];
        for (ca, cb) in ra.iter().zip(&rb) {
            let (ha, hb) = (ca[0], cb[cb.len() - 1]);
            let (pa, pb) = (ha.xyz() / ha[3], hb.xyz() / hb[3]);
            let same = (pa - pb).norm() <= tol && (ha[3] / hb[3] - ratio).abs() <= 1e-12 * ratio.abs();
            if !same {
                return Err(not_closed());
            }
        }
        let (ka, kb) = (a.u_knots.as_slice(), b.u_knots.as_slice());
        let p = self.u_degree;
        let mut knots: Vec<f64> = kb[..kb.len() - 1].to_vec();
        knots.extend(ka[p + 1..].iter().map(|k| k + period));
        let rows: Vec<Vec<Hom>> = rb
            .iter()
            .zip(&ra)
            .map(|(cb, ca)| cb.iter().copied().chain(ca[1..].iter().map(|h| h / ratio)).collect())
            .collect();
        Ok(self.with_u_rows(p, knots, &rows))
    }

    /// [`reseamed_u`](Self::reseamed_u) in v.
    ///
    /// # Errors
    ///
    /// As [`reseamed_u`](Self::reseamed_u), for v.
    pub fn reseamed_v(&self, c: f64, tol: f64) -> Result<Self> {
        Ok(self.transposed().reseamed_u(c, tol)?.transposed())
    }

    /// Splits at `v = t`; see [`split_u`](Self::split_u).
    ///
    /// # Errors
    ///
    /// [`Error::OutsideDomain`] unless `t` is strictly inside the v domain.
    pub fn split_v(&self, t: f64) -> Result<(Self, Self)> {
        let (a, b) = self.transposed().split_u(t)?;
        Ok((a.transposed(), b.transposed()))
    }

    /// The same surface with u running the other way: `r.eval(u₀ + u₁ − u, v) == s.eval(u, v)`.
    pub fn u_reversed(&self) -> Self {
        let mut s = self.clone();
        s.u_knots = self.u_knots.reversed();
        s.u_inv = inverse_denominators(s.u_knots.as_slice(), s.u_degree);
        let n_v = self.n_v;
        s.control_points =
            (0..self.n_u).rev().flat_map(|i| self.control_points[i * n_v..(i + 1) * n_v].iter().copied()).collect();
        if let Some(w) = &self.weights {
            s.weights = Some((0..self.n_u).rev().flat_map(|i| w[i * n_v..(i + 1) * n_v].iter().copied()).collect());
        }
        s
    }

    /// The same surface with v running the other way.
    pub fn v_reversed(&self) -> Self {
        self.transposed().u_reversed().transposed()
    }

    /// The iso-parametric curve `v ↦ S(u, v)` as an exact NURBS curve (degree q, the v knots).
    pub fn u_iso(&self, u: f64) -> NurbsCurve {
        let p = self.u_degree;
        let ks = self.u_knots.as_slice();
        let span = crate::knots::find_span(ks, p, u);
        let mut n = vec![0.0; p + 1];
        let (mut l, mut r) = (vec![0.0; p + 1], vec![0.0; p + 1]);
        basis_funs_into(ks, span, u, p, &mut n, &mut l, &mut r);
        let pw = self.homogeneous();
        let q: Vec<Hom> =
            (0..self.n_v).map(|j| (0..=p).map(|k| pw[(span - p + k) * self.n_v + j] * n[k]).sum()).collect();
        NurbsCurve::from_parts(self.v_degree, self.v_knots.as_slice().to_vec(), &q, self.is_rational())
    }

    /// The iso-parametric curve `u ↦ S(u, v)` as an exact NURBS curve (degree p, the u knots).
    pub fn v_iso(&self, v: f64) -> NurbsCurve {
        self.transposed().u_iso(v)
    }

    /// The boundary curve on one side of the parameter rectangle, running in the
    /// direction of increasing parameter.
    pub fn boundary(&self, side: Side) -> NurbsCurve {
        let (ud, vd) = self.domain();
        match side {
            Side::UMin => self.u_iso(*ud.start()),
            Side::UMax => self.u_iso(*ud.end()),
            Side::VMin => self.v_iso(*vd.start()),
            Side::VMax => self.v_iso(*vd.end()),
        }
    }

    /// Point and first partial derivatives, with stack buffers (the hot path of
    /// normals, projection and seam sampling).
    ///
    /// On x86-64 CPUs with AVX2 and FMA (checked at run time) the tensor contraction
    /// runs on packed 4-lane vectors, one control point per vector; elsewhere on the
    /// scalar path, which computes the same values up to the rounding of the fused
    /// multiply-adds.
    pub fn eval_d1(&self, u: f64, v: f64) -> SurfacePointD1 {
        #[cfg(target_arch = "x86_64")]
        if !self.infinite {
            if let Some(simd) = pulp::x86::V3::try_new() {
                let (s, p, q) = (self, self.u_degree, self.v_degree);
                return match p.max(q) {
                    _ if (p, q) == (3, 3) => {
                        pulp::Simd::vectorize(simd, v3::D1::<4, 3> { simd, surface: s, u, v, p, q })
                    }
                    0..=3 => pulp::Simd::vectorize(simd, v3::D1::<4, 0> { simd, surface: s, u, v, p, q }),
                    4..=7 => pulp::Simd::vectorize(simd, v3::D1::<8, 0> { simd, surface: s, u, v, p, q }),
                    8..=15 => pulp::Simd::vectorize(simd, v3::D1::<16, 0> { simd, surface: s, u, v, p, q }),
                    _ => self.eval_d1_scalar(u, v),
                };
            }
        }
        self.eval_d1_scalar(u, v)
    }

    /// [`eval_d1`](Self::eval_d1) on scalar code only (the fallback of the SIMD path, and
    /// its reference in the tests).
    pub(crate) fn eval_d1_scalar(&self, u: f64, v: f64) -> SurfacePointD1 {
        let (p, q) = (self.u_degree, self.v_degree);
        match p.max(q) {
            _ if self.infinite => self.eval_d1_infinite(u, v),
            _ if (p, q) == (3, 3) => self.eval_d1_n::<4>(u, v, 3, 3),
            0..=3 => self.eval_d1_n::<4>(u, v, p, q),
            4..=7 => self.eval_d1_n::<8>(u, v, p, q),
            8..=15 => self.eval_d1_n::<16>(u, v, p, q),
            _ => {
                let d = self.derivs_general(u, v, 1);
                SurfacePointD1 { point: d.point(), du: d[(1, 0)], dv: d[(0, 1)] }
            }
        }
    }

    /// [`eval_d1`](Self::eval_d1) with basis buffers of `N > max(p, q)` entries on the stack.
    #[inline(always)]
    fn eval_d1_n<const N: usize>(&self, u: f64, v: f64, p: usize, q: usize) -> SurfacePointD1 {
        let uk = self.u_knots.as_slice();
        let vk = self.v_knots.as_slice();
        let su = crate::knots::find_span(uk, p, u);
        let sv = crate::knots::find_span(vk, q, v);
        let ((nu, dnu), (nv, dnv)) = basis_d1_pair::<N>(self, (su, sv), (u, v), (p, q));
        let (i0, j0) = (su - p, sv - q);
        match &self.weights {
            None => {
                let mut s = Vector3::zeros();
                let mut su_ = Vector3::zeros();
                let mut sv_ = Vector3::zeros();
                for k in 0..=p {
                    let row = &self.control_points[(i0 + k) * self.n_v + j0..];
                    let mut t0 = Vector3::zeros();
                    let mut t1 = Vector3::zeros();
                    for l in 0..=q {
                        let c = row[l].coords;
                        t0 += c * nv[l];
                        t1 += c * dnv[l];
                    }
                    s += t0 * nu[k];
                    su_ += t0 * dnu[k];
                    sv_ += t1 * nu[k];
                }
                SurfacePointD1 { point: Point3::from(s), du: su_, dv: sv_ }
            }
            Some(w) => {
                let mut s = Hom::zeros();
                let mut su_ = Hom::zeros();
                let mut sv_ = Hom::zeros();
                for k in 0..=p {
                    let base = (i0 + k) * self.n_v + j0;
                    let mut t0 = Hom::zeros();
                    let mut t1 = Hom::zeros();
                    for l in 0..=q {
                        let c = self.control_points[base + l];
                        let wi = w[base + l];
                        let h = Hom::new(c.x * wi, c.y * wi, c.z * wi, wi);
                        t0 += h * nv[l];
                        t1 += h * dnv[l];
                    }
                    s += t0 * nu[k];
                    su_ += t0 * dnu[k];
                    sv_ += t1 * nu[k];
                }
                let pt = s.xyz() / s.w;
                SurfacePointD1 {
                    point: Point3::from(pt),
                    du: (su_.xyz() - pt * su_.w) / s.w,
                    dv: (sv_.xyz() - pt * sv_.w) / s.w,
                }
            }
        }
    }

    /// [`eval_d1`](Self::eval_d1) with control points at infinity: the general
    /// homogeneous path, kept out of line so that the fast paths stay small.
    #[cold]
    #[inline(never)]
    fn eval_d1_infinite(&self, u: f64, v: f64) -> SurfacePointD1 {
        let d = self.derivs_general(u, v, 1);
        SurfacePointD1 { point: d.point(), du: d[(1, 0)], dv: d[(0, 1)] }
    }

    /// `eval` with control points at infinity; see [`eval_d1_infinite`](Self::eval_d1_infinite).
    #[cold]
    #[inline(never)]
    fn eval_infinite(&self, u: f64, v: f64) -> Point3<f64> {
        self.derivs_general(u, v, 0).point()
    }

    /// A3.6 + A4.4 with heap buffers, any order.
    fn derivs_general(&self, u: f64, v: f64, n: usize) -> SurfaceDerivs {
        let (p, q) = (self.u_degree, self.v_degree);
        let uk = self.u_knots.as_slice();
        let vk = self.v_knots.as_slice();
        let su = crate::knots::find_span(uk, p, u);
        let sv = crate::knots::find_span(vk, q, v);
        let mut nu = vec![vec![0.0; p + 1]; n + 1];
        let mut nv = vec![vec![0.0; q + 1]; n + 1];
        ders_basis_funs_into(uk, su, u, p, n, &mut nu);
        ders_basis_funs_into(vk, sv, v, q, n, &mut nv);
        let w = self.weights.as_deref();
        let hom = |i: usize, j: usize| {
            let wi = w.map_or(1.0, |w| w[i * self.n_v + j]);
            hom_of(&self.control_points[i * self.n_v + j], wi)
        };
        let dim = n + 1;
        let mut h = vec![Hom::zeros(); dim * dim];
        let mut temp = vec![Hom::zeros(); q + 1];
        for k in 0..=n {
            for (s, t) in temp.iter_mut().enumerate() {
                *t = (0..=p).map(|r| hom(su - p + r, sv - q + s) * nu[k][r]).sum();
            }
            for l in 0..=n - k {
                h[k * dim + l] = (0..=q).map(|s| temp[s] * nv[l][s]).sum();
            }
        }
        // A4.4: Cartesian derivatives from homogeneous ones.
        let mut d = vec![Vector3::zeros(); dim * dim];
        for k in 0..=n {
            for l in 0..=n - k {
                let mut v = h[k * dim + l].xyz();
                for j in 1..=l {
                    v -= d[k * dim + l - j] * (binomial(l, j) * h[j].w);
                }
                for i in 1..=k {
                    v -= d[(k - i) * dim + l] * (binomial(k, i) * h[i * dim].w);
                    let mut v2 = Vector3::zeros();
                    for j in 1..=l {
                        v2 += d[(k - i) * dim + l - j] * (binomial(l, j) * h[i * dim + j].w);
                    }
                    v -= v2 * binomial(k, i);
                }
                d[k * dim + l] = v / h[0].w;
            }
        }
        SurfaceDerivs { order: n, d }
    }
}

/// Basis functions and first derivatives in fixed-size buffers (degree < N), division-free
/// with the reciprocals of [`inverse_denominators`]. The derivative is A2.3's first-order
/// formula `N'ᵢ,ₚ = p (Nᵢ,ₚ₋₁ / (uᵢ₊ₚ − uᵢ) − Nᵢ₊₁,ₚ₋₁ / (uᵢ₊ₚ₊₁ − uᵢ₊₁))`, whose
/// denominators are the last level of A2.2's.
#[inline(always)]
fn basis_d1<const N: usize>(knots: &[f64], inv: &[f64], span: usize, u: f64, p: usize) -> ([f64; N], [f64; N]) {
    let per = p * (p + 1) / 2;
    let inv = &inv[span * per..span * per + per];
    let mut n = [0.0; N];
    let mut left = [0.0; N];
    let mut right = [0.0; N];
    let mut d = [0.0; N];
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let row = j * (j - 1) / 2;
        if j == p {
            // n[0..p] holds the degree p-1 functions N_{span-p+1..=span, p-1}.
            let pf = p as f64;
            for r in 0..=p {
                let a = if r >= 1 { n[r - 1] * inv[row + r - 1] } else { 0.0 };
                let b = if r < p { n[r] * inv[row + r] } else { 0.0 };
                d[r] = pf * (a - b);
            }
        }
        let mut saved = 0.0;
        for r in 0..j {
            let temp = n[r] * inv[row + r];
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    (n, d)
}

/// The non-zero basis functions of one direction and their first derivatives.
type BasisD1<const N: usize> = ([f64; N], [f64; N]);

/// The basis functions and first derivatives of both directions at the spans `(su, sv)`:
/// [`basis_d1_cubic`] when both degrees are 3 (a constant after inlining for the bicubic
/// call sites), [`basis_d1`] otherwise.
#[inline(always)]
fn basis_d1_pair<const N: usize>(
    s: &NurbsSurface,
    (su, sv): (usize, usize),
    (u, v): (f64, f64),
    (p, q): (usize, usize),
) -> (BasisD1<N>, BasisD1<N>) {
    let (uk, vk) = (s.u_knots.as_slice(), s.v_knots.as_slice());
    if (p, q) == (3, 3) && N >= 4 {
        let (nu, dnu) = basis_d1_cubic(uk, &s.u_inv, su, u);
        let (nv, dnv) = basis_d1_cubic(vk, &s.v_inv, sv, v);
        ((pad(nu), pad(dnu)), (pad(nv), pad(dnv)))
    } else {
        (basis_d1::<N>(uk, &s.u_inv, su, u, p), basis_d1::<N>(vk, &s.v_inv, sv, v, q))
    }
}

/// `a` in an array of `N ≥ 4` entries (the rest zero); the identity for `N = 4`.
#[inline(always)]
fn pad<const N: usize>(a: [f64; 4]) -> [f64; N] {
    let mut out = [0.0; N];
    out[..4].copy_from_slice(&a);
    out
}

/// [`basis_d1`] for degree 3, unrolled with named temporaries so that everything stays in
/// registers (the array form is stored and reloaded through the stack). The same products
/// in the same order as [`basis_d1`], so the same values bit for bit; the derivative
/// reuses A2.2's last-level quotients: `N'ᵣ = 3 (tᵣ₋₁ − tᵣ)` with `tᵣ = Nᵣ,₂ / (u_{r+3} − u_r)`
/// (shifted to the span), `t₋₁ = t₃ = 0`.
#[inline(always)]
pub(crate) fn basis_d1_cubic(knots: &[f64], inv: &[f64], span: usize, u: f64) -> ([f64; 4], [f64; 4]) {
    let inv: &[f64; 6] = inv[span * 6..span * 6 + 6].try_into().expect("six reciprocals per span");
    let k: &[f64; 6] = knots[span - 2..span + 4].try_into().expect("six knots around the span");
    let (l1, l2, l3) = (u - k[2], u - k[1], u - k[0]);
    let (r1, r2, r3) = (k[3] - u, k[4] - u, k[5] - u);
    // Degree 1.
    let t = inv[0];
    let (a0, a1) = (r1 * t, l1 * t);
    // Degree 2.
    let t0 = a0 * inv[1];
    let b0 = r1 * t0;
    let s = l2 * t0;
    let t1 = a1 * inv[2];
    let b1 = s + r2 * t1;
    let b2 = l1 * t1;
    // Degree 3 and the derivatives.
    let t0 = b0 * inv[3];
    let t1 = b1 * inv[4];
    let t2 = b2 * inv[5];
    let n = [r1 * t0, l3 * t0 + r2 * t1, l2 * t1 + r3 * t2, l1 * t2];
    let d = [3.0 * (0.0 - t0), 3.0 * (t0 - t1), 3.0 * (t1 - t2), 3.0 * t2];
    (n, d)
}

impl NurbsSurface {
    /// `S(u, v)` with basis buffers of `N > max(p, q)` entries on the stack.
    /// `p` and `q` are passed in (equal to the degrees) so that the common bicubic
    /// case is compiled with constant loop bounds.
    #[inline(always)]
    fn eval_n<const N: usize>(&self, u: f64, v: f64, p: usize, q: usize) -> Point3<f64> {
        let uk = self.u_knots.as_slice();
        let vk = self.v_knots.as_slice();
        let su = crate::knots::find_span(uk, p, u);
        let sv = crate::knots::find_span(vk, q, v);
        let nu = basis_funs_inv::<N>(uk, &self.u_inv, su, u, p);
        let nv = basis_funs_inv::<N>(vk, &self.v_inv, sv, v, q);
        let (i0, j0) = (su - p, sv - q);
        match &self.weights {
            None => {
                let mut s = Vector3::zeros();
                for k in 0..=p {
                    let row = &self.control_points[(i0 + k) * self.n_v + j0..];
                    let mut t = Vector3::zeros();
                    for l in 0..=q {
                        t += row[l].coords * nv[l];
                    }
                    s += t * nu[k];
                }
                Point3::from(s)
            }
            Some(w) => {
                let mut s = Vector3::zeros();
                let mut ws = 0.0;
                for k in 0..=p {
                    let base = (i0 + k) * self.n_v + j0;
                    let mut t = Vector3::zeros();
                    let mut tw = 0.0;
                    for l in 0..=q {
                        let nw = nv[l] * w[base + l];
                        t += self.control_points[base + l].coords * nw;
                        tw += nw;
                    }
                    s += t * nu[k];
                    ws += tw * nu[k];
                }
                Point3::from(s / ws)
            }
        }
    }
}

fn check_in(knots: &KnotVector, p: usize, u: f64) -> Result<()> {
    let d = knots.domain(p);
    if !(u >= *d.start() && u <= *d.end()) {
        return Err(Error::OutsideDomain { value: u, start: *d.start(), end: *d.end() });
    }
    Ok(())
}

impl Surface for NurbsSurface {
    fn domain(&self) -> (RangeInclusive<f64>, RangeInclusive<f64>) {
        (self.u_knots.domain(self.u_degree), self.v_knots.domain(self.v_degree))
    }

    fn eval(&self, u: f64, v: f64) -> Point3<f64> {
        let (p, q) = (self.u_degree, self.v_degree);
        match p.max(q) {
            _ if self.infinite => self.eval_infinite(u, v),
            _ if (p, q) == (3, 3) => self.eval_n::<4>(u, v, 3, 3),
            0..=3 => self.eval_n::<4>(u, v, p, q),
            4..=7 => self.eval_n::<8>(u, v, p, q),
            8..=15 => self.eval_n::<16>(u, v, p, q),
            _ => self.derivs_general(u, v, 0).point(),
        }
    }

    fn derivs(&self, u: f64, v: f64, n: usize) -> SurfaceDerivs {
        self.derivs_general(u, v, n)
    }

    /// The unit normal `S_u × S_v`; at a degenerate point (a pole, a cone's apex: one
    /// partial vanishes, `|S_u| ≤ 1e-8 |S_v|` or the converse) its limit from inside the
    /// domain, `±S_uv × S_v` (or `±S_u × S_uv`): near a pole at `v₀`,
    /// `S_u(u, v) ≈ (v − v₀) S_uv`, the sign that of `v − v₀` on the domain's side.
    /// The cross product of a partial that is only rounding noise (1e-15 of the other)
    /// points anywhere in the tangent plane; the limit is what OCCT's `CSLib::Normal`
    /// takes from the higher derivatives there. `None` where both forms vanish.
    fn normal(&self, u: f64, v: f64) -> Option<Unit<Vector3<f64>>> {
        let d = self.eval_d1(u, v);
        let (nu, nv) = (d.du.norm(), d.dv.norm());
        if !(nu.is_finite() && nv.is_finite()) {
            return None;
        }
        let (du_pole, dv_pole) = (nu <= DEGENERATE * nv, nv <= DEGENERATE * nu);
        if du_pole != dv_pole {
            let (ud, vd) = self.domain();
            let inward = |x: f64, r: &RangeInclusive<f64>| if x - r.start() <= r.end() - x { 1.0 } else { -1.0 };
            let dd = self.derivs_general(u, v, 2);
            let n = if du_pole {
                dd[(1, 1)].cross(&dd[(0, 1)]) * inward(v, &vd)
            } else {
                dd[(1, 0)].cross(&dd[(1, 1)]) * inward(u, &ud)
            };
            let scale = dd[(1, 1)].norm() * nu.max(nv);
            return (n.norm() > 1e-12 * scale && scale > 0.0).then(|| Unit::new_normalize(n));
        }
        let n = d.du.cross(&d.dv);
        let scale = nu * nv;
        let m = n.norm();
        if m.is_nan() || m <= 1e-12 * scale || scale == 0.0 {
            return None;
        }
        Unit::try_new(n, 0.0)
    }
}

/// A partial derivative at most this fraction of the other is taken as vanishing
/// ([`NurbsSurface`]'s `normal`): the direct cross product's error is `ε / ρ` for the ratio
/// `ρ` of the two partials, the limit form's `O(ρ)`; they balance near `√ε ≈ 1e-8`.
const DEGENERATE: f64 = 1e-8;

/// Whether any weight is zero (a control point at infinity).
fn has_zero_weight(weights: Option<&[f64]>) -> bool {
    weights.is_some_and(|w| w.contains(&0.0))
}
