//! The closed blade solid: upper and lower faces from one interpolating surface split at
//! the leading edge, ruled tip and root caps (and a ruled trailing-edge face when the
//! trailing edge is open), oriented outward.

use cadmorph_nurbs::math::{Matrix4, Point3};
use cadmorph_nurbs::{Curve, KnotVector, NurbsCurve, NurbsSurface, Surface};

use crate::blade::BladeCoordinates;
use crate::loft::{loft, Lofted};
use crate::{Error, Result};

/// Gauss–Legendre nodes and weights on [−1, 1], 6 points (exact for degree 11, which
/// covers `S · (S_u × S_v)` of bicubic patches, degree 8 per direction).
#[allow(clippy::excessive_precision)]
const GAUSS: [(f64, f64); 6] = [
    (-0.932_469_514_203_152_1, 0.171_324_492_379_170_4),
    (-0.661_209_386_466_264_5, 0.360_761_573_048_138_6),
    (-0.238_619_186_083_196_9, 0.467_913_934_572_691_0),
    (0.238_619_186_083_196_9, 0.467_913_934_572_691_0),
    (0.661_209_386_466_264_5, 0.360_761_573_048_138_6),
    (0.932_469_514_203_152_1, 0.171_324_492_379_170_4),
];

/// The faces of a blade solid and how they were made.
#[derive(Debug, Clone)]
pub struct BladeSolid {
    /// Upper (suction) face, trailing edge → leading edge along u, root → tip along v
    /// (parameter directions may be reversed so that `S_u × S_v` points outward).
    pub upper: NurbsSurface,
    /// Lower (pressure) face.
    pub lower: NurbsSurface,
    /// Tip cap, ruled between the tip boundaries of upper and lower.
    pub tip: NurbsSurface,
    /// Root cap.
    pub root: NurbsSurface,
    /// Trailing-edge face when the sections have an open trailing edge.
    pub trailing: Option<NurbsSurface>,
    /// The interpolating surface before the split (u: TE → upper → LE → lower → TE).
    pub wrapped: Lofted,
    /// Index of the leading-edge point in a wrapped row (= upper points − 1).
    pub le_index: usize,
}

/// Section rows TE → upper → LE → lower → TE, with the leading edge (and a trailing edge
/// closed within `1e-12 ×` chord) made one point; and whether the TE is open.
fn wrapped_rows(c: &BladeCoordinates) -> Result<(Vec<Vec<Point3<f64>>>, bool)> {
    let n = c.up.len();
    if n < 2 || c.down.len() != n {
        return Err(Error::Geometry(format!("{} upper and {} lower sections (at least 2 each)", n, c.down.len())));
    }
    let mut rows = Vec::with_capacity(n);
    let mut open = false;
    for l in 0..n {
        let (up, down) = (&c.up[l], &c.down[l]);
        if up.len() < 2 || down.len() < 2 {
            return Err(Error::table("sections", Some(l), "each side needs at least 2 points"));
        }
        let le = Point3::from((up[0].coords + down[0].coords) / 2.0);
        let (tu, td) = (up[up.len() - 1], down[down.len() - 1]);
        let chord = (tu - le).norm().max((td - le).norm());
        if chord <= 0.0 {
            return Err(Error::table("chord", Some(l), "zero chord"));
        }
        if (up[0] - down[0]).norm() > 1e-6 * chord {
            return Err(Error::table("sections", Some(l), "upper and lower sides do not meet at the leading edge"));
        }
        let gap = (tu - td).norm();
        let closed = gap <= 1e-12 * chord;
        open |= !closed;
        let te = Point3::from((tu.coords + td.coords) / 2.0);
        let mut row: Vec<Point3<f64>> = Vec::with_capacity(up.len() + down.len() - 1);
        row.extend(up.iter().rev().copied());
        row[0] = if closed { te } else { tu };
        let k = row.len() - 1;
        row[k] = le;
        row.extend(down[1..].iter().copied());
        let last = row.len() - 1;
        row[last] = if closed { te } else { td };
        rows.push(row);
    }
    if let Some(l) = rows.iter().position(|r| r.len() != rows[0].len()) {
        return Err(Error::table(
            "sections",
            Some(l),
            format!("{} points, section 0 has {}", rows[l].len(), rows[0].len()),
        ));
    }
    if c.up.iter().any(|s| s.len() != c.up[0].len()) {
        return Err(Error::table("sections", None, "all sections need the same number of upper points"));
    }
    Ok((rows, open))
}

