//! Tessellation of surfaces into triangles within a chordal tolerance, and bounding boxes.
//!
//! # Tessellation
//!
//! [`NurbsSurface::tessellate`] triangulates a tensor grid of parameters. The grid
//! starts at the knot lines (the Bézier patch boundaries, Piegl & Tiller A5.6), and each
//! knot span is split into equal parts, per direction and per span. The number of parts
//! grows until, on every grid cell, the chord deviation at the midpoints of the four
//! cell edges and of the diagonal (the midpoints of all three edges of both triangles)
//! is at most `0.7·tol`:
//!
//! ```text
//! e = | S(mid of the edge's parameters) − mid of the edge's end points |
//! ```
//!
//! Why 0.7: where the surface is well resolved, the deviation of a triangle from the
//! surface (at linearly interpolated parameters) is a quadratic in the barycentric
//! coordinates that vanishes at the vertices, `e(b) = Σᵢ<ⱼ cᵢⱼ bᵢ bⱼ`, with
//! `cᵢⱼ = 4·e(midᵢⱼ)`; its maximum is at most `(4/3)·max e(mid)`. Keeping the edge
//! midpoints below `0.7·tol` bounds the deviation by `0.93·tol`, leaving room for the
//! higher-order terms. The bound holds for the distance from the triangle point to the
//! surface point at the *same interpolated parameters*, so it also bounds the true
//! distance to the surface.
//!
//! Refinement is driven per span and per direction: an edge along u that deviates
//! too much refines its u span; a diagonal that deviates while its edges do not (twist)
//! refines both spans. The new part count is estimated from the quadratic convergence
//! of the chord error, `n' = ⌈n·√(e/target)⌉`, between `n + 1` and `4n`.
//!
//! # Bounding boxes
//!
//! [`NurbsSurface::bounding_box`] and [`NurbsCurve::bounding_box`] enclose the control
//! points: with positive weights the curve or surface lies in their convex hull (Piegl &
//! Tiller P4.9 / P4.25), so the box is valid, but it may be loose. The `tight_` variants
//! box a tessellation (or polyline) within `tol` and widen it by `tol`.

use nalgebra::{Point3, Vector3};

use crate::{Curve, KnotVector, NurbsCurve, NurbsSurface, Surface};

/// The chord deviation at edge midpoints is kept below this fraction of `tol` (see the
/// source comments at the top of `tessellate.rs`).
const MIDPOINT_FRACTION: f64 = 0.7;
/// Refinement rounds before giving up (each at least doubles nothing, but adds one part).
const MAX_ROUNDS: usize = 40;
/// Grid intervals per direction, at most (all spans together); bounds the work for a
/// tiny `tol` to a grid of about 4 million points.
const MAX_PARTS: usize = 2048;

/// An axis-aligned bounding box.
///
/// # Examples
///
/// ```
/// use cadmorph_nurbs::Aabb;
/// use nalgebra::Point3;
/// let b = Aabb::from_points(&[Point3::new(0.0, 1.0, 2.0), Point3::new(3.0, -3.0, 2.0)]).unwrap();
/// assert_eq!(b.min, Point3::new(0.0, -3.0, 2.0));
/// assert_eq!(b.diagonal(), 5.0);
/// assert!(b.contains(&Point3::new(1.0, 0.0, 2.0)));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// The corner with the smallest coordinates.
    pub min: Point3<f64>,
    /// The corner with the largest coordinates.
    pub max: Point3<f64>,
}

impl Aabb {
    /// The smallest box holding all `points`; `None` if there are none.
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Point3<f64>>) -> Option<Self> {
        let mut it = points.into_iter();
        let first = *it.next()?;
        Some(it.fold(Self { min: first, max: first }, |b, p| Self { min: b.min.inf(p), max: b.max.sup(p) }))
    }

    /// Length of the diagonal `|max − min|`: the model size used to scale tolerances.
    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).norm()
    }

    /// Whether `p` is inside or on the box.
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        (0..3).all(|k| p[k] >= self.min[k] && p[k] <= self.max[k])
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb { min: self.min.inf(&other.min), max: self.max.sup(&other.max) }
    }

    /// The box grown by `d` on every side.
    pub fn inflated(&self, d: f64) -> Aabb {
        let v = Vector3::repeat(d);
        Aabb { min: self.min - v, max: self.max + v }
    }

    /// The common part of both boxes, `None` if they do not overlap.
    pub fn intersection(&self, other: &Aabb) -> Option<Aabb> {
        let b = Aabb { min: self.min.sup(&other.min), max: self.max.inf(&other.max) };
        (0..3).all(|k| b.min[k] <= b.max[k]).then_some(b)
    }
}

