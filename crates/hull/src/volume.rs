//! Exact enclosed volume and first moments of a closed B-rep of NURBS faces, by the
//! divergence theorem, and their derivatives with respect to the faces' control points.
//!
//! For a solid `Ω` bounded by faces with outward normal `n`:
//!
//! ```text
//! V      = ∫_Ω 1 dV   = (1/3) ∮ x · n dA
//! M_k    = ∫_Ω x_k dV = (1/2) ∮ x_k² n_k dA          (k = x, y, z; centroid M / V)
//! δ∫_Ω f = ∮ f δx · n dA                              (Reynolds transport, f = 1, x, y, z)
//! ```
//!
//! On a face `S(u, v)` with `n dA = ±(S_u × S_v) du dv` the integrands are polynomial
//! (rational for rational faces) on every knot span, so Gauss–Legendre quadrature per span
//! with `2p + 1` points is exact for the volume, the moments and the gradients of a
//! non-rational face of degree `p` (each span of a rational face is split in four and
//! takes `2p + 6` points). Two kinds of faces are integrated exactly:
//!
//! * **natural** faces, bounded by their surface's own parameter boundary (every B-spline
//!   face of a lofted or sewn solid, analytic faces over their parameter box), over the
//!   whole domain;
//! * **planar** trimmed faces, by Green's theorem in the plane along their bounding
//!   curves (`∫_R f dA = ∮ P dt`, `P(s, t) = ∫₀ˢ f dσ`, the inner integral by Gauss), with
//!   the largest loop as the outer one and the others as holes.
//!
//! * **trimmed** curved faces, by Green's theorem in the surface's parameters:
//!   `∬_R F du dv = ∮_∂R P dv` with `P(u, v) = ∫_{u₀}^{u} F(σ, v) dσ` (the inner integral
//!   by Gauss per knot span, exact as above), along the preimages of the bounding curves
//!   (found by projecting them onto the surface; `dv/dt` from `C' = S_u u' + S_v v'`),
//!   Gauss–Legendre along each curve span split in eight. Not exact (the preimages are
//!   not polynomial), but converged far below the tolerances of CAD files.
//!
//! A face whose loops cross a closed surface's seam (a sphere octant across `u = 0`, a
//! torus whose seam edges are not its surface's) is integrated on the same surface with
//! its seam moved outside the face ([`FaceMethod::Reseamed`]). A face whose curves do not
//! lie on its surface, or that no seam position puts inside one period, is refused
//! ([`Error::TrimmedFace`]).

use cadmorph_brep::{BoundCurve, Face};
use cadmorph_nurbs::math::{Point3, Vector3};
use cadmorph_nurbs::{basis_funs, Curve, NurbsSurface, Surface, SurfaceProject};
use serde::Serialize;

use crate::gauss::gauss_legendre;
use crate::{Error, Result};

/// How a face's share of the enclosed integrals is computed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum FaceMethod {
    /// Over the whole parameter domain of its surface.
    Natural,
    /// Green's theorem in its plane along its bounding curves.
    Planar,
    /// Green's theorem in its surface's parameters along the preimages of its bounding
    /// curves (a curved face trimmed inside its surface).
    Trimmed,
    /// Over a box `[u0, u1, v0, v1]` of its surface's parameters: a face bounded by
    /// iso-parameter lines (a cylinder or cone between two circles, whose loops close
    /// only across the periodic seam), see `iso_box`.
    Rectangle([f64; 4]),
    /// On its closed surface with the seam moved (`NurbsSurface::reseamed_u`/`_v`) to
    /// `seam` (u, v; `None`: kept) so that the face no longer crosses it: a sphere
    /// octant or fillet whose loops straddle `u = 0`, a torus or hemisphere whose own
    /// seam edges lie elsewhere than the surface's. See `reseamed_method`.
    Reseamed {
        /// The new seam parameters in u and v.
        seam: [Option<f64>; 2],
        /// The method on the reseamed surface.
        method: OnReseamed,
    },
}

/// How a face is integrated on its reseamed surface ([`FaceMethod::Reseamed`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum OnReseamed {
    /// Over the whole reseamed domain.
    Natural,
    /// Over a box of the reseamed parameters.
    Rectangle([f64; 4]),
    /// Green's theorem along the loops' preimages on the reseamed surface.
    Trimmed,
}

/// Volume and first moments of an enclosed solid (or one face's share of them), and the
/// area of its boundary.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Moments {
    /// `∫ dV`.
    pub volume: f64,
    /// `∫ x dV` (the centroid times the volume).
    pub moment: [f64; 3],
    /// `∮ dA`, the area of the faces (never negative; by a denser quadrature, since
    /// `|S_u × S_v|` is not polynomial: converged far below CAD tolerances).
    pub area: f64,
    /// `∮ n dA`, the vector area: zero on a closed surface (the divergence theorem for a
    /// constant field), so the volume does not depend on the origin.
    pub vector_area: [f64; 3],
    /// `∮ x_j n_k dA` (row `j`, column `k`): `V·I` on a closed, consistently oriented
    /// surface (the divergence theorem for the field `x_j e_k`).
    pub flux: [[f64; 3]; 3],
}

impl Moments {
    /// The centroid `M / V`.
    pub fn centroid(&self) -> Point3<f64> {
        Point3::new(self.moment[0], self.moment[1], self.moment[2]) / self.volume
    }

    /// Nothing: the start of a sum.
    pub const ZERO: Moments =
        Moments { volume: 0.0, moment: [0.0; 3], area: 0.0, vector_area: [0.0; 3], flux: [[0.0; 3]; 3] };

    fn add(&mut self, o: &Moments) {
        self.volume += o.volume;
        self.area += o.area;
        for k in 0..3 {
            self.vector_area[k] += o.vector_area[k];
            for j in 0..3 {
                self.flux[j][k] += o.flux[j][k];
            }
        }
        for k in 0..3 {
            self.moment[k] += o.moment[k];
        }
    }

    fn scaled(&self, s: f64) -> Moments {
        Moments {
            volume: s * self.volume,
            moment: self.moment.map(|m| s * m),
            area: s.abs() * self.area,
            vector_area: self.vector_area.map(|a| s * a),
            flux: self.flux.map(|row| row.map(|f| s * f)),
        }
    }
}

/// The enclosed solid of a set of faces: its integrals, how each face was treated, and
/// the orientation that made the volume positive.
#[derive(Debug, Clone, Serialize)]
pub struct Enclosed {
    /// Volume and moments of the solid.
    pub total: Moments,
    /// Each face's method, in face order.
    pub methods: Vec<FaceMethod>,
    /// Each face's share, outward orientation applied.
    pub faces: Vec<Moments>,
    /// `+1` when the faces' own orientation points outward, `−1` when the shell was
    /// oriented inward (every share then flips).
    pub orientation: f64,
    /// Faces whose orientation was turned to close the shell consistently (IGES faces
    /// without a B-rep carry none; see `orient`).
    pub turned: Vec<usize>,
    /// Per face, the factor turning its `S_u × S_v` outward (its `reversed` flag, the
    /// turning and the orientation together).
    pub signs: Vec<f64>,
}

