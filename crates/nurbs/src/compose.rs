//! Exact composition of curves and surfaces with a trivariate Bernstein (Bézier) volume:
//! the exact image of a NURBS patch under a free-form deformation (paper §2.1.1,
//! eq. (1)–(2)) whose lattice holds the patch.
//!
//! # The degree
//!
//! An FFD with an `(l+1) × (m+1) × (n+1)` lattice is, inside its box, the Bézier volume
//!
//! ```text
//! V(t) = Σᵢ Σⱼ Σₖ Bᵢˡ(t₁) Bⱼᵐ(t₂) Bₖⁿ(t₃) Qᵢⱼₖ,   t = ψ(x) = M (x − o)   (affine)
//! ```
//!
//! with `Qᵢⱼₖ` the displaced lattice nodes (Bernstein polynomials reproduce linear
//! functions, so `x + Σ b μ` is this sum over the moved nodes). For a rational patch
//! `S = A/W` of degree `(p, q)`, `ψ(S) = T/W` with `T = M(A − o W)` polynomial of
//! degree `(p, q)`, and
//!
//! ```text
//! Bᵢˡ(T₁/W) = C(l,i) T₁ⁱ (W − T₁)ˡ⁻ⁱ / Wˡ,
//! V(ψ(S)) = Σᵢⱼₖ C(l,i) C(m,j) C(n,k) T₁ⁱ(W−T₁)ˡ⁻ⁱ T₂ʲ(W−T₂)ᵐ⁻ʲ T₃ᵏ(W−T₃)ⁿ⁻ᵏ Qᵢⱼₖ / W^(l+m+n).
//! ```
//!
//! Numerator and denominator are polynomials of degree `p·(l+m+n)` in u and
//! `q·(l+m+n)` in v: the composed patch is rational of that degree with homogeneous
//! control points `(N, W^(l+m+n))`, and polynomial (weights 1) when `S` is. A curve of
//! degree `p` becomes one of degree `p·(l+m+n)`. This is the general degree; a patch
//! whose box coordinates do not all depend on a parameter can have a lower true degree,
//! which this module does not look for.
//!
//! # The algorithm
//!
//! Each Bézier piece (Piegl & Tiller A5.6/A5.7) is composed in the Bernstein basis:
//! products of Bernstein polynomials by the product rule of Farouki & Rajan (1988),
//! `(f·g)ᵢ = Σₐ C(p₁,a) C(p₂,i−a) / C(p₁+p₂,i) · fₐ gᵢ₋ₐ` (per direction), and the sum
//! over the lattice nested as `Σᵢ Pᵢ¹ (Σⱼ Pⱼ² (Σₖ Pₖ³ Qᵢⱼₖ))`. Every coefficient is a
//! convex-like combination of the inputs, so the composition is as well conditioned as
//! evaluation. The pieces are joined again with interior knots of multiplicity
//! `p·(l+m+n)` (C⁰ as a net); the continuity the patch had (C^k at a knot of
//! multiplicity `p − k`) is kept by the composition, and
//! [`NurbsSurface::remove_knots_within`] takes the surplus copies out.

use nalgebra::{Matrix3, Point3, Vector3};

use crate::algo::Hom;
use crate::curve::binomial;
use crate::{Error, NurbsCurve, NurbsSurface, Result, MAX_DEGREE};

/// A trivariate Bézier volume placed in model space: `V(ψ(x))` with
/// `ψ(x) = M (x − o)` mapping the model onto the unit cube `[0, 1]³` (paper eq. (1)).
///
/// This is an FFD's map inside its box: with `Qᵢⱼₖ` the moved lattice nodes
/// (`Ffd::control_points(true)` in `cadmorph-morph`), `M = diag(1/ℓ) Rᵀ` and `o` the box
/// origin, `V(ψ(x)) = φ(x)` for every `x` in the box.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::{BezierVolume, NurbsSurface, Surface};
/// use cadmorph_nurbs::math::{Matrix3, Point3};
/// // The identity lattice of the unit cube, corner (1, 1, 1) raised by 0.5 in z.
/// let mut q = Vec::new();
/// for i in 0..2 { for j in 0..2 { for k in 0..2 {
///     q.push(Point3::new(i as f64, j as f64, k as f64 + if i + j + k == 3 { 0.5 } else { 0.0 }));
/// } } }
/// let v = BezierVolume::try_new([1, 1, 1], q, Point3::origin(), Matrix3::identity())?;
/// let plane = NurbsSurface::bilinear([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0]]);
/// let s = plane.composed_with(&v)?;
/// assert_eq!((s.u_degree(), s.v_degree()), (3, 3)); // 1 · (1 + 1 + 1)
/// let (u, w) = (0.3, 0.8);
/// assert!((s.eval(u, w) - v.eval(&plane.eval(u, w))).norm() < 1e-14);
/// # Ok::<(), cadmorph_nurbs::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct BezierVolume {
    degrees: [usize; 3],
    /// `Qᵢⱼₖ` at `(i·(m+1) + j)·(n+1) + k`, as homogeneous points of weight 1.
    nodes: Vec<Hom>,
    origin: Point3<f64>,
    to_unit: Matrix3<f64>,
}