/// A triangle mesh of a surface, with the parameters and normals of its vertices.
///
/// Triangles are counter-clockwise in the (u, v) plane, so their geometric normals
/// point the way of the surface normal `S_u × S_v`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Vertex positions `S(u, v)`.
    pub vertices: Vec<Point3<f64>>,
    /// Unit surface normals at the vertices; at a singular point (pole, collapsed edge)
    /// the normal of a nearby interior point, or zero if there is none.
    pub normals: Vec<Vector3<f64>>,
    /// Vertex parameters `(u, v)`.
    pub params: Vec<(f64, f64)>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

/// The distinct knots inside the domain `[a, b]`, with both ends.
fn span_breaks(knots: &KnotVector, (a, b): (f64, f64)) -> Vec<f64> {
    let (values, _) = knots.distinct();
    let mut out = vec![a];
    out.extend(values.into_iter().filter(|&k| k > a && k < b));
    out.push(b);
    out
}

/// Parameters of `parts[s]` equal parts in span `s`, and for each interval the span it lies in.
fn grid(breaks: &[f64], parts: &[usize]) -> (Vec<f64>, Vec<usize>) {
    let mut t = Vec::new();
    let mut owner = Vec::new();
    for (s, w) in breaks.windows(2).enumerate() {
        for i in 0..parts[s] {
            t.push(w[0] + (w[1] - w[0]) * i as f64 / parts[s] as f64);
            owner.push(s);
        }
    }
    t.push(*breaks.last().expect("at least two breaks"));
    (t, owner)
}

/// New part count for a span whose chord error is `err` with `n` parts.
fn refined(n: usize, err: f64, target: f64) -> usize {
    let factor = if err.is_finite() && target > 0.0 { (err / target).sqrt() * 1.05 } else { 4.0 };
    ((n as f64 * factor).ceil() as usize).clamp(n + 1, 8 * n)
}

/// Raises the part count of every span whose error exceeds `target` (NaN counts as
/// exceeding); returns whether anything changed. Nothing changes if the total would
/// pass [`MAX_PARTS`].
fn refine_parts(parts: &mut [usize], err: &[f64], target: f64) -> bool {
    let new: Vec<usize> = parts
        .iter()
        .zip(err)
        .map(|(&n, &e)| if e > target || e.is_nan() { refined(n, e, target) } else { n })
        .collect();
    let changed = new.as_slice() != &*parts;
    if !changed || new.iter().sum::<usize>() > MAX_PARTS {
        return false;
    }
    parts.copy_from_slice(&new);
    true
}

fn mid(a: &Point3<f64>, b: &Point3<f64>) -> Point3<f64> {
    Point3::from((a.coords + b.coords) * 0.5)
}