/// Nodes per knot span and sub-intervals per span for a direction of degree `p`.
fn rule(p: usize, rational: bool) -> (usize, usize) {
    if rational {
        (2 * p + 6, 4)
    } else {
        (2 * p + 1, 1)
    }
}

/// Gauss nodes per direction for the area integrand `|S_u × S_v|` on a span of degree
/// `p`: it is not polynomial, so [`adaptive_area`] checks each span against its four
/// quarters and splits where they differ.
fn area_nodes(p: usize) -> usize {
    p + 3
}

/// Relative agreement of two estimates of a span's area (two Gauss rules, or the span
/// against its quarters) at which the finer is taken. The finer's own error is orders
/// below the difference: on the samples' faces the areas agree with OCCT's adaptive
/// `BRepGProp::SurfaceProperties` (Eps 1e-12) to 1e-13 relative, 2.5e-12 on the planing
/// hull; a fixed rule of `2p + 1` nodes was off by up to 4e-6 next to degenerate edges.
const AREA_TOL: f64 = 1e-10;

/// The deepest quartering of a span.
const AREA_DEPTH: usize = 6;

/// `∫∫ f` over the box `b` by tensor Gauss rules of `n = (nu, nv)` and one more node
/// per direction: when the two agree to [`AREA_TOL`] (relative) the finer is taken;
/// otherwise the box is compared with its four quarters and split while they differ, to
/// [`AREA_DEPTH`] levels.
fn adaptive_area(f: &dyn Fn(f64, f64) -> f64, b: [f64; 4], n: (usize, usize)) -> f64 {
    type Rule = (Vec<(f64, f64)>, Vec<(f64, f64)>);
    let rule = |n: (usize, usize)| (gauss_legendre(n.0, 0.0, 1.0), gauss_legendre(n.1, 0.0, 1.0));
    let tensor = |g: &Rule, b: [f64; 4]| -> f64 {
        let (du, dv) = (b[1] - b[0], b[3] - b[2]);
        let mut acc = 0.0;
        for &(x, wx) in &g.0 {
            for &(y, wy) in &g.1 {
                acc += wx * wy * f(b[0] + x * du, b[2] + y * dv);
            }
        }
        acc * du * dv
    };
    let fine = rule((n.0 + 1, n.1 + 1));
    let coarse = rule(n);
    let whole = tensor(&fine, b);
    if (tensor(&coarse, b) - whole).abs() <= AREA_TOL * whole.abs() {
        return whole;
    }
    let quad = |b: [f64; 4]| tensor(&fine, b);
    fn go(quad: &dyn Fn([f64; 4]) -> f64, b: [f64; 4], whole: f64, depth: usize) -> f64 {
        let (um, vm) = (0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]));
        let parts = [[b[0], um, b[2], vm], [um, b[1], b[2], vm], [b[0], um, vm, b[3]], [um, b[1], vm, b[3]]];
        let q = parts.map(quad);
        let sum: f64 = q.iter().sum();
        if depth == 0 || (sum - whole).abs() <= AREA_TOL * sum.abs() {
            return sum;
        }
        parts.iter().zip(q).map(|(p, qp)| go(quad, *p, qp, depth - 1)).sum()
    }
    go(&quad, b, whole, AREA_DEPTH)
}

/// `∫ f` over `[a, b]` by `n` Gauss nodes, halved adaptively as [`adaptive_area`].
fn adaptive_line(f: &dyn Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let g = gauss_legendre(n, 0.0, 1.0);
    let quad = |a: f64, b: f64| g.iter().map(|&(x, w)| w * f(a + x * (b - a))).sum::<f64>() * (b - a);
    fn go(quad: &dyn Fn(f64, f64) -> f64, a: f64, b: f64, whole: f64, depth: usize) -> f64 {
        let m = 0.5 * (a + b);
        let (l, r) = (quad(a, m), quad(m, b));
        if depth == 0 || (l + r - whole).abs() <= AREA_TOL * (l + r).abs() {
            return l + r;
        }
        go(quad, a, m, l, depth - 1) + go(quad, m, b, r, depth - 1)
    }
    go(&quad, a, b, quad(a, b), 2 * AREA_DEPTH)
}

/// The area of the box `b` of `s`, span by span.
fn box_area(s: &NurbsSurface, b: [f64; 4]) -> f64 {
    let uc = cuts(s.u_knots().distinct().0, b[0], b[1]);
    let vc = cuts(s.v_knots().distinct().0, b[2], b[3]);
    let n = (area_nodes(s.u_degree()), area_nodes(s.v_degree()));
    let f = |u: f64, v: f64| area_density(s, u, v);
    let mut total = 0.0;
    for us in uc.windows(2) {
        for vs in vc.windows(2) {
            total += adaptive_area(&f, [us[0], us[1], vs[0], vs[1]], n);
        }
    }
    total
}

/// `(parameter, weight)` pairs covering `[lo, hi]` span by span.
fn span_rule(breaks: &[f64], lo: f64, hi: f64, n: usize, split: usize) -> Vec<(f64, f64)> {
    let mut cuts: Vec<f64> = vec![lo];
    cuts.extend(breaks.iter().copied().filter(|&k| k > lo && k < hi));
    cuts.push(hi);
    let mut out = Vec::new();
    for w in cuts.windows(2) {
        let h = (w[1] - w[0]) / split as f64;
        for s in 0..split {
            let a = w[0] + s as f64 * h;
            out.extend(gauss_legendre(n, a, a + h));
        }
    }
    out
}

/// Quadrature over the parameter box `[u0, u1] × [v0, v1]` of `s`, each direction by
/// `rule` on every knot span inside the box.
fn box_rule(s: &NurbsSurface, b: [f64; 4], rule: fn(usize, bool) -> (usize, usize)) -> Vec<(f64, f64, f64)> {
    let r = s.is_rational();
    let (nu, su) = rule(s.u_degree(), r);
    let (nv, sv) = rule(s.v_degree(), r);
    let uk = s.u_knots().distinct().0;
    let vk = s.v_knots().distinct().0;
    let ur = span_rule(&uk, b[0], b[1], nu, su);
    let vr = span_rule(&vk, b[2], b[3], nv, sv);
    let mut out = Vec::with_capacity(ur.len() * vr.len());
    for &(u, wu) in &ur {
        for &(v, wv) in &vr {
            out.push((u, v, wu * wv));
        }
    }
    out
}