impl BezierVolume {
    /// A volume of degrees `[l, m, n]` with control points in C order
    /// (`(i·(m+1) + j)·(n+1) + k`), placed by `t = to_unit · (x − origin)`.
    ///
    /// # Errors
    ///
    /// [`Error::Degree`] for a degree of 0 or above [`MAX_DEGREE`]; [`Error::NetSize`] when
    /// the point count is not `(l+1)(m+1)(n+1)`; [`Error::NotFinite`] for a non-finite
    /// point, origin or map entry.
    pub fn try_new(
        degrees: [usize; 3],
        control_points: Vec<Point3<f64>>,
        origin: Point3<f64>,
        to_unit: Matrix3<f64>,
    ) -> Result<Self> {
        for &d in &degrees {
            if d == 0 || d > MAX_DEGREE {
                return Err(Error::Degree { degree: d });
            }
        }
        let [l, m, n] = degrees;
        let count = (l + 1) * (m + 1) * (n + 1);
        if control_points.len() != count {
            return Err(Error::NetSize { n_u: (l + 1) * (m + 1), n_v: n + 1, found: control_points.len() });
        }
        crate::curve::check_points(&control_points)?;
        for (index, &value) in origin.iter().chain(to_unit.iter()).enumerate() {
            if !value.is_finite() {
                return Err(Error::NotFinite { what: "volume placement entry", index, value });
            }
        }
        let nodes = control_points.iter().map(|p| Hom::new(p.x, p.y, p.z, 1.0)).collect();
        Ok(Self { degrees, nodes, origin, to_unit })
    }

    /// Degrees `[l, m, n]` (lattice size minus one per direction).
    pub fn degrees(&self) -> [usize; 3] {
        self.degrees
    }

    /// The control points `Qᵢⱼₖ` in C order (`(i·(m+1) + j)·(n+1) + k`).
    pub fn control_points(&self) -> Vec<Point3<f64>> {
        self.nodes.iter().map(|h| Point3::from(h.xyz())).collect()
    }

    /// The origin `o` of the placement `t = M (x − o)`.
    pub fn origin(&self) -> Point3<f64> {
        self.origin
    }

    /// The matrix `M` of the placement `t = M (x − o)`.
    pub fn to_unit(&self) -> &Matrix3<f64> {
        &self.to_unit
    }

    /// `l + m + n`: a curve or surface of degree `p` composed with the volume has degree
    /// `p · (l + m + n)` (module docs).
    pub fn degree_factor(&self) -> usize {
        self.degrees.iter().sum()
    }