impl NurbsSurface {
    /// The box of the control points; it encloses the surface (convex hull property).
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_nurbs::{NurbsSurface, Surface};
    /// let s = NurbsSurface::bilinear([[0.0, 0.0, 0.0], [2.0, 0.0, 1.0], [0.0, 1.0, 0.0], [2.0, 1.0, -1.0]]);
    /// let b = s.bounding_box();
    /// assert!(b.contains(&s.eval(0.3, 0.6)));
    /// assert_eq!(b.max.z, 1.0);
    /// ```
    ///
    /// With control points at infinity (weight 0) the box is that of the surface
    /// elevated in both directions until every weight is positive, as for
    /// [`NurbsCurve::bounding_box`]; unbounded if that does not happen (the surface
    /// reaches infinity).
    pub fn bounding_box(&self) -> Aabb {
        let has_zero = |s: &NurbsSurface| s.weights().is_some_and(|w| w.contains(&0.0));
        if !has_zero(self) {
            return Aabb::from_points(self.control_points()).expect("a surface has control points");
        }
        let unbounded = Aabb {
            min: Point3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
            max: Point3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        };
        let mut s = self.clamped();
        let (n_u, n_v) = (s.n_u(), s.n_v());
        let w = s.weights().expect("has a zero weight");
        // A zero weight at a corner of the clamped net puts the surface at infinity there.
        if [0, n_v - 1, (n_u - 1) * n_v, n_u * n_v - 1].iter().any(|&i| w[i] == 0.0) {
            return unbounded;
        }
        // Each elevation shortens every run of zero weights along its direction by one;
        // a run along a whole row or column would need as many as the net is long.
        for _ in 0..n_u.max(n_v) {
            if !has_zero(&s) {
                return Aabb::from_points(s.control_points()).expect("a surface has control points");
            }
            if s.elevate_u_degree(1).and_then(|_| s.elevate_v_degree(1)).is_err() {
                break;
            }
        }
        unbounded
    }

    /// A box that is close to the surface: the box of a tessellation within `tol`,
    /// widened by `tol` and clipped to [`bounding_box`](Self::bounding_box).
    ///
    /// # Tolerance
    ///
    /// The surface lies in the box up to the accuracy of the tessellation (see the
    /// source comments at the top of `tessellate.rs`) and rounding; the box exceeds the surface's true extent by at
    /// most about `2·tol`. The cost is that of [`tessellate`](Self::tessellate).
    pub fn tight_bounding_box(&self, tol: f64) -> Aabb {
        let mesh = self.tessellate(tol);
        let loose = self.bounding_box();
        Aabb::from_points(&mesh.vertices).map(|b| b.inflated(tol)).and_then(|b| b.intersection(&loose)).unwrap_or(loose)
    }