/// `|S_u × S_v|`, the area element of `s` at `(u, v)`.
fn area_density(s: &NurbsSurface, u: f64, v: f64) -> f64 {
    let d = s.eval_d1(u, v);
    d.du.cross(&d.dv).norm()
}

/// Quadrature over the whole domain of `s` exact for the volume integrands.
fn surface_rule(s: &NurbsSurface) -> Vec<(f64, f64, f64)> {
    let (ud, vd) = s.domain();
    box_rule(s, [*ud.start(), *ud.end(), *vd.start(), *vd.end()], rule)
}

/// The share of a natural face (whole domain), with `sign` = ±1 turning `S_u × S_v` into
/// the outward normal.
pub fn natural_moments(s: &NurbsSurface, sign: f64) -> Moments {
    let (ud, vd) = s.domain();
    box_moments(s, [*ud.start(), *ud.end(), *vd.start(), *vd.end()], sign)
}

/// The share of a face that is the parameter box `b = [u0, u1, v0, v1]` of its surface
/// (exact as for natural faces: the box's sides fall on knot spans' parts).
pub fn box_moments(s: &NurbsSurface, b: [f64; 4], sign: f64) -> Moments {
    let mut m = Moments::ZERO;
    let mut add = |d: &cadmorph_nurbs::SurfacePointD1, w: f64| {
        let n = d.du.cross(&d.dv) * (sign * w);
        let x = d.point.coords;
        m.volume += x.dot(&n) / 3.0;
        for k in 0..3 {
            m.moment[k] += 0.5 * x[k] * x[k] * n[k];
            m.vector_area[k] += n[k];
            for j in 0..3 {
                m.flux[j][k] += x[j] * n[k];
            }
        }
    };
    if s.is_rational() {
        for (u, v, w) in box_rule(s, b, rule) {
            add(&s.eval_d1(u, v), w);
        }
        m.area = box_area(s, b);
        return m;
    }
    // Non-rational: span by span, the volume rule's nodes also give the area, checked
    // against a rule of one node less per direction (as `adaptive_area` does).
    let (nu, _) = rule(s.u_degree(), false);
    let (nv, _) = rule(s.v_degree(), false);
    let (gu, gv) = (gauss_legendre(nu, 0.0, 1.0), gauss_legendre(nv, 0.0, 1.0));
    let (cu, cv) = (gauss_legendre(nu - 1, 0.0, 1.0), gauss_legendre(nv - 1, 0.0, 1.0));
    let f = |u: f64, v: f64| area_density(s, u, v);
    let mut area = 0.0;
    for us in cuts(s.u_knots().distinct().0, b[0], b[1]).windows(2) {
        for vs in cuts(s.v_knots().distinct().0, b[2], b[3]).windows(2) {
            let (du, dv) = (us[1] - us[0], vs[1] - vs[0]);
            let mut fine = 0.0;
            for &(x, wx) in &gu {
                for &(y, wy) in &gv {
                    let d = s.eval_d1(us[0] + x * du, vs[0] + y * dv);
                    let w = wx * wy * du * dv;
                    fine += w * d.du.cross(&d.dv).norm();
                    add(&d, w);
                }
            }
            let mut coarse = 0.0;
            for &(x, wx) in &cu {
                for &(y, wy) in &cv {
                    coarse += wx * wy * du * dv * f(us[0] + x * du, vs[0] + y * dv);
                }
            }
            area += if (fine - coarse).abs() <= AREA_TOL * fine.abs() {
                fine
            } else {
                adaptive_area(&f, [us[0], us[1], vs[0], vs[1]], (nu - 1, nv - 1))
            };
        }
    }
    m.area = area;
    m
}

/// `[lo, knots inside, hi]`.
fn cuts(knots: Vec<f64>, lo: f64, hi: f64) -> Vec<f64> {
    let mut c = vec![lo];
    c.extend(knots.into_iter().filter(|&k| k > lo && k < hi));
    c.push(hi);
    c
}

/// `∂(∫_Ω f)/∂P_j = ∫ f R_j n dA` over a natural face for `f = 1, x, y, z`: for each
/// control point `j` (in the surface's order) the four gradient vectors. `R_j` is the
/// (rational) basis function of control point `j`; the weights stay fixed.
pub fn natural_gradients(s: &NurbsSurface, sign: f64) -> Vec<[Vector3<f64>; 4]> {
    let (p, q) = (s.u_degree(), s.v_degree());
    let nv = s.n_v();
    let weights = s.weights();
    let mut out = vec![[Vector3::zeros(); 4]; s.control_points().len()];
    let mut r = vec![0.0; (p + 1) * (q + 1)];
    for (u, v, w) in surface_rule(s) {
        let d = s.eval_d1(u, v);
        let n = d.du.cross(&d.dv) * (sign * w);
        let x = d.point.coords;
        let f = [1.0, x.x, x.y, x.z];
        let su = s.u_knots().find_span(p, u);
        let sv = s.v_knots().find_span(q, v);
        let bu = basis_funs(s.u_knots(), p, u);
        let bv = basis_funs(s.v_knots(), q, v);
        let mut denom = 0.0;
        for a in 0..=p {
            for b in 0..=q {
                let j = (su - p + a) * nv + (sv - q + b);
                let wj = weights.map_or(1.0, |ws| ws[j]);
                r[a * (q + 1) + b] = bu[a] * bv[b] * wj;
                denom += r[a * (q + 1) + b];
            }
        }
        for a in 0..=p {
            for b in 0..=q {
                let j = (su - p + a) * nv + (sv - q + b);
                let rj = r[a * (q + 1) + b] / denom;
                for (k, fk) in f.iter().enumerate() {
                    out[j][k] += n * (rj * fk);
                }
            }
        }
    }
    out
}

/// Whether every bounding curve of the face lies on its surface's parameter boundary.
fn is_natural(face: &Face, bounds: &[&BoundCurve], size: f64) -> bool {
    if !face.trimmed {
        return true;
    }
    let s = &face.surface;
    let (ud, vd) = s.domain();
    let (u0, u1, v0, v1) = (*ud.start(), *ud.end(), *vd.start(), *vd.end());
    let (pu, pv) = (1e-7 * (u1 - u0), 1e-7 * (v1 - v0));
    bounds.iter().all(|b| {
        (0..5).all(|k| {
            let t = b.range.0 + (b.range.1 - b.range.0) * (0.1 + 0.2 * k as f64);
            let pr = s.project(&b.curve.eval(t), 1e-10 * size);
            pr.distance_sq.sqrt() <= 1e-6 * size
                && ((pr.u - u0).abs() <= pu
                    || (pr.u - u1).abs() <= pu
                    || (pr.v - v0).abs() <= pv
                    || (pr.v - v1).abs() <= pv)
        })
    })
}