    /// The same map at the lowest degree per direction that it has within `tol` (model
    /// units), and a bound on how far the new map is from this one anywhere in the box.
    ///
    /// An FFD's lattice is the identity (degree 1 in every direction) plus the
    /// displacements μ, and the polynomial those make often has a lower degree than the
    /// lattice: nodes moved alike, as in a dome that raises the inner nodes of a
    /// direction by one value, make the Bernstein coefficients `(0, a, a, 0)`, which
    /// are the degree elevation (Piegl & Tiller eq. (5.36)) of the quadratic
    /// `(0, 3a/2, 0)`. A composed face's degree is `p·(l+m+n)` with the degrees found
    /// here, so lowering them is what keeps such a lattice under degree 25.
    ///
    /// Each step lowers one direction by one: every line of nodes along it is reduced
    /// as a Bézier curve (the Bézier step of Piegl & Tiller A5.11) and elevated back, and
    /// the largest node difference is the step's error. The Bernstein basis is a
    /// partition of unity, so a node difference of ε moves the map by at most ε; the
    /// steps' errors add up to the returned bound, and a step is taken only while the
    /// sum stays within `tol`. `tol = 0` lowers only where the reduction is exact in
    /// floating point.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_nurbs::BezierVolume;
    /// use cadmorph_nurbs::math::{Matrix3, Point3};
    /// // A 4 x 4 x 2 lattice of the unit cube whose four inner nodes (in x and y) rise
    /// // by 0.1: quadratic in x and y, linear in z.
    /// let mut q = Vec::new();
    /// for i in 0..4 { for j in 0..4 { for k in 0..2 {
    ///     let lift = if (1..3).contains(&i) && (1..3).contains(&j) { 0.1 } else { 0.0 };
    ///     q.push(Point3::new(i as f64 / 3.0, j as f64 / 3.0, k as f64 + lift));
    /// } } }
    /// let v = BezierVolume::try_new([3, 3, 1], q, Point3::origin(), Matrix3::identity())?;
    /// let (low, bound) = v.lowered(1e-14);
    /// assert_eq!(low.degrees(), [2, 2, 1]);
    /// assert!(bound <= 1e-14);
    /// let x = Point3::new(0.3, 0.6, 0.2);
    /// assert!((low.eval(&x) - v.eval(&x)).norm() <= 1e-14);
    /// # Ok::<(), cadmorph_nurbs::Error>(())
    /// ```
    pub fn lowered(&self, tol: f64) -> (BezierVolume, f64) {
        let mut out = self.clone();
        let mut bound = 0.0;
        for axis in 0..3 {
            while out.degrees[axis] > 1 {
                let (next, err) = out.lowered_once(axis);
                if bound + err > tol {
                    break;
                }
                bound += err;
                out = next;
            }
        }
        (out, bound)
    }