/// The curve with its knots mapped linearly onto [0, 1].
fn unit_domain(c: &NurbsCurve) -> Result<NurbsCurve> {
    let d = c.domain();
    let (a, b) = (*d.start(), *d.end());
    let k: Vec<f64> = c.knots().as_slice().iter().map(|t| ((t - a) / (b - a)).clamp(0.0, 1.0)).collect();
    Ok(NurbsCurve::try_new(c.degree(), KnotVector::try_new(k)?, c.control_points().to_vec(), None)?)
}

/// Inserts into `a` the knots of `b` it lacks (values equal within 1e-12 are one knot).
fn merge_into(a: &mut NurbsCurve, b: &NurbsCurve) -> Result<()> {
    let (av, am) = a.knots().distinct();
    let (bv, bm) = b.knots().distinct();
    let mut add = Vec::new();
    for (v, m) in bv.iter().zip(&bm) {
        if *v <= 0.0 || *v >= 1.0 {
            continue;
        }
        let have = av.iter().zip(&am).find(|(x, _)| (*x - v).abs() <= 1e-12).map_or(0, |(_, m)| *m);
        add.extend(std::iter::repeat_n(*v, m.saturating_sub(have)));
    }
    if !add.is_empty() {
        a.refine(&add)?;
    }
    Ok(())
}

/// The ruled surface `(1 − t) a(s) + t b(s)`, `s, t ∈ [0, 1]`, after bringing both curves
/// to [0, 1] and to common knots (exact: knot insertion keeps the curves).
pub fn ruled(a: &NurbsCurve, b: &NurbsCurve) -> Result<NurbsSurface> {
    let (mut a, mut b) = (unit_domain(a)?, unit_domain(b)?);
    if a.degree() != b.degree() {
        return Err(Error::Geometry("ruled surface between curves of different degree".into()));
    }
    merge_into(&mut a, &b)?;
    merge_into(&mut b, &a)?;
    let n = a.control_points().len();
    if b.control_points().len() != n {
        return Err(Error::Geometry("ruled surface: knots could not be made common".into()));
    }
    let mut net = Vec::with_capacity(2 * n);
    for i in 0..n {
        net.push(a.control_points()[i]);
        net.push(b.control_points()[i]);
    }
    let lin = KnotVector::try_new(vec![0.0, 0.0, 1.0, 1.0])?;
    Ok(NurbsSurface::try_new((a.degree(), 1), (a.knots().clone(), lin), (n, 2), net, None)?)
}

fn center(s: &NurbsSurface) -> (f64, f64) {
    let (ud, vd) = s.domain();
    ((ud.start() + ud.end()) / 2.0, (vd.start() + vd.end()) / 2.0)
}

fn normal_at(s: &NurbsSurface, u: f64, v: f64) -> nalgebra::Vector3<f64> {
    let d = s.eval_d1(u, v);
    d.du.cross(&d.dv)
}

/// `(1/3) ∬ S · (S_u × S_v) du dv` over one face, by Gauss–Legendre on every knot span
/// (divergence theorem: the sum over a closed outward shell is its volume).
pub fn face_volume(s: &NurbsSurface) -> f64 {
    integrate(s, |d| d.point.coords.dot(&d.du.cross(&d.dv)) / 3.0)
}

/// `∬ |S_u × S_v| du dv` over one face.
pub fn face_area(s: &NurbsSurface) -> f64 {
    integrate(s, |d| d.du.cross(&d.dv).norm())
}

fn integrate(s: &NurbsSurface, f: impl Fn(&cadmorph_nurbs::SurfacePointD1) -> f64) -> f64 {
    let (uk, _) = s.u_knots().distinct();
    let (vk, _) = s.v_knots().distinct();
    // Rational faces (the hub) are not polynomial: split each span in 4 (the 6-point
    // rule then integrates a quarter circle to ~1e-15 instead of ~1e-9).
    let split = |k: Vec<f64>| -> Vec<f64> {
        if !s.is_rational() {
            return k;
        }
        let mut out = vec![k[0]];
        for w in k.windows(2) {
            for i in 1..=4 {
                out.push(w[0] + (w[1] - w[0]) * i as f64 / 4.0);
            }
        }
        out
    };
    let (uk, vk) = (split(uk), split(vk));
    let mut total = 0.0;
    for uw in uk.windows(2) {
        for vw in vk.windows(2) {
            let (hu, hv) = ((uw[1] - uw[0]) / 2.0, (vw[1] - vw[0]) / 2.0);
            if hu <= 0.0 || hv <= 0.0 {
                continue;
            }
            for (xu, wu) in GAUSS {
                for (xv, wv) in GAUSS {
                    let d = s.eval_d1(uw[0] + hu * (xu + 1.0), vw[0] + hv * (xv + 1.0));
                    total += wu * wv * hu * hv * f(&d);
                }
            }
        }
    }
    total
}