    /// Triangles within the chordal tolerance `tol` of the surface (see the
    /// source comments at the top of `tessellate.rs` for the algorithm).
    ///
    /// # Tolerance
    ///
    /// Every point of a triangle is within `tol` of the surface point at the same
    /// (linearly interpolated) parameters, as far as the edge-midpoint estimate sees: the
    /// estimate is exact for quadratic deviation and conservative by a factor of 0.7.
    /// Triangle counts grow like `1/tol` (chord error is quadratic in the cell size).
    /// The grid has at most 2048 intervals per direction; a `tol` finer than that
    /// resolves (or a non-positive or NaN one) gives the last grid within that limit.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_nurbs::analytic::{AnalyticSurface, Cylinder, Placement};
    /// use cadmorph_nurbs::Surface;
    /// let cyl = Cylinder::try_new(Placement::standard(), 1.0).unwrap();
    /// let s = cyl.to_nurbs(0.0..=std::f64::consts::PI, 0.0..=1.0).unwrap().surface;
    /// let coarse = s.tessellate(1e-2);
    /// let fine = s.tessellate(1e-4);
    /// assert!(fine.triangles.len() > 5 * coarse.triangles.len());
    /// // Vertices lie on the cylinder; triangle centroids within tol of it.
    /// for t in &fine.triangles {
    ///     let c = t.iter().map(|&i| fine.vertices[i as usize].coords).sum::<nalgebra::Vector3<f64>>() / 3.0;
    ///     assert!((1.0 - c.x.hypot(c.y)) <= 1e-4);
    /// }
    /// ```
    pub fn tessellate(&self, tol: f64) -> Mesh {
        let (du, dv) = self.domain();
        let ub = span_breaks(self.u_knots(), (*du.start(), *du.end()));
        let vb = span_breaks(self.v_knots(), (*dv.start(), *dv.end()));
        let mut nu = vec![self.u_degree(); ub.len() - 1];
        let mut nv = vec![self.v_degree(); vb.len() - 1];
        let target = MIDPOINT_FRACTION * tol;
        for _ in 0..MAX_ROUNDS {
            let (us, uown) = grid(&ub, &nu);
            let (vs, vown) = grid(&vb, &nv);
            let (cu, cv) = (us.len() - 1, vs.len() - 1);
            let pts: Vec<Point3<f64>> =
                us.iter().flat_map(|&u| vs.iter().map(move |&v| (u, v))).map(|(u, v)| self.eval(u, v)).collect();
            let at = |i: usize, j: usize| &pts[i * vs.len() + j];
            let mut err_u = vec![0.0f64; nu.len()];
            let mut err_v = vec![0.0f64; nv.len()];
            // Edges along u (i → i+1 at fixed v_j) and along v.
            let mut eu = vec![0.0f64; cu * vs.len()];
            for i in 0..cu {
                let um = 0.5 * (us[i] + us[i + 1]);
                for (j, &v) in vs.iter().enumerate() {
                    let e = (self.eval(um, v) - mid(at(i, j), at(i + 1, j))).norm();
                    eu[i * vs.len() + j] = e;
                    err_u[uown[i]] = err_u[uown[i]].max(e);
                }
            }
            let mut ev = vec![0.0f64; us.len() * cv];
            for (i, &u) in us.iter().enumerate() {
                for j in 0..cv {
                    let vm = 0.5 * (vs[j] + vs[j + 1]);
                    let e = (self.eval(u, vm) - mid(at(i, j), at(i, j + 1))).norm();
                    ev[i * cv + j] = e;
                    err_v[vown[j]] = err_v[vown[j]].max(e);
                }
            }
            // Diagonals (i, j) → (i+1, j+1); twist refines both spans.
            let mut twist_u = vec![0.0f64; nu.len()];
            let mut twist_v = vec![0.0f64; nv.len()];
            for i in 0..cu {
                let um = 0.5 * (us[i] + us[i + 1]);
                for j in 0..cv {
                    let vm = 0.5 * (vs[j] + vs[j + 1]);
                    let e = (self.eval(um, vm) - mid(at(i, j), at(i + 1, j + 1))).norm();
                    let edges_fine = eu[i * vs.len() + j].max(eu[i * vs.len() + j + 1]) <= target
                        && ev[i * cv + j].max(ev[(i + 1) * cv + j]) <= target;
                    if edges_fine && e > target {
                        twist_u[uown[i]] = twist_u[uown[i]].max(e);
                        twist_v[vown[j]] = twist_v[vown[j]].max(e);
                    }
                }
            }
            let err_u: Vec<f64> = err_u.iter().zip(&twist_u).map(|(e, t)| e.max(*t)).collect();
            let err_v: Vec<f64> = err_v.iter().zip(&twist_v).map(|(e, t)| e.max(*t)).collect();
            let changed_u = refine_parts(&mut nu, &err_u, target);
            let changed_v = refine_parts(&mut nv, &err_v, target);
            if !(changed_u || changed_v) {
                return self.mesh_on(&us, &vs, pts);
            }
        }
        let (us, _) = grid(&ub, &nu);
        let (vs, _) = grid(&vb, &nv);
        let pts = us.iter().flat_map(|&u| vs.iter().map(move |&v| (u, v))).map(|(u, v)| self.eval(u, v)).collect();
        self.mesh_on(&us, &vs, pts)
    }