    /// One degree less along `axis`, with the largest node difference between this net
    /// and the new one elevated back (see [`lowered`](Self::lowered)).
    fn lowered_once(&self, axis: usize) -> (BezierVolume, f64) {
        let dims = self.degrees.map(|d| d + 1);
        let index = |c: [usize; 3]| (c[0] * dims[1] + c[1]) * dims[2] + c[2];
        let mut new_dims = dims;
        new_dims[axis] -= 1;
        let new_index = |c: [usize; 3]| (c[0] * new_dims[1] + c[1]) * new_dims[2] + c[2];
        let (a, b) = match axis {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let d = self.degrees[axis];
        let mut nodes = vec![Hom::zeros(); new_dims.iter().product()];
        let mut err = 0.0f64;
        for s in 0..dims[a] {
            for t in 0..dims[b] {
                let at = |i: usize| {
                    let mut c = [0; 3];
                    c[axis] = i;
                    c[a] = s;
                    c[b] = t;
                    c
                };
                let line: Vec<Hom> = (0..=d).map(|i| self.nodes[index(at(i))]).collect();
                let reduced = crate::reduce::bezier_reduce(&line);
                for (back, q) in crate::reduce::bezier_elevate(&reduced).iter().zip(&line) {
                    err = err.max((back.xyz() - q.xyz()).norm());
                }
                for (i, r) in reduced.into_iter().enumerate() {
                    nodes[new_index(at(i))] = r;
                }
            }
        }
        let mut degrees = self.degrees;
        degrees[axis] -= 1;
        let err = if err.is_nan() { f64::INFINITY } else { err };
        (BezierVolume { degrees, nodes, origin: self.origin, to_unit: self.to_unit }, err)
    }

    /// The unit-cube coordinates `ψ(x)` of a model point.
    pub fn reference(&self, x: &Point3<f64>) -> Vector3<f64> {
        self.to_unit * (x - self.origin)
    }

    /// Whether `x` lies in the closed box, to `tol` in unit-cube coordinates.
    pub fn contains(&self, x: &Point3<f64>, tol: f64) -> bool {
        self.reference(x).iter().all(|&c| c >= -tol && c <= 1.0 + tol)
    }

    /// `V(ψ(x))`, by the de Casteljau-free Bernstein sum (no clamping: points outside
    /// the box are extrapolated by the same polynomial).
    pub fn eval(&self, x: &Point3<f64>) -> Point3<f64> {
        let t = self.reference(x);
        let [l, m, n] = self.degrees;
        let b = |d: usize, s: f64| -> Vec<f64> {
            (0..=d).map(|i| binomial(d, i) * s.powi(i as i32) * (1.0 - s).powi((d - i) as i32)).collect()
        };
        let (bx, by, bz) = (b(l, t.x), b(m, t.y), b(n, t.z));
        let mut acc = Vector3::zeros();
        for i in 0..=l {
            for j in 0..=m {
                for k in 0..=n {
                    acc += self.nodes[(i * (m + 1) + j) * (n + 1) + k].xyz() * (bx[i] * by[j] * bz[k]);
                }
            }
        }
        Point3::from(acc)
    }

    /// Composes one Bézier piece of bidegree `(p, q)` (homogeneous net, row by row)
    /// and returns the composed net of bidegree `(p·D, q·D)`, `D = l + m + n`.
    fn compose_piece(&self, p: usize, q: usize, net: &[Hom]) -> Bernstein<Hom> {
        let w = Bernstein { p, q, c: net.iter().map(|h| h.w).collect() };
        let [l, m, n] = self.degrees;
        // T_a = M_a · (A − o W) and U_a = W − T_a, for the three box directions.
        let coords: Vec<(Bernstein<f64>, Bernstein<f64>)> = (0..3)
            .map(|a| {
                let row = self.to_unit.row(a).transpose();
                let t: Vec<f64> = net.iter().map(|h| row.dot(&(h.xyz() - self.origin.coords * h.w))).collect();
                let u = t.iter().zip(&w.c).map(|(t, w)| w - t).collect();
                (Bernstein { p, q, c: t }, Bernstein { p, q, c: u })
            })
            .collect();
        // Pᵢ = C(d, i) Tⁱ U^(d−i) for i = 0..=d.
        let powers = |(t, u): &(Bernstein<f64>, Bernstein<f64>), d: usize| -> Vec<Bernstein<f64>> {
            let mut tp = vec![Bernstein::one()];
            let mut up = vec![Bernstein::one()];
            for i in 1..=d {
                tp.push(tp[i - 1].times(t, 0.0));
                up.push(up[i - 1].times(u, 0.0));
            }
            (0..=d)
                .map(|i| {
                    let mut b = tp[i].times(&up[d - i], 0.0);
                    b.scale(binomial(d, i));
                    b
                })
                .collect()
        };
        let (p1, p2, p3) = (powers(&coords[0], l), powers(&coords[1], m), powers(&coords[2], n));
        let mut total: Option<Bernstein<Hom>> = None;
        for (i, pi) in p1.iter().enumerate() {
            let mut h: Option<Bernstein<Hom>> = None;
            for (j, pj) in p2.iter().enumerate() {
                // G = Σₖ Pₖ³ Qᵢⱼₖ
                let mut g = Bernstein { p: p3[0].p, q: p3[0].q, c: vec![Hom::zeros(); p3[0].c.len()] };
                for (k, pk) in p3.iter().enumerate() {
                    let node = self.nodes[(i * (m + 1) + j) * (n + 1) + k];
                    for (gc, &s) in g.c.iter_mut().zip(&pk.c) {
                        *gc += node * s;
                    }
                }
                let term = pj.times(&g, Hom::zeros());
                h = Some(match h {
                    None => term,
                    Some(mut acc) => {
                        acc.add(&term);
                        acc
                    }
                });
            }
            let term = pi.times(&h.expect("m ≥ 1"), Hom::zeros());
            total = Some(match total {
                None => term,
                Some(mut acc) => {
                    acc.add(&term);
                    acc
                }
            });
        }
        total.expect("l ≥ 1")
    }

    /// The degrees `(p·D, q·D)` a surface of degrees `(p, q)` needs, and the degrees it
    /// is written at: the same, or [`MAX_DEGREE`] where they exceed it and `tol > 0`
    /// allows a reduction. The error names the degrees needed when they exceed
    /// [`MAX_DEGREE`] and no reduction is allowed, or exceed [`COMPOSE_CAP`].
    fn check_degrees(&self, p: usize, q: usize, tol: f64) -> Result<((usize, usize), (usize, usize))> {
        let d = self.degree_factor();
        let (pu, qv) = (p * d, q * d);
        let over = pu > MAX_DEGREE || qv > MAX_DEGREE;
        let reducible = tol > 0.0 && tol.is_finite() && pu <= COMPOSE_CAP && qv <= COMPOSE_CAP;
        if over && !reducible {
            return Err(Error::ComposedDegree { u_degree: pu, v_degree: qv, max: MAX_DEGREE });
        }
        Ok(((pu, qv), (pu.min(MAX_DEGREE), qv.min(MAX_DEGREE))))
    }
}

/// The highest degree a composition is carried out at before it is reduced to
/// [`MAX_DEGREE`]: beyond it the reduction would have to remove more than the degree it
/// keeps, and the composition's cost (quadratic in the degree per direction) buys nothing.
const COMPOSE_CAP: usize = 64;

impl Bernstein<Hom> {
    /// The same rows and columns swapped (`(q, p)`).
    fn transposed(&self) -> Self {
        let (p, q) = (self.p, self.q);
        let mut c = vec![Hom::zeros(); self.c.len()];
        for i in 0..=p {
            for j in 0..=q {
                c[j * (p + 1) + i] = self.c[i * (q + 1) + j];
            }
        }
        Bernstein { p: q, q: p, c }
    }