/// The gap along one edge of the solid.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EdgeGap {
    /// The two faces (indices into [`BladeSolid::faces`]).
    pub faces: [usize; 2],
    /// Largest distance found.
    pub gap: f64,
}

/// Per-section interpolation errors: the largest distance between a section point and
/// the face at the point's parameters, upper and lower side.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SectionError {
    /// Section index, root first.
    pub section: usize,
    /// Largest upper-side distance.
    pub upper: f64,
    /// Largest lower-side distance.
    pub lower: f64,
}

impl BladeSolid {
    /// Builds the solid from section points (root first), interpolating with degree `p`
    /// along the sections and `q` across them (P&T A9.4, see [`loft`]).
    ///
    /// # Errors
    ///
    /// [`Error::Table`] naming the section whose sides do not meet at the leading edge or
    /// whose point count differs; errors of the loft.
    pub fn from_coordinates(c: &BladeCoordinates, p: usize, q: usize) -> Result<Self> {
        let (rows, open) = wrapped_rows(c)?;
        let le_index = c.up[0].len() - 1;
        let wrapped = loft(&rows, p, q)?;
        let le_u = wrapped.u[le_index];
        let (mut upper, mut lower) = wrapped.surface.split_u(le_u)?;
        // Outward: at mid-span the normal of the upper face points away from the lower.
        let (uc, vc) = (le_u / 2.0, 0.5);
        let pu = upper.eval(uc, vc);
        let pl = lower.eval((le_u + 1.0) / 2.0, vc);
        if normal_at(&upper, uc, vc).dot(&(pu - pl)) < 0.0 {
            upper = upper.u_reversed();
            lower = lower.u_reversed();
        }
        let tip_a = upper.boundary(cadmorph_nurbs::Side::VMax);
        let tip_b = lower.boundary(cadmorph_nurbs::Side::VMax);
        let root_a = upper.boundary(cadmorph_nurbs::Side::VMin);
        let root_b = lower.boundary(cadmorph_nurbs::Side::VMin);
        // Upper runs towards one edge and lower away from it: reverse one to rule them.
        let same = |a: &NurbsCurve, b: &NurbsCurve| {
            let (da, db) = (a.domain(), b.domain());
            (a.eval(*da.start()) - b.eval(*db.start())).norm() <= (a.eval(*da.start()) - b.eval(*db.end())).norm()
        };
        let rule = |a: &NurbsCurve, b: &NurbsCurve| if same(a, b) { ruled(a, b) } else { ruled(&a.reversed(), b) };
        let mut tip = rule(&tip_a, &tip_b)?;
        let mut root = rule(&root_a, &root_b)?;
        let (ud, _) = upper.domain();
        let um = (ud.start() + ud.end()) / 2.0;
        let sv = |v: f64| upper.eval_d1(um, v).dv;
        let (tu, tv) = center(&tip);
        if normal_at(&tip, tu, tv).dot(&sv(1.0)) < 0.0 {
            tip = tip.u_reversed();
        }
        let (ru, rv) = center(&root);
        if normal_at(&root, ru, rv).dot(&sv(0.0)) > 0.0 {
            root = root.u_reversed();
        }
        let trailing = if open {
            // The u ends of upper and lower that are not the leading edge.
            let le_pt = c.up[0][0];
            let pick = |s: &NurbsSurface| {
                let a = s.boundary(cadmorph_nurbs::Side::UMin);
                let b = s.boundary(cadmorph_nurbs::Side::UMax);
                let d = a.domain();
                if (a.eval(*d.start()) - le_pt).norm() < (b.eval(*d.start()) - le_pt).norm() {
                    b
                } else {
                    a
                }
            };
            let mut t = ruled(&pick(&upper), &pick(&lower))?;
            // Outward: away from the leading edge.
            let (a, b) = center(&t);
            if normal_at(&t, a, b).dot(&(t.eval(a, b) - le_pt)) < 0.0 {
                t = t.u_reversed();
            }
            Some(t)
        } else {
            None
        };
        Ok(Self { upper, lower, tip, root, trailing, wrapped, le_index })
    }