/// The unit normal of a planar surface, or `None` when it is not planar.
fn plane_of(s: &NurbsSurface) -> Option<(Point3<f64>, Vector3<f64>)> {
    let (ud, vd) = s.domain();
    let (u, v) = (0.5 * (ud.start() + ud.end()), 0.5 * (vd.start() + vd.end()));
    let n = s.normal(u, v)?.into_inner();
    let o = s.eval(u, v);
    let extent = s.control_extent().max(f64::MIN_POSITIVE);
    s.control_points().iter().all(|p| (p - o).dot(&n).abs() <= 1e-9 * extent).then_some((o, n))
}

/// One piece of a loop: a bounding curve between two parameters, in loop direction.
struct Piece<'a> {
    curve: &'a BoundCurve,
    forward: bool,
}

/// Chains the bounding curves of one face into closed loops.
fn loops<'a>(face: &Face, bounds: &[&'a BoundCurve], tol: f64) -> Result<Vec<Vec<Piece<'a>>>> {
    let ends: Vec<(Point3<f64>, Point3<f64>)> =
        bounds.iter().map(|b| (b.curve.eval(b.range.0), b.curve.eval(b.range.1))).collect();
    let mut used = vec![false; bounds.len()];
    let mut out = Vec::new();
    while let Some(first) = used.iter().position(|u| !u) {
        used[first] = true;
        let start = ends[first].0;
        let mut end = ends[first].1;
        let mut lp = vec![Piece { curve: bounds[first], forward: true }];
        while (end - start).norm() > tol {
            let mut best: Option<(usize, bool, f64)> = None;
            for (i, (a, b)) in ends.iter().enumerate() {
                if used[i] {
                    continue;
                }
                for (fw, d) in [(true, (a - end).norm()), (false, (b - end).norm())] {
                    if best.is_none_or(|(_, _, bd)| d < bd) {
                        best = Some((i, fw, d));
                    }
                }
            }
            match best {
                Some((i, fw, d)) if d <= tol => {
                    used[i] = true;
                    end = if fw { ends[i].1 } else { ends[i].0 };
                    lp.push(Piece { curve: bounds[i], forward: fw });
                }
                other => {
                    let gap = other.map_or((end - start).norm(), |b| b.2);
                    return Err(Error::OpenLoop { face: face.entity, gap });
                }
            }
        }
        out.push(lp);
    }
    Ok(out)
}

/// `∮ P_f dt` along one loop for `f = 1, x², y², z², s, t` in plane coordinates
/// `x = o + s e1 + t e2` (the first is the loop's signed area `∮ s dt`).
fn loop_integrals(lp: &[Piece], o: &Point3<f64>, e1: &Vector3<f64>, e2: &Vector3<f64>) -> [f64; 6] {
    let inner = gauss_legendre(3, 0.0, 1.0);
    let mut acc = [0.0; 6];
    for piece in lp {
        let c = &piece.curve.curve;
        let (n, split) = rule(c.degree(), c.is_rational());
        let knots = c.knots().distinct().0;
        let (a, b) = (piece.curve.range.0.min(piece.curve.range.1), piece.curve.range.0.max(piece.curve.range.1));
        // The stored range runs from the curve's first vertex to its second.
        let dir = if piece.curve.range.1 >= piece.curve.range.0 { 1.0 } else { -1.0 };
        let sense = if piece.forward { dir } else { -dir };
        for (tau, w) in span_rule(&knots, a, b, n, split) {
            let d = c.derivs(tau, 1);
            let rel = d[0] - o.coords;
            let (s, t) = (rel.dot(e1), rel.dot(e2));
            let dt = d[1].dot(e2) * w * sense;
            let mut p = [0.0; 6];
            for &(sig, ws) in &inner {
                let x = o.coords + e1 * (s * sig) + e2 * t;
                p[0] += ws;
                for k in 0..3 {
                    p[k + 1] += ws * x[k] * x[k];
                }
                p[4] += ws * s * sig;
                p[5] += ws * t;
            }
            for k in 0..6 {
                acc[k] += s * p[k] * dt;
            }
        }
    }
    acc
}

/// The share of a planar trimmed face, `sign` turning the surface normal outward.
fn planar_moments(
    face: &Face,
    bounds: &[&BoundCurve],
    o: Point3<f64>,
    n: Vector3<f64>,
    sign: f64,
    tol: f64,
) -> Result<Moments> {
    let e1 = {
        let a = if n.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
        (a - n * a.dot(&n)).normalize()
    };
    let e2 = n.cross(&e1);
    let lps = loops(face, bounds, tol)?;
    let ints: Vec<[f64; 6]> = lps.iter().map(|lp| loop_integrals(lp, &o, &e1, &e2)).collect();
    let outer = (0..ints.len()).max_by(|&a, &b| ints[a][0].abs().total_cmp(&ints[b][0].abs())).unwrap_or(0);
    let mut region = [0.0; 6];
    for (i, int) in ints.iter().enumerate() {
        let s = if i == outer { int[0].signum() } else { -int[0].signum() };
        for k in 0..6 {
            region[k] += s * int[k];
        }
    }
    let nout = n * sign;
    Ok(Moments {
        volume: o.coords.dot(&nout) * region[0] / 3.0,
        moment: [0.5 * nout.x * region[1], 0.5 * nout.y * region[2], 0.5 * nout.z * region[3]],
        area: region[0].abs(),
        vector_area: [0, 1, 2].map(|k| nout[k] * region[0]),
        // ∫ x_j dA = o_j A + e1_j ∫ s dA + e2_j ∫ t dA.
        flux: [0, 1, 2].map(|j| {
            let xj = o.coords[j] * region[0] + e1[j] * region[4] + e2[j] * region[5];
            [0, 1, 2].map(|k| xj * nout[k])
        }),
    })
}

/// The share of a curved face trimmed inside its surface (see the module docs),
/// `sign` turning `S_u × S_v` outward.
/// One quadrature node of a loop's preimage: `(u, v, w·dv/dt)`.
type Node = (f64, f64, f64);