    /// One degree less in u: every column (fixed `j`) reduced as a Bézier curve (the
    /// Bézier step of Piegl & Tiller A5.11), and the bound of
    /// [`deviation_bound`](crate::reduce::deviation_bound) between the net and the
    /// reduced net elevated back (eq. (5.36)), which bounds how far the piece moved.
    fn reduced_u(&self, rational: bool) -> (Self, f64) {
        let (p, q) = (self.p, self.q);
        let mut c = vec![Hom::zeros(); p * (q + 1)];
        let (mut original, mut back) = (Vec::with_capacity(self.c.len()), Vec::with_capacity(self.c.len()));
        for j in 0..=q {
            let line: Vec<Hom> = (0..=p).map(|i| self.c[i * (q + 1) + j]).collect();
            let r = crate::reduce::bezier_reduce(&line);
            back.extend(crate::reduce::bezier_elevate(&r));
            original.extend(line);
            for (i, h) in r.into_iter().enumerate() {
                c[i * (q + 1) + j] = h;
            }
        }
        (Bernstein { p: p - 1, q, c }, crate::reduce::deviation_bound(&original, &back, rational))
    }

    /// Reduced to degrees `(pu, qv)` (at most its own) one step at a time; returns the
    /// net and the sum of the steps' bounds (infinite if a step's is).
    fn reduced_to(mut self, pu: usize, qv: usize, rational: bool) -> (Self, f64) {
        let mut bound = 0.0;
        while self.p > pu {
            let (next, b) = self.reduced_u(rational);
            self = next;
            bound += b;
        }
        if self.q > qv {
            let mut t = self.transposed();
            while t.p > qv {
                let (next, b) = t.reduced_u(rational);
                t = next;
                bound += b;
            }
            self = t.transposed();
        }
        (self, bound)
    }
}

/// A bivariate polynomial in the tensor Bernstein basis of bidegree `(p, q)`,
/// coefficients row by row (`i·(q+1) + j`); a univariate one has `q = 0`.
#[derive(Debug, Clone)]
struct Bernstein<T> {
    p: usize,
    q: usize,
    c: Vec<T>,
}

impl Bernstein<f64> {
    fn one() -> Self {
        Bernstein { p: 0, q: 0, c: vec![1.0] }
    }

    fn scale(&mut self, s: f64) {
        for c in &mut self.c {
            *c *= s;
        }
    }