    /// The faces, outward: upper, lower, tip, root and the trailing-edge face if any.
    pub fn faces(&self) -> Vec<&NurbsSurface> {
        let mut f = vec![&self.upper, &self.lower, &self.tip, &self.root];
        if let Some(t) = &self.trailing {
            f.push(t);
        }
        f
    }

    /// The enclosed volume (divergence theorem over the faces; exact up to round-off for
    /// polynomial faces, see [`face_volume`]).
    pub fn volume(&self) -> f64 {
        self.faces().iter().map(|s| face_volume(s)).sum()
    }

    /// The surface area.
    pub fn area(&self) -> f64 {
        self.faces().iter().map(|s| face_area(s)).sum()
    }

    /// Applies the affine map `m` (rotation, scaling, mirror); a map that reverses
    /// orientation (negative determinant) also reverses the faces so they stay outward.
    pub fn transform_by(&mut self, m: &Matrix4<f64>) {
        let flip = m.fixed_view::<3, 3>(0, 0).determinant() < 0.0;
        let t = |s: &mut NurbsSurface| {
            s.transform_by(m);
            if flip {
                *s = s.u_reversed();
            }
        };
        t(&mut self.upper);
        t(&mut self.lower);
        t(&mut self.tip);
        t(&mut self.root);
        if let Some(s) = &mut self.trailing {
            t(s);
        }
        self.wrapped.surface.transform_by(m);
    }

    /// The gap of every edge of the solid's topology (the edges the STEP and IGES
    /// writers share between faces, found as they find them within `tol`): `samples`
    /// points of one face's boundary projected onto the other face's boundary curve.
    /// An edge used by only one face (a hole in the shell) has an infinite gap.
    pub fn edge_gaps(&self, tol: f64, samples: usize) -> Vec<EdgeGap> {
        use cadmorph_nurbs::CurveProject;
        let faces = self.faces();
        let shell = crate::export::shell_topology(&faces, tol);
        shell
            .uses
            .iter()
            .map(|u| match u.as_slice() {
                [(fa, sa), (fb, sb)] => {
                    let (a, b) = (faces[*fa].boundary(*sa), faces[*fb].boundary(*sb));
                    let d = a.domain();
                    let n = samples.max(2);
                    let gap = (0..n)
                        .map(|i| {
                            let p = a.eval(d.start() + (d.end() - d.start()) * i as f64 / (n - 1) as f64);
                            b.project(&p, 1e-3 * tol).distance_sq.sqrt()
                        })
                        .fold(0.0, f64::max);
                    EdgeGap { faces: [*fa, *fb], gap }
                }
                other => EdgeGap { faces: [other.first().map_or(0, |x| x.0), usize::MAX], gap: f64::INFINITY },
            })
            .collect()
    }

    /// The seams between the faces as `cadmorph-seam` finds and measures them: every
    /// pair of coinciding iso-boundaries within `tol`, sampled at `samples` points
    /// (C0 gap, G1 angle). Round leading edge: 0° there; the trailing edge and the caps
    /// are sharp edges by construction.
    pub fn seams(&self, tol: f64, samples: usize) -> cadmorph_seam::SeamReport {
        let faces = self.faces();
        let edges = cadmorph_seam::shared_boundaries(&faces, tol, 32, 0.9);
        let fs: Vec<cadmorph_seam::Face> =
            faces.iter().map(|s| cadmorph_seam::Face { surface: s, reversed: false }).collect();
        cadmorph_seam::SeamReport::new(edges.iter().map(|e| cadmorph_seam::measure_boundary(&fs, e, samples)).collect())
    }

    /// Distances between the section points and the wrapped surface at their
    /// parameters, per section (the figures of BladeX's `errors.txt`, which measures them
    /// by projection; a distance at the assigned parameters bounds the projection's).
    pub fn section_errors(&self, c: &BladeCoordinates) -> Result<Vec<SectionError>> {
        let (rows, _) = wrapped_rows(c)?;
        let s = &self.wrapped.surface;
        Ok(rows
            .iter()
            .enumerate()
            .map(|(l, row)| {
                let v = self.wrapped.v[l];
                let d = |k: usize| (s.eval(self.wrapped.u[k], v) - row[k]).norm();
                let upper = (0..=self.le_index).map(d).fold(0.0, f64::max);
                let lower = (self.le_index..row.len()).map(d).fold(0.0, f64::max);
                SectionError { section: l, upper, lower }
            })
            .collect())
    }
}