/// The preimages on `s` of a face's loops, as quadrature nodes along each loop (Gauss per
/// curve span split in eight): `None` where a curve leaves the surface, the walk jumps
/// across a closed surface's seam, or a loop's preimage does not close.
fn preimages(s: &NurbsSurface, lps: &[Vec<Piece>], size: f64) -> Option<Vec<Vec<Node>>> {
    let tol = 1e-6 * size;
    let (ud, vd) = s.domain();
    let (u0, u1) = (*ud.start(), *ud.end());
    let mut out = Vec::with_capacity(lps.len());
    for lp in lps {
        let mut nodes_out = Vec::new();
        let mut last: Option<(f64, f64)> = None;
        let mut first: Option<(f64, f64)> = None;
        for piece in lp {
            let c = &piece.curve.curve;
            let knots = c.knots().distinct().0;
            let (a, b) = (piece.curve.range.0.min(piece.curve.range.1), piece.curve.range.0.max(piece.curve.range.1));
            let dir = if piece.curve.range.1 >= piece.curve.range.0 { 1.0 } else { -1.0 };
            let sense = if piece.forward { dir } else { -dir };
            let mut nodes = span_rule(&knots, a, b, 12, 8);
            if sense < 0.0 {
                nodes.reverse();
            }
            for (tau, w) in nodes {
                let d = c.derivs(tau, 1);
                let pr = s.project_near(&Point3::from(d[0]), last, 1e-12 * size, 1e-6 * size);
                if pr.distance_sq.sqrt() > tol {
                    return None;
                }
                if let Some(l) = last {
                    if (pr.u - l.0).abs() > 0.5 * (u1 - u0) && !short_path(s, l, (pr.u, pr.v)) {
                        // The loop crosses a periodic surface's seam.
                        return None;
                    }
                }
                last = Some((pr.u, pr.v));
                first = first.or(last);
                let sd = s.eval_d1(pr.u, pr.v);
                // C' = S_u u' + S_v v', least squares.
                let (a11, a12, a22) = (sd.du.dot(&sd.du), sd.du.dot(&sd.dv), sd.dv.dot(&sd.dv));
                let (b1, b2) = (sd.du.dot(&d[1]), sd.dv.dot(&d[1]));
                let det = a11 * a22 - a12 * a12;
                if det.abs() <= f64::MIN_POSITIVE {
                    return None;
                }
                nodes_out.push((pr.u, pr.v, (a11 * b2 - a12 * b1) / det * w * sense));
            }
        }
        // A loop closed in space whose preimage does not close crosses the seam of a
        // periodic surface: Green's theorem does not hold along it.
        if let (Some(a), Some(b)) = (first, last) {
            let far = (a.0 - b.0).abs() > 0.25 * (ud.end() - ud.start())
                || (a.1 - b.1).abs() > 0.25 * (vd.end() - vd.start());
            if far && !short_path(s, b, a) {
                return None;
            }
        }
        out.push(nodes_out);
    }
    Some(out)
}

/// Whether the straight parameter segment from `a` to `b` is short on the surface: at most
/// twice the chord `|S(a) − S(b)|` long. A jump of the preimage along a degenerate
/// boundary (from one meridian to the next at a sphere's pole) is; a jump across a closed
/// surface's seam, between two points side by side in space, runs the whole period.
fn short_path(s: &NurbsSurface, a: (f64, f64), b: (f64, f64)) -> bool {
    const N: usize = 16;
    let at = |k: usize| {
        let t = k as f64 / N as f64;
        s.eval(a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t)
    };
    let length: f64 = (0..N).map(|k| (at(k + 1) - at(k)).norm()).sum();
    length <= 2.0 * (at(N) - at(0)).norm()
}

fn trimmed_moments(face: &Face, s: &NurbsSurface, bounds: &[&BoundCurve], sign: f64, size: f64) -> Result<Moments> {
    let refuse = || Error::TrimmedFace { face: face.entity, kind: face.type_name.clone() };
    let (ud, _) = s.domain();
    let u0 = *ud.start();
    let uk = s.u_knots().distinct().0;
    let (nu, su) = rule(s.u_degree(), s.is_rational());
    let nau = area_nodes(s.u_degree());
    // P(u, v) for f = x·n/3, x_k² n_k / 2, |n|, n_k and x_j n_k.
    let inner = |u: f64, v: f64| -> [f64; 17] {
        let mut p = [0.0; 17];
        if u <= u0 {
            return p;
        }
        for (sig, w) in span_rule(&uk, u0, u, nu, su) {
            let d = s.eval_d1(sig, v);
            let n = d.du.cross(&d.dv) * (sign * w);
            let x = d.point.coords;
            p[0] += x.dot(&n) / 3.0;
            for k in 0..3 {
                p[k + 1] += 0.5 * x[k] * x[k] * n[k];
                p[k + 5] += n[k];
                for j in 0..3 {
                    p[8 + 3 * j + k] += x[j] * n[k];
                }
            }
        }
        let mut lo = u0;
        for k in uk.iter().copied().filter(|&k| k > u0 && k < u).chain(std::iter::once(u)) {
            p[4] += adaptive_line(&|sig| area_density(s, sig, v), lo, k, nau);
            lo = k;
        }
        p
    };
    let lps = loops(face, bounds, 1e-6 * size)?;
    let walks = preimages(s, &lps, size).ok_or_else(refuse)?;
    let mut ints: Vec<([f64; 17], f64)> = Vec::with_capacity(walks.len());
    for walk in &walks {
        let mut acc = [0.0; 17];
        let mut area = 0.0;
        for &(u, v, dv) in walk {
            let p = inner(u, v);
            for k in 0..17 {
                acc[k] += p[k] * dv;
            }
            area += (u - u0) * dv;
        }
        ints.push((acc, area));
    }
    let outer = (0..ints.len()).max_by(|&a, &b| ints[a].1.abs().total_cmp(&ints[b].1.abs())).unwrap_or(0);
    let mut m = Moments::ZERO;
    for (i, (acc, area)) in ints.iter().enumerate() {
        let o = if i == outer { area.signum() } else { -area.signum() };
        m.volume += o * acc[0];
        for k in 0..3 {
            m.moment[k] += o * acc[k + 1];
            m.vector_area[k] += o * acc[k + 5];
            for j in 0..3 {
                m.flux[j][k] += o * acc[8 + 3 * j + k];
            }
        }
        m.area += o * acc[4];
    }
    m.area = m.area.abs();
    Ok(m)
}

/// Whether `s` closes on itself in u (`dir` 0) or v (`dir` 1): its first and last
/// iso-lines in that direction coincide (sampled, to `tol`).
fn closes(s: &NurbsSurface, dir: usize, tol: f64) -> bool {
    let (ud, vd) = s.domain();
    let (a, b) = if dir == 0 { (ud, vd) } else { (vd, ud) };
    (0..7).all(|k| {
        let t = b.start() + (b.end() - b.start()) * k as f64 / 6.0;
        let (p, q) = if dir == 0 {
            (s.eval(*a.start(), t), s.eval(*a.end(), t))
        } else {
            (s.eval(t, *a.start()), s.eval(t, *a.end()))
        };
        (p - q).norm() <= tol
    })
}