    /// The product `self · g` (Farouki & Rajan's Bernstein product, per direction).
    fn times<T>(&self, g: &Bernstein<T>, zero: T) -> Bernstein<T>
    where
        T: Copy + std::ops::AddAssign + std::ops::Mul<f64, Output = T>,
    {
        let (p, q) = (self.p + g.p, self.q + g.q);
        let mut c = vec![zero; (p + 1) * (q + 1)];
        let wu = product_weights(self.p, g.p);
        let wv = product_weights(self.q, g.q);
        for a in 0..=self.p {
            for b in 0..=self.q {
                let f = self.c[a * (self.q + 1) + b];
                if f == 0.0 {
                    continue;
                }
                for i in 0..=g.p {
                    let cu = wu[a][i] * f;
                    for j in 0..=g.q {
                        c[(a + i) * (q + 1) + b + j] += g.c[i * (g.q + 1) + j] * (cu * wv[b][j]);
                    }
                }
            }
        }
        Bernstein { p, q, c }
    }
}

impl Bernstein<Hom> {
    fn add(&mut self, other: &Bernstein<Hom>) {
        for (a, b) in self.c.iter_mut().zip(&other.c) {
            *a += *b;
        }
    }
}

/// `w[a][i] = C(p₁, a) C(p₂, i) / C(p₁ + p₂, a + i)`.
fn product_weights(p1: usize, p2: usize) -> Vec<Vec<f64>> {
    (0..=p1).map(|a| (0..=p2).map(|i| binomial(p1, a) * binomial(p2, i) / binomial(p1 + p2, a + i)).collect()).collect()
}

/// Knot values with the multiplicity each needs after composition: `d + 1` at the ends
/// and at C⁻¹ joints (input multiplicity above `p`), `d` elsewhere (C⁰ nets).
fn joined_knots(values: &[f64], mults: &[usize], p: usize, d: usize) -> (Vec<f64>, Vec<bool>) {
    let last = values.len() - 1;
    let mut knots = Vec::new();
    let mut broken = vec![false; values.len()];
    for (i, (&v, &m)) in values.iter().zip(mults).enumerate() {
        let end = i == 0 || i == last;
        broken[i] = !end && m > p;
        let r = if end || broken[i] { d + 1 } else { d };
        knots.extend(std::iter::repeat_n(v, r));
    }
    (knots, broken)
}

/// Index of the first control point of piece `a` along a direction whose interior joints
/// are C⁰ (`d` per piece) or broken (one more).
fn piece_start(a: usize, d: usize, broken: &[bool]) -> usize {
    a * d + broken[1..=a].iter().filter(|&&b| b).count()
}

impl NurbsSurface {
    /// The exact composition `V ∘ S`: a surface `R` with `R(u, v) = V(ψ(S(u, v)))` on the
    /// same domain, of degree `(p·D, q·D)` with `D = l + m + n` (module docs), rational
    /// when `S` is (through its homogeneous form), with interior knots of multiplicity
    /// `p·D` (`q·D`) — follow with
    /// [`remove_knots_within`](NurbsSurface::remove_knots_within) for a smaller net.
    ///
    /// Where `S` leaves the volume's box the result follows the volume's polynomial, not
    /// a clamped FFD: compose only surfaces that lie in the box.
    ///
    /// # Errors
    ///
    /// [`Error::ComposedDegree`] when a degree would exceed [`MAX_DEGREE`] (OCCT's
    /// limit), naming the degrees needed; [`Error::NotFinite`] if the result is not finite.
    pub fn composed_with(&self, v: &BezierVolume) -> Result<NurbsSurface> {
        self.composed_within(v, 0.0).map(|(s, _)| s)
    }