    /// The mesh of the grid `us × vs` with its evaluated points.
    fn mesh_on(&self, us: &[f64], vs: &[f64], vertices: Vec<Point3<f64>>) -> Mesh {
        let (du, dv) = self.domain();
        let centre = (0.5 * (du.start() + du.end()), 0.5 * (dv.start() + dv.end()));
        let params: Vec<(f64, f64)> = us.iter().flat_map(|&u| vs.iter().map(move |&v| (u, v))).collect();
        let normals = params
            .iter()
            .map(|&(u, v)| {
                // At a singular point, take the normal a little way towards the centre.
                [0.0, 1e-8, 1e-5, 1e-3]
                    .iter()
                    .find_map(|&f| self.normal(u + f * (centre.0 - u), v + f * (centre.1 - v)))
                    .map_or(Vector3::zeros(), |n| n.into_inner())
            })
            .collect();
        let nv = vs.len();
        let mut triangles = Vec::with_capacity(2 * (us.len() - 1) * (nv - 1));
        for i in 0..us.len() - 1 {
            for j in 0..nv - 1 {
                let a = (i * nv + j) as u32;
                let b = ((i + 1) * nv + j) as u32;
                let c = ((i + 1) * nv + j + 1) as u32;
                let d = (i * nv + j + 1) as u32;
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
        Mesh { vertices, normals, params, triangles }
    }
}

impl NurbsCurve {
    /// The box of the control points; it encloses the curve (convex hull property).
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_nurbs::{Curve, KnotVector, NurbsCurve};
    /// use nalgebra::Point3;
    /// let c = NurbsCurve::new(
    ///     2,
    ///     KnotVector::try_new(vec![0., 0., 0., 1., 1., 1.]).unwrap(),
    ///     vec![Point3::new(0., 0., 0.), Point3::new(1., 2., 0.), Point3::new(2., 0., 0.)],
    ///     None,
    /// );
    /// let (loose, tight) = (c.bounding_box(), c.tight_bounding_box(1e-6));
    /// assert_eq!(loose.max.y, 2.0);
    /// assert!((tight.max.y - 1.0).abs() < 2e-6); // the apex is at y = 1
    /// assert!(tight.contains(&c.eval(0.5)));
    /// ```
    ///
    /// With control points at infinity (weight 0) the control points do not enclose
    /// the curve; the box is then that of the curve's degree-elevated form (A5.9),
    /// whose every control point has a positive weight: each elevation replaces a run
    /// of `z` zero weights by `z − 1` (the new points are combinations of neighbours
    /// with positive coefficients). If the curve itself reaches infinity (a zero
    /// weight at a clamped end) the box is unbounded.
    pub fn bounding_box(&self) -> Aabb {
        let unbounded = || Aabb {
            min: Point3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
            max: Point3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        };
        let has_zero = |c: &NurbsCurve| c.weights().is_some_and(|w| w.contains(&0.0));
        if !has_zero(self) {
            return Aabb::from_points(self.control_points()).expect("a curve has control points");
        }
        let mut c = self.clamped();
        let w = c.weights().expect("has a zero weight");
        if w[0] == 0.0 || w[w.len() - 1] == 0.0 {
            return unbounded();
        }
        while has_zero(&c) {
            if c.elevate_degree(1).is_err() {
                return unbounded();
            }
        }
        Aabb::from_points(c.control_points()).expect("a curve has control points")
    }

    /// A box close to the curve: the box of a polyline within `tol` (same refinement as
    /// [`NurbsSurface::tessellate`], per knot span), widened by `tol` and clipped to
    /// [`bounding_box`](Self::bounding_box).
    ///
    /// # Tolerance
    ///
    /// The box exceeds the curve's extent by at most about `2·tol`; the polyline has
    /// `O(1/√tol)` points.
    pub fn tight_bounding_box(&self, tol: f64) -> Aabb {
        let d = self.domain();
        let breaks = span_breaks(self.knots(), (*d.start(), *d.end()));
        let mut parts = vec![self.degree(); breaks.len() - 1];
        let target = MIDPOINT_FRACTION * tol;
        let mut pts = Vec::new();
        for _ in 0..MAX_ROUNDS {
            let (ts, own) = grid(&breaks, &parts);
            pts = ts.iter().map(|&t| self.eval(t)).collect();
            let mut err = vec![0.0f64; parts.len()];
            for i in 0..ts.len() - 1 {
                let e = (self.eval(0.5 * (ts[i] + ts[i + 1])) - mid(&pts[i], &pts[i + 1])).norm();
                err[own[i]] = err[own[i]].max(e);
            }
            if !refine_parts(&mut parts, &err, target) {
                break;
            }
        }
        let loose = self.bounding_box();
        Aabb::from_points(&pts).map(|b| b.inflated(tol)).and_then(|b| b.intersection(&loose)).unwrap_or(loose)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::{AnalyticSurface, Cylinder, Placement, Sphere, Torus};
    use crate::SurfaceProject;

    fn wavy_surface() -> NurbsSurface {
        let (n_u, n_v) = (6, 5);
        let mut pts = Vec::new();
        for i in 0..n_u {
            for j in 0..n_v {
                let (x, y) = (i as f64 / (n_u - 1) as f64, j as f64 / (n_v - 1) as f64);
                pts.push(Point3::new(x, y + 0.2 * x * x, 0.2 * (x * 3.0).sin() * (y * 2.0).cos()));
            }
        }
        let w: Vec<f64> = (0..n_u * n_v).map(|k| 1.0 + 0.3 * ((k * 7) % 5) as f64 / 5.0).collect();
        NurbsSurface::new(
            (3, 2),
            (
                KnotVector::try_new(vec![0., 0., 0., 0., 0.3, 0.6, 1., 1., 1., 1.]).unwrap(),
                KnotVector::try_new(vec![0., 0., 0., 0.4, 0.6, 1., 1., 1.]).unwrap(),
            ),
            (n_u, n_v),
            pts,
            Some(w),
        )
    }

    fn test_surfaces() -> Vec<(&'static str, NurbsSurface)> {
        let f = Placement::standard();
        let half_pi = std::f64::consts::FRAC_PI_2;
        vec![
            ("wavy", wavy_surface()),
            ("cylinder", Cylinder::try_new(f, 1.0).unwrap().to_nurbs(0.0..=half_pi, 0.0..=1.0).unwrap().surface),
            ("sphere cap", Sphere::try_new(f, 1.0).unwrap().to_nurbs(0.0..=1.0, 0.5..=half_pi).unwrap().surface),
            ("torus", Torus::try_new(f, 1.0, 0.4).unwrap().to_nurbs(0.0..=1.0, 0.0..=2.5).unwrap().surface),
        ]
    }

    /// Barycentric sample points on a triangle: vertices' edge midpoints, centroid and
    /// points between.
    const BARY: [[f64; 3]; 7] = [
        [0.5, 0.5, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
        [0.6, 0.2, 0.2],
        [0.2, 0.6, 0.2],
        [0.2, 0.2, 0.6],
    ];

    /// Largest distance from sampled triangle points to the surface point at the same
    /// interpolated parameters (an upper bound of the distance to the surface). Large
    /// meshes are checked on every k-th triangle (about 20 000 of them), which still
    /// visits every knot span and every grid row.
    fn max_chord_error(s: &NurbsSurface, m: &Mesh) -> f64 {
        let mut worst = 0.0f64;
        let step = (m.triangles.len() / 20_000).max(1) | 1;
        for t in m.triangles.iter().step_by(step) {
            let [a, b, c] = t.map(|i| i as usize);
            for w in BARY {
                let p = m.vertices[a].coords * w[0] + m.vertices[b].coords * w[1] + m.vertices[c].coords * w[2];
                let u = m.params[a].0 * w[0] + m.params[b].0 * w[1] + m.params[c].0 * w[2];
                let v = m.params[a].1 * w[0] + m.params[b].1 * w[1] + m.params[c].1 * w[2];
                worst = worst.max((s.eval(u, v).coords - p).norm());
            }
        }
        worst
    }

    #[test]
    fn chord_error_follows_tolerance() {
        for (name, s) in test_surfaces() {
            let mut last = 0;
            for i in 0..6 {
                let tol = 0.1f64.powi(i);
                let m = s.tessellate(tol);
                let err = max_chord_error(&s, &m);
                assert!(err <= tol, "{name} tol {tol}: chord error {err}");
                assert!(m.triangles.len() >= last, "{name} tol {tol}: fewer triangles");
                if i >= 3 {
                    // Chord error is quadratic in the cell size: ×10 precision ≈ ×10 triangles.
                    assert!(m.triangles.len() > 3 * last, "{name} tol {tol}: {} vs {last}", m.triangles.len());
                }
                last = m.triangles.len();
            }
        }
    }

    #[test]
    fn projection_distance_within_tolerance() {
        // The true distance (by projection) is no more than the parameter-based bound.
        let s = wavy_surface();
        let tol = 1e-3;
        let m = s.tessellate(tol);
        for t in m.triangles.iter().step_by(7) {
            let [a, b, c] = t.map(|i| i as usize);
            let p = Point3::from((m.vertices[a].coords + m.vertices[b].coords + m.vertices[c].coords) / 3.0);
            let pr = s.project(&p, 1e-12);
            assert!(pr.distance_sq.sqrt() <= tol);
        }
    }

    #[test]
    fn mesh_is_consistent() {
        let s = wavy_surface();
        let m = s.tessellate(1e-2);
        assert_eq!(m.vertices.len(), m.params.len());
        assert_eq!(m.vertices.len(), m.normals.len());
        for (p, &(u, v)) in m.vertices.iter().zip(&m.params) {
            assert_eq!(*p, s.eval(u, v));
        }
        // Every knot value is a grid line.
        for k in [0.3, 0.6] {
            assert!(m.params.iter().any(|&(u, _)| u == k));
        }
        for k in [0.4, 0.6] {
            assert!(m.params.iter().any(|&(_, v)| v == k));
        }
        // Triangles face the way of the surface normal.
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| i as usize);
            let n = (m.vertices[b] - m.vertices[a]).cross(&(m.vertices[c] - m.vertices[a]));
            assert!(n.dot(&m.normals[a]) > 0.0);
            assert!(t.iter().all(|&i| (i as usize) < m.vertices.len()));
        }
    }

    #[test]
    fn pole_normals_are_defined() {
        let s = Sphere::try_new(Placement::standard(), 1.0)
            .unwrap()
            .to_nurbs(0.0..=std::f64::consts::TAU, 0.0..=std::f64::consts::FRAC_PI_2)
            .unwrap()
            .surface;
        let m = s.tessellate(1e-2);
        for (n, p) in m.normals.iter().zip(&m.vertices) {
            assert!((n.norm() - 1.0).abs() < 1e-12);
            assert!(n.dot(&p.coords) > 0.99, "{n} at {p}");
        }
        assert!(max_chord_error(&s, &m) <= 1e-2);
    }

    #[test]
    fn flat_patches_stay_coarse() {
        let plane = NurbsSurface::bilinear([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]);
        assert_eq!(plane.tessellate(1e-9).triangles.len(), 2);
    }

    #[test]
    fn boxes_enclose() {
        for (name, s) in test_surfaces() {
            let loose = s.bounding_box();
            let tight = s.tight_bounding_box(1e-4);
            assert!(tight.diagonal() <= loose.diagonal());
            let (du, dv) = s.domain();
            for i in 0..=40 {
                for j in 0..=40 {
                    let u = du.start() + (du.end() - du.start()) * i as f64 / 40.0;
                    let v = dv.start() + (dv.end() - dv.start()) * j as f64 / 40.0;
                    let p = s.eval(u, v);
                    // Control points and surface points are rounded separately.
                    assert!(loose.inflated(1e-14).contains(&p), "{name}");
                    assert!(tight.inflated(1e-14).contains(&p), "{name} {p} {tight:?}");
                }
            }
        }
        // The wavy net's control points overshoot the surface: the tight box is smaller.
        let s = wavy_surface();
        assert!(s.tight_bounding_box(1e-4).diagonal() < s.bounding_box().diagonal() - 1e-3);
    }

    #[test]
    fn curve_boxes_enclose() {
        let c = wavy_surface().v_iso(0.5);
        let (loose, tight) = (c.bounding_box(), c.tight_bounding_box(1e-6));
        for i in 0..=500 {
            let p = c.eval(i as f64 / 500.0);
            assert!(loose.contains(&p) && tight.contains(&p));
        }
        assert!(tight.diagonal() <= loose.diagonal());
    }

    #[test]
    fn aabb_operations() {
        let a = Aabb::from_points(&[Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 1.0, 1.0)]).unwrap();
        let b = Aabb::from_points(&[Point3::new(0.5, 0.5, 0.5), Point3::new(2.0, 2.0, 2.0)]).unwrap();
        assert_eq!(a.union(&b).max, Point3::new(2.0, 2.0, 2.0));
        assert_eq!(a.intersection(&b).unwrap().min, Point3::new(0.5, 0.5, 0.5));
        assert!(a.intersection(&b.inflated(-0.6)).is_none());
        assert_eq!(a.inflated(1.0).diagonal(), 3.0 * 3f64.sqrt());
        assert!(Aabb::from_points(&[]).is_none());
    }
}