/// The parameter box a face's bounding curves bound when every one of them is an
/// iso-parameter line of its surface (sampled; degenerate curves, such as a cone's apex,
/// are left out). On a surface that closes in a direction, the seam line is the only
/// line of that direction the face may have: it then spans the whole period.
fn iso_box(face: &Face, bounds: &[&BoundCurve], size: f64) -> Option<[f64; 4]> {
    const N: usize = 9;
    let s = &face.surface;
    let (ud, vd) = s.domain();
    let dom = [*ud.start(), *ud.end(), *vd.start(), *vd.end()];
    let tol = [1e-7 * (dom[1] - dom[0]), 1e-7 * (dom[3] - dom[2])];
    let closed = [closes(s, 0, 1e-9 * size), closes(s, 1, 1e-9 * size)];
    // Iso values per direction, and the extent of the other lines along it.
    let mut lines: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
    let mut extent = [(f64::INFINITY, f64::NEG_INFINITY); 2];
    for b in bounds {
        let pts: Vec<Point3<f64>> =
            (0..N).map(|k| b.curve.eval(b.range.0 + (b.range.1 - b.range.0) * (k as f64 + 0.5) / N as f64)).collect();
        if pts.iter().all(|p| (p - pts[0]).norm() <= 1e-9 * size) {
            continue;
        }
        let mut uv = Vec::with_capacity(N);
        for p in &pts {
            let pr = s.project(p, 1e-10 * size);
            if pr.distance_sq.sqrt() > 1e-6 * size {
                return None;
            }
            let mut q = [pr.u, pr.v];
            for d in 0..2 {
                // A point on a closed direction's seam may project to either end.
                if closed[d] && (q[d] - dom[2 * d + 1]).abs() <= tol[d] {
                    q[d] = dom[2 * d];
                }
            }
            uv.push(q);
        }
        let span =
            |d: usize| uv.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| (lo.min(q[d]), hi.max(q[d])));
        let (mut su, mut sv) = (span(0), span(1));
        let along = if su.1 - su.0 <= tol[0] {
            lines[0].push(0.5 * (su.0 + su.1));
            1
        } else if sv.1 - sv.0 <= tol[1] {
            lines[1].push(0.5 * (sv.0 + sv.1));
            0
        } else {
            return None;
        };
        // Along a direction that does not close, the line's ends count too: one may be a
        // pole (a hemisphere's seam edge runs up to it), which the samples stop short of.
        if !closed[along] {
            for t in [b.range.0, b.range.1] {
                let pr = s.project(&b.curve.eval(t), 1e-10 * size);
                let x = if along == 0 { pr.u } else { pr.v };
                let sp = if along == 0 { &mut su } else { &mut sv };
                *sp = (sp.0.min(x), sp.1.max(x));
            }
        }
        let sp = if along == 0 { su } else { sv };
        extent[along] = (extent[along].0.min(sp.0), extent[along].1.max(sp.1));
    }
    let mut out = [0.0; 4];
    for d in 0..2 {
        let (lo, hi) = lines[d].iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        let (a, b) = if hi - lo > tol[d] {
            (lo, hi)
        } else if closed[d] && (lines[d].is_empty() || (lo - dom[2 * d]).abs() <= tol[d]) {
            // Only the seam (or no line at all): the face goes once around.
            (dom[2 * d], dom[2 * d + 1])
        } else {
            // One line (or none) and a pole: a hemisphere from its equator, a cone from
            // its base circle to its apex.
            to_poles(s, d, &dom, (lo, hi), extent[d], tol[d], size)?
        };
        // The other direction's lines must run inside the box.
        if extent[d].0 < a - tol[d] || extent[d].1 > b + tol[d] {
            return None;
        }
        out[2 * d] = a;
        out[2 * d + 1] = b;
    }
    Some(out)
}

/// The range in direction `d` of a face with at most one iso-line of that direction
/// (`lines`, empty when `lo > hi`), whose other lines run over `extent`: the range from
/// the line to the end of the extent, when the surface collapses to a point there (a
/// pole, an apex: a boundary with no curve in the file; an apex may lie inside the
/// domain of a cone made over more than the face).
fn to_poles(
    s: &NurbsSurface,
    d: usize,
    dom: &[f64; 4],
    (lo, hi): (f64, f64),
    extent: (f64, f64),
    tol: f64,
    size: f64,
) -> Option<(f64, f64)> {
    let pole = |x: f64| {
        let (o0, o1) = if d == 0 { (dom[2], dom[3]) } else { (dom[0], dom[1]) };
        let at = |k: usize| {
            let t = o0 + (o1 - o0) * k as f64 / 6.0;
            if d == 0 {
                s.eval(x, t)
            } else {
                s.eval(t, x)
            }
        };
        (1..=6).all(|k| (at(k) - at(0)).norm() <= 1e-9 * size)
    };
    let (ea, eb) = extent;
    if ea.is_nan() || eb.is_nan() || ea > eb {
        return None;
    }
    let (a, b) = if lo > hi { (ea, eb) } else { (lo.min(ea), hi.max(eb)) };
    let bounded = |x: f64| (lo <= hi && (x - lo).abs() <= tol) || pole(x);
    (b - a > tol && bounded(a) && bounded(b)).then_some((a, b))
}

/// Whether every bounding curve of a face lies on its surface (sampled).
fn curves_on_surface(face: &Face, bounds: &[&BoundCurve], size: f64) -> bool {
    !bounds.is_empty()
        && bounds.iter().all(|b| {
            (0..5).all(|k| {
                let t = b.range.0 + (b.range.1 - b.range.0) * (0.1 + 0.2 * k as f64);
                face.surface.project(&b.curve.eval(t), 1e-10 * size).distance_sq.sqrt() <= 1e-6 * size
            })
        })
}

/// Which method a face needs, or [`Error::TrimmedFace`].
pub fn face_method(face: &Face, bounds: &[&BoundCurve], size: f64) -> Result<FaceMethod> {
    if is_natural(face, bounds, size) {
        Ok(FaceMethod::Natural)
    } else if plane_of(&face.surface).is_some() {
        Ok(FaceMethod::Planar)
    } else if let Some(b) = iso_box(face, bounds, size) {
        Ok(FaceMethod::Rectangle(b))
    } else if curves_on_surface(face, bounds, size) {
        let walks = loops(face, bounds, 1e-6 * size).map(|lps| preimages(&face.surface, &lps, size).is_some());
        match walks {
            Ok(true) => Ok(FaceMethod::Trimmed),
            Ok(false) => reseamed_method(face, bounds, size)
                .ok_or_else(|| Error::TrimmedFace { face: face.entity, kind: face.type_name.clone() }),
            Err(e) => Err(e),
        }
    } else {
        Err(Error::TrimmedFace { face: face.entity, kind: face.type_name.clone() })
    }
}

/// Samples per bounding curve for placing a new seam.
const SEAM_SAMPLES: usize = 32;