    /// [`composed_with`](Self::composed_with), and where the exact image needs a degree
    /// above [`MAX_DEGREE`] (up to 64), that image reduced to [`MAX_DEGREE`] within
    /// `tol` (model units): each Bézier piece is composed at its full degree and then
    /// lowered one degree at a time (the Bézier step of Piegl & Tiller A5.11), each step
    /// bounded by its difference to the piece it came from, elevated back. Returns the
    /// surface and that bound (0 when no reduction was needed).
    ///
    /// The reduction keeps a piece's boundary rows functions of those rows alone (a
    /// reduction across them keeps their end points, one along them sees only them), so
    /// two faces whose exact images share a boundary curve, parametrised alike, still
    /// share it after the reduction.
    ///
    /// # Errors
    ///
    /// [`Error::ComposedDegree`] when a degree needed is above 64, or above
    /// [`MAX_DEGREE`] with `tol = 0`; [`Error::ComposedReduction`] when the reduction's
    /// bound exceeds `tol`; [`Error::NotFinite`] if the result is not finite.
    pub fn composed_within(&self, v: &BezierVolume, tol: f64) -> Result<(NurbsSurface, f64)> {
        let c = self.clamped();
        let (p, q) = (c.u_degree(), c.v_degree());
        let ((pn, qn), (pd, qd)) = v.check_degrees(p, q, tol)?;
        let rational = c.is_rational();
        let (uvals, umults) = c.u_knots().distinct();
        let (vvals, vmults) = c.v_knots().distinct();
        let (uk, ubroken) = joined_knots(&uvals, &umults, p, pd);
        let (vk, vbroken) = joined_knots(&vvals, &vmults, q, qd);
        let n_u = uk.len() - pd - 1;
        let n_v = vk.len() - qd - 1;
        let mut pw = vec![Hom::zeros(); n_u * n_v];
        let mut bound = 0.0;
        for (a, row) in c.bezier_patches().iter().enumerate() {
            let i0 = piece_start(a, pd, &ubroken);
            for (b, piece) in row.iter().enumerate() {
                let j0 = piece_start(b, qd, &vbroken);
                let (net, b) = v.compose_piece(p, q, &piece.homogeneous()).reduced_to(pd, qd, rational);
                bound = f64::max(bound, b);
                for i in 0..=pd {
                    for j in 0..=qd {
                        pw[(i0 + i) * n_v + j0 + j] = net.c[i * (qd + 1) + j];
                    }
                }
            }
        }
        if (bound.is_nan() || bound > tol) && (pn, qn) != (pd, qd) {
            return Err(Error::ComposedReduction { u_degree: pn, v_degree: qn, max: MAX_DEGREE, bound, tol });
        }
        if !rational {
            for h in &mut pw {
                *h = Hom::new(h.x / h.w, h.y / h.w, h.z / h.w, 1.0);
            }
        }
        let s = NurbsSurface::from_parts((pd, qd), (uk, vk), (n_u, n_v), &pw, rational);
        crate::curve::check_points(s.control_points())?;
        if let Some(w) = s.weights() {
            crate::curve::check_weights(w, w.len(), true)?;
        }
        Ok((s, bound))
    }
}

impl NurbsCurve {
    /// The exact composition `V ∘ C` of degree `p·(l + m + n)` on the same domain
    /// (module docs; see [`NurbsSurface::composed_with`]), rational when `C` is.
    ///
    /// # Errors
    ///
    /// [`Error::ComposedDegree`] above [`MAX_DEGREE`]; [`Error::NotFinite`].
    pub fn composed_with(&self, v: &BezierVolume) -> Result<NurbsCurve> {
        self.composed_within(v, 0.0).map(|(c, _)| c)
    }

    /// [`composed_with`](Self::composed_with), reduced to [`MAX_DEGREE`] within `tol`
    /// where the exact image needs more (see [`NurbsSurface::composed_within`]); returns
    /// the curve and the reduction's bound.
    ///
    /// # Errors
    ///
    /// As [`NurbsSurface::composed_within`].
    pub fn composed_within(&self, v: &BezierVolume, tol: f64) -> Result<(NurbsCurve, f64)> {
        let c = self.clamped();
        let p = c.degree();
        let ((pn, _), (pd, _)) = v.check_degrees(p, 0, tol)?;
        let rational = c.is_rational();
        let mut bound = 0.0;
        let (vals, mults) = c.knots().distinct();
        let (knots, broken) = joined_knots(&vals, &mults, p, pd);
        let n = knots.len() - pd - 1;
        let mut pw = vec![Hom::zeros(); n];
        for (a, seg) in c.bezier_segments().iter().enumerate() {
            let i0 = piece_start(a, pd, &broken);
            let (net, b) = v.compose_piece(p, 0, &seg.homogeneous()).reduced_to(pd, 0, rational);
            bound = f64::max(bound, b);
            pw[i0..=i0 + pd].copy_from_slice(&net.c);
        }
        if (bound.is_nan() || bound > tol) && pn != pd {
            return Err(Error::ComposedReduction { u_degree: pn, v_degree: 0, max: MAX_DEGREE, bound, tol });
        }
        if !rational {
            for h in &mut pw {
                *h = Hom::new(h.x / h.w, h.y / h.w, h.z / h.w, 1.0);
            }
        }
        let out = NurbsCurve::from_parts(pd, knots, &pw, rational);
        crate::curve::check_points(out.control_points())?;
        Ok((out, bound))
    }
}