/// A face on a closed surface whose loops cross its seam, or whose own seam edges lie
/// elsewhere than the surface's: the seam positions (u, v) that put the face inside one
/// period, and the method on the surface reseamed there ([`FaceMethod::Reseamed`]).
///
/// In each direction the surface closes in, the candidates are the face's own iso-lines
/// of that direction (a seam edge, used twice, bounds a face that goes all the way
/// round: the new seam must be that edge) and the middle of the largest gap that the
/// preimages of its bounding curves leave on the circle of that parameter (a sphere
/// octant covering a quarter turn across `u = 0`). Samples at degenerate points (a pole,
/// where one partial vanishes and the parameter is arbitrary) are left out. The first
/// candidate on which the face is natural, an iso-box or a closing trimmed walk wins.
fn reseamed_method(face: &Face, bounds: &[&BoundCurve], size: f64) -> Option<FaceMethod> {
    let s = &face.surface;
    let closed = [closes(s, 0, 1e-9 * size), closes(s, 1, 1e-9 * size)];
    if !closed[0] && !closed[1] {
        return None;
    }
    let (ud, vd) = s.domain();
    let dom = [(*ud.start(), *ud.end()), (*vd.start(), *vd.end())];
    // Per bounding curve, the (u, v) of its samples off degenerate points.
    let uvs: Vec<Vec<[f64; 2]>> = bounds
        .iter()
        .map(|b| {
            (0..=SEAM_SAMPLES)
                .filter_map(|k| {
                    let t = b.range.0 + (b.range.1 - b.range.0) * k as f64 / SEAM_SAMPLES as f64;
                    let pr = s.project(&b.curve.eval(t), 1e-10 * size);
                    let d = s.eval_d1(pr.u, pr.v);
                    let (nu, nv) = (d.du.norm(), d.dv.norm());
                    (nu > 1e-6 * nv && nv > 1e-6 * nu).then_some([pr.u, pr.v])
                })
                .collect()
        })
        .collect();
    let mut candidates: [Vec<Option<f64>>; 2] = [vec![None], vec![None]];
    for d in 0..2 {
        if !closed[d] {
            continue;
        }
        let (lo, hi) = dom[d];
        let period = hi - lo;
        let wrap = |x: f64| lo + (x - lo).rem_euclid(period);
        for uv in uvs.iter().filter(|uv| uv.len() >= 2) {
            let x: Vec<f64> = uv.iter().map(|q| wrap(q[d])).collect();
            let spread = x.iter().map(|&a| {
                let e = (a - x[0]).rem_euclid(period);
                e.min(period - e)
            });
            if spread.fold(0.0f64, f64::max) <= 1e-7 * period {
                candidates[d].push(Some(x[0]));
            }
        }
        let mut all: Vec<f64> = uvs.iter().flatten().map(|q| wrap(q[d])).collect();
        all.sort_by(f64::total_cmp);
        if let (Some(&first), Some(&last)) = (all.first(), all.last()) {
            let (mut gap, mut mid) = (first + period - last, wrap(last + 0.5 * (first + period - last)));
            for w in all.windows(2) {
                if w[1] - w[0] > gap {
                    gap = w[1] - w[0];
                    mid = 0.5 * (w[0] + w[1]);
                }
            }
            candidates[d].push(Some(mid));
        }
    }
    for &cu in &candidates[0] {
        for &cv in &candidates[1] {
            if cu.is_none() && cv.is_none() {
                continue;
            }
            let Some(surface) = reseam(s, [cu, cv], size) else { continue };
            let moved = Face { surface, ..face.clone() };
            let method = if is_natural(&moved, bounds, size) {
                OnReseamed::Natural
            } else if let Some(b) = iso_box(&moved, bounds, size) {
                OnReseamed::Rectangle(b)
            } else if loops(&moved, bounds, 1e-6 * size)
                .is_ok_and(|lps| preimages(&moved.surface, &lps, size).is_some())
            {
                OnReseamed::Trimmed
            } else {
                continue;
            };
            return Some(FaceMethod::Reseamed { seam: [cu, cv], method });
        }
    }
    None
}

/// `s` with its seams moved to `seam` (u, v; `None`: kept), or `None` when it does not
/// close where asked.
fn reseam(s: &NurbsSurface, seam: [Option<f64>; 2], size: f64) -> Option<NurbsSurface> {
    let mut out = s.clone();
    if let Some(c) = seam[0] {
        out = out.reseamed_u(c, 1e-9 * size).ok()?;
    }
    if let Some(c) = seam[1] {
        out = out.reseamed_v(c, 1e-9 * size).ok()?;
    }
    Some(out)
}

/// The bounding curves of each face, by face index.
pub fn bounds_by_face(n_faces: usize, bounds: &[BoundCurve]) -> Vec<Vec<&BoundCurve>> {
    let mut out = vec![Vec::new(); n_faces];
    for b in bounds {
        if b.face < n_faces {
            out[b.face].push(b);
        }
    }
    out
}

/// The outward sign of a face's `S_u × S_v` before the shell's orientation is known.
pub(crate) fn face_sign(face: &Face) -> f64 {
    if face.reversed {
        -1.0
    } else {
        1.0
    }
}

/// The largest `|∮ n dA| / ∮ dA` of a closed shell: its quadrature error and the seam
/// gaps of real files (a gap `g` along a seam of length `L` opens `~g L`) stay orders
/// below it, while a shell missing a face is off by that face's share of the area.
pub const CLOSED_VECTOR_AREA: f64 = 1e-6;

/// Volume, moments and centroid of the solid the faces enclose (see the module docs).
///
/// `size` is the model size (bounding-box diagonal), for the tolerances of telling
/// natural faces and loops apart.
///
/// # Errors
///
/// [`Error::TrimmedFace`] for a face that is neither natural nor planar,
/// [`Error::OpenLoop`] for a planar face whose curves do not close,
/// [`Error::NotClosed`] when the signed volume vanishes, [`Error::OpenShell`] when the
/// vector area does not (a necessary test of closure: a shell whose open borders' vector
/// areas cancel, a tube open at both ends, passes it).
pub fn enclosed(faces: &[Face], bounds: &[BoundCurve], size: f64) -> Result<Enclosed> {
    let by_face = bounds_by_face(faces.len(), bounds);
    let methods = faces.iter().zip(&by_face).map(|(f, fb)| face_method(f, fb, size)).collect::<Result<Vec<_>>>()?;
    enclosed_with(faces, bounds, size, &methods)
}

/// [`enclosed`] with each face's method already known (faces moved by a morph keep the
/// methods of the faces they came from, which saves telling them apart again).
///
/// # Errors
///
/// As [`enclosed`].
pub fn enclosed_with(faces: &[Face], bounds: &[BoundCurve], size: f64, methods: &[FaceMethod]) -> Result<Enclosed> {
    let by_face = bounds_by_face(faces.len(), bounds);
    let mut shares = Vec::with_capacity(faces.len());
    for ((face, fb), method) in faces.iter().zip(&by_face).zip(methods) {
        let sign = face_sign(face);
        let share = match method {
            FaceMethod::Natural => natural_moments(&face.surface, sign),
            FaceMethod::Planar => {
                let (o, n) = plane_of(&face.surface)
                    .ok_or_else(|| Error::TrimmedFace { face: face.entity, kind: face.type_name.clone() })?;
                planar_moments(face, fb, o, n, sign, 1e-6 * size)?
            }
            FaceMethod::Trimmed => trimmed_moments(face, &face.surface, fb, sign, size)?,
            FaceMethod::Rectangle(b) => box_moments(&face.surface, *b, sign),
            FaceMethod::Reseamed { seam, method } => {
                let refuse = || Error::TrimmedFace { face: face.entity, kind: face.type_name.clone() };
                let r = reseam(&face.surface, *seam, size).ok_or_else(refuse)?;
                match method {
                    OnReseamed::Natural => natural_moments(&r, sign),
                    OnReseamed::Rectangle(b) => box_moments(&r, *b, sign),
                    OnReseamed::Trimmed => trimmed_moments(face, &r, fb, sign, size)?,
                }
            }
        };
        shares.push(share);
    }
    let turned = orient(&shares, size)?;
    for &i in &turned {
        shares[i] = shares[i].scaled(-1.0);
    }
    let mut total = Moments::ZERO;
    for s in &shares {
        total.add(s);
    }
    if total.volume.is_nan() || total.volume.abs() <= 1e-12 * size.powi(3) {
        return Err(Error::NotClosed { volume: total.volume });
    }
    let orientation = total.volume.signum();
    let signs = faces
        .iter()
        .enumerate()
        .map(|(i, f)| face_sign(f) * orientation * if turned.contains(&i) { -1.0 } else { 1.0 })
        .collect();
    Ok(Enclosed {
        total: total.scaled(orientation),
        methods: methods.to_vec(),
        faces: shares.iter().map(|s| s.scaled(orientation)).collect(),
        orientation,
        turned,
        signs,
    })
}

/// The closure residual of a sum of shares: `|∮ n dA| / A + ‖∮ x ⊗ n dA − (tr/3) I‖ / (A L)`,
/// zero on a closed, consistently oriented shell.
fn closure_residual(sum: &[f64; 12], area: f64, size: f64) -> f64 {
    let va = (sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]).sqrt();
    let tr = (sum[3] + sum[7] + sum[11]) / 3.0;
    let mut off = 0.0;
    for j in 0..3 {
        for k in 0..3 {
            let d = sum[3 + 3 * j + k] - if j == k { tr } else { 0.0 };
            off += d * d;
        }
    }
    va / area + off.sqrt() / (area * size)
}

/// The faces whose orientation must turn for the shell to close consistently (none
/// when the file's orientations already do), found by turning, one at a time, the face
/// that lowers [`closure_residual`] most (a face turned changes the sums by twice its
/// share, and IGES faces without a B-rep carry no orientation at all).
///
/// # Errors
///
/// [`Error::OpenShell`] when no turning closes the shell to [`CLOSED_VECTOR_AREA`].
fn orient(shares: &[Moments], size: f64) -> Result<Vec<usize>> {
    let vecs: Vec<[f64; 12]> = shares
        .iter()
        .map(|m| {
            let mut v = [0.0; 12];
            v[..3].copy_from_slice(&m.vector_area);
            for j in 0..3 {
                v[3 + 3 * j..6 + 3 * j].copy_from_slice(&m.flux[j]);
            }
            v
        })
        .collect();
    let area: f64 = shares.iter().map(|m| m.area).sum();
    let mut sum = [0.0; 12];
    for v in &vecs {
        for k in 0..12 {
            sum[k] += v[k];
        }
    }
    let mut sign = vec![1.0; shares.len()];
    let mut r = closure_residual(&sum, area, size);
    let mut turned = Vec::new();
    while (r.is_nan() || r > CLOSED_VECTOR_AREA) && turned.len() < shares.len() {
        let mut best: Option<(usize, f64)> = None;
        for (i, v) in vecs.iter().enumerate() {
            let mut t = sum;
            for k in 0..12 {
                t[k] -= 2.0 * sign[i] * v[k];
            }
            let ri = closure_residual(&t, area, size);
            if ri < r && best.is_none_or(|(_, b)| ri < b) {
                best = Some((i, ri));
            }
        }
        let Some((i, ri)) = best else { break };
        for k in 0..12 {
            sum[k] -= 2.0 * sign[i] * vecs[i][k];
        }
        sign[i] = -sign[i];
        r = ri;
        turned.push(i);
    }
    if r <= CLOSED_VECTOR_AREA {
        turned.sort_unstable();
        turned.dedup();
        return Ok(turned.into_iter().filter(|&i| sign[i] < 0.0).collect());
    }
    Err(Error::OpenShell { vector_area: [sum[0], sum[1], sum[2]], area, ratio: r })
}

#[cfg(test)]
mod tests {
    use super::*;
    use cadmorph_nurbs::KnotVector;

    /// The unit-radius quarter-cylinder wall has a closed-form volume share.
    #[test]
    fn rational_face_share_matches_closed_form() {
        // Quarter cylinder x² + y² = R², 0 ≤ z ≤ H, outward normal: (1/3)∫ x·n dA = R·(πR/2)·H/3.
        let (r, h) = (2.0, 3.0);
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let pts = vec![
            Point3::new(r, 0.0, 0.0),
            Point3::new(r, 0.0, h),
            Point3::new(r, r, 0.0),
            Point3::new(r, r, h),
            Point3::new(0.0, r, 0.0),
            Point3::new(0.0, r, h),
        ];
        let s = NurbsSurface::try_new(
            (2, 1),
            (
                KnotVector::try_new(vec![0., 0., 0., 1., 1., 1.]).unwrap(),
                KnotVector::try_new(vec![0., 0., 1., 1.]).unwrap(),
            ),
            (3, 2),
            pts,
            Some(vec![1.0, 1.0, w, w, 1.0, 1.0]),
        )
        .unwrap();
        let sign = if s.normal(0.5, 0.5).unwrap().x > 0.0 { 1.0 } else { -1.0 };
        let m = natural_moments(&s, sign);
        let exact = r * (std::f64::consts::PI * r / 2.0) * h / 3.0;
        assert!((m.volume - exact).abs() < 1e-14 * exact, "{} vs {exact}", m.volume);
    }
}
