//! Inverse distance weighting (paper §2.1.3, eq. (6)–(10)), in the paper's form and in the
//! form PyGeM actually computes.

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use crate::deformation::{check_params, ParamWeights, PARALLEL_CHUNK, PARALLEL_MIN_POINTS};
use crate::{Deformation, Error, LinearInParameters, Result};

/// Which inverse-distance weights an [`Idw`] uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IdwVariant {
    /// The paper's eq. (7)–(8): Euclidean distance d, weight `d⁻ᵖ`, and with a cutoff
    /// ε only the control points with `d < ε` count (found with a k-d tree); a point with
    /// none within ε does not move. As the paper writes it, the map jumps where a control
    /// point enters or leaves the cutoff ball.
    Paper {
        /// Power p > 0.
        power: f64,
        /// Cutoff radius ε, or `None` for all control points.
        cutoff: Option<f64>,
    },
    /// What PyGeM's `IDW.__call__` computes (and what its docstring does not say): distance
    /// `‖x − c‖ₚ` in the Minkowski p-norm (`numpy.linalg.norm(ord=p)`), weight `1/d`.
    /// Reading a PyGeM `.prm` file selects this variant.
    PyGem {
        /// PyGeM's `power`: the order of the Minkowski norm.
        power: u32,
    },
}

/// The parameters of an IDW: variant, control points before and after the deformation.
#[derive(Debug, Clone, PartialEq)]
pub struct IdwParameters {
    /// Weights used.
    pub variant: IdwVariant,
    /// Control points before the deformation.
    pub original: Vec<Point3<f64>>,
    /// Control points after the deformation (same count).
    pub deformed: Vec<Point3<f64>>,
}

/// Inverse distance weighting of control-point displacements (paper eq. (9)):
///
/// ```text
/// φ(x) = x + Σᵢ wᵢ(x) δᵢ,   wᵢ(x) = g(dᵢ) / Σⱼ g(dⱼ),   δᵢ = deformed_i − original_i
/// ```
///
/// with `g(d) = d⁻ᵖ` (paper) or `1/‖x − cᵢ‖ₚ` (PyGeM), see [`IdwVariant`]. At a control
/// point the weight is 1 for it and 0 for the others (the mean over coincident control
/// points), so φ reproduces the control displacements.
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Deformation, Idw, IdwVariant};
/// use cadmorph_morph::math::{Point3, Vector3};
/// let centres = [Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0)];
/// let moves = [Vector3::zeros(), Vector3::new(0.0, 1.0, 0.0)];
/// let idw = Idw::try_new(&centres, &moves, IdwVariant::Paper { power: 2.0, cutoff: None })?;
/// assert_eq!(idw.deform_point(&centres[1]), Point3::new(1.0, 1.0, 0.0));
/// assert!((idw.deform_point(&Point3::new(0.5, 0.0, 0.0)).y - 0.5).abs() < 1e-15);
/// # Ok::<(), cadmorph_morph::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Idw {
    variant: IdwVariant,
    centres: Vec<Point3<f64>>,
    displacements: Vec<Vector3<f64>>,
    // Structure of arrays for the vectorised loops.
    cx: Vec<f64>,
    cy: Vec<f64>,
    cz: Vec<f64>,
    dx: Vec<f64>,
    dy: Vec<f64>,
    dz: Vec<f64>,
    tree: Option<ImmutableKdTree<f64, 3>>,
}

impl Idw {
    /// An IDW moving `centres[i]` by `displacements[i]`.
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] for unequal or empty lists, [`Error::InvalidParameter`] for
    /// a non-finite coordinate, a power ≤ 0 (paper) or 0 (PyGeM), a cutoff ≤ 0.
    pub fn try_new(centres: &[Point3<f64>], displacements: &[Vector3<f64>], variant: IdwVariant) -> Result<Idw> {
        if centres.is_empty() {
            return Err(Error::CountMismatch { line: 0, what: "control points", expected: 1, found: 0 });
        }
        if centres.len() != displacements.len() {
            return Err(Error::CountMismatch {
                line: 0,
                what: "displacements (one per control point)",
                expected: centres.len(),
                found: displacements.len(),
            });
        }
        for v in centres.iter().flat_map(|p| p.iter()).chain(displacements.iter().flat_map(|d| d.iter())) {
            if !v.is_finite() {
                return Err(Error::InvalidParameter {
                    line: None,
                    name: "control point",
                    value: *v,
                    reason: "must be finite",
                });
            }
        }
        let tree = match variant {
            IdwVariant::Paper { power, cutoff } => {
                if !(power.is_finite() && power > 0.0) {
                    return Err(Error::InvalidParameter {
                        line: None,
                        name: "power",
                        value: power,
                        reason: "must be positive and finite",
                    });
                }
                match cutoff {
                    Some(eps) if !(eps.is_finite() && eps > 0.0) => {
                        return Err(Error::InvalidParameter {
                            line: None,
                            name: "cutoff",
                            value: eps,
                            reason: "must be positive and finite",
                        });
                    }
                    Some(_) => {
                        let pts: Vec<[f64; 3]> = centres.iter().map(|p| [p.x, p.y, p.z]).collect();
                        Some(ImmutableKdTree::new_from_slice(&pts))
                    }
                    None => None,
                }
            }
            IdwVariant::PyGem { power } => {
                if power == 0 {
                    return Err(Error::InvalidParameter {
                        line: None,
                        name: "power",
                        value: 0.0,
                        reason: "Minkowski order must be at least 1",
                    });
                }
                None
            }
        };
        Ok(Idw {
            variant,
            centres: centres.to_vec(),
            displacements: displacements.to_vec(),
            cx: centres.iter().map(|p| p.x).collect(),
            cy: centres.iter().map(|p| p.y).collect(),
            cz: centres.iter().map(|p| p.z).collect(),
            dx: displacements.iter().map(|d| d.x).collect(),
            dy: displacements.iter().map(|d| d.y).collect(),
            dz: displacements.iter().map(|d| d.z).collect(),
            tree,
        })
    }

    /// The IDW described by `params`.
    ///
    /// # Errors
    ///
    /// As [`Idw::try_new`].
    pub fn from_parameters(params: &IdwParameters) -> Result<Idw> {
        let d = crate::deformation::displacements(&params.original, &params.deformed)?;
        Idw::try_new(&params.original, &d, params.variant)
    }

    /// The parameters (control points before and after).
    pub fn parameters(&self) -> IdwParameters {
        IdwParameters {
            variant: self.variant,
            original: self.centres.clone(),
            deformed: self.centres.iter().zip(&self.displacements).map(|(c, d)| c + d).collect(),
        }
    }

    /// The variant.
    pub fn variant(&self) -> IdwVariant {
        self.variant
    }
    /// Control points.
    pub fn centres(&self) -> &[Point3<f64>] {
        &self.centres
    }
    /// Control displacements δᵢ.
    pub fn displacements(&self) -> &[Vector3<f64>] {
        &self.displacements
    }

    /// Unnormalised weight g(d) from the difference vector `x − c`.
    #[inline(always)]
    fn g(&self, v: &Vector3<f64>) -> f64 {
        match self.variant {
            IdwVariant::Paper { power, .. } => inv_pow_sq(v.norm_squared(), power),
            IdwVariant::PyGem { power } => 1.0 / minkowski(v, power),
        }
    }

    /// The normalised weights `(i, wᵢ(x))` with nonzero weight.
    pub fn weights(&self, x: &Point3<f64>) -> Vec<(usize, f64)> {
        let candidates: Vec<usize> = match (&self.tree, self.variant) {
            (Some(tree), IdwVariant::Paper { cutoff: Some(eps), .. }) => {
                let mut v: Vec<usize> = tree
                    .within_unsorted::<SquaredEuclidean>(&[x.x, x.y, x.z], eps * eps)
                    .into_iter()
                    .filter(|n| n.distance < eps * eps)
                    .map(|n| n.item as usize)
                    .collect();
                v.sort_unstable();
                v
            }
            _ => (0..self.centres.len()).collect(),
        };
        let hits: Vec<usize> = candidates.iter().copied().filter(|&i| self.centres[i] == *x).collect();
        if !hits.is_empty() {
            let w = 1.0 / hits.len() as f64;
            return hits.into_iter().map(|i| (i, w)).collect();
        }
        let g: Vec<f64> = candidates.iter().map(|&i| self.g(&(x - self.centres[i]))).collect();
        let s: f64 = g.iter().sum();
        if s == 0.0 || !s.is_finite() {
            return Vec::new();
        }
        candidates.into_iter().zip(g).map(|(i, gi)| (i, gi / s)).collect()
    }

    /// Deform a block of points on the calling thread.
    fn deform_serial(&self, points: &mut [Point3<f64>]) {
        if self.tree.is_some() {
            for p in points {
                *p = self.deform_point(p);
            }
            return;
        }
        for block in points.chunks_mut(LANES) {
            let mut px = [0.0; LANES];
            let mut py = [0.0; LANES];
            let mut pz = [0.0; LANES];
            for (lane, p) in block.iter().enumerate() {
                px[lane] = p.x;
                py[lane] = p.y;
                pz[lane] = p.z;
            }
            let sums = match self.variant {
                IdwVariant::Paper { power: 2.0, .. } => self.sums(&px, &py, &pz, |d2| 1.0 / d2),
                IdwVariant::Paper { power, .. } => self.sums(&px, &py, &pz, |d2| inv_pow_sq(d2, power)),
                IdwVariant::PyGem { power: 2 } => self.sums(&px, &py, &pz, |d2| 1.0 / d2.sqrt()),
                IdwVariant::PyGem { .. } => {
                    for p in block.iter_mut() {
                        *p = self.deform_point(p);
                    }
                    continue;
                }
            };
            for (lane, p) in block.iter_mut().enumerate() {
                if sums.min_d2[lane] == 0.0 {
                    *p = self.deform_point(p); // exactly on a control point
                } else {
                    let inv = 1.0 / sums.den[lane];
                    *p += Vector3::new(sums.num[0][lane] * inv, sums.num[1][lane] * inv, sums.num[2][lane] * inv);
                }
            }
        }
    }

    /// Weighted sums over all control points for `LANES` points, with `g` a function of d².
    #[inline(always)]
    fn sums<G: Fn(f64) -> f64>(&self, px: &[f64; LANES], py: &[f64; LANES], pz: &[f64; LANES], g: G) -> Sums {
        crate::simd::dispatch(SumsOp { idw: self, px, py, pz, g })
    }
}

/// The IDW sum loop, compiled inside `pulp`'s target-feature function.
struct SumsOp<'a, G> {
    idw: &'a Idw,
    px: &'a [f64; LANES],
    py: &'a [f64; LANES],
    pz: &'a [f64; LANES],
    g: G,
}

impl<G: Fn(f64) -> f64> pulp::WithSimd for SumsOp<'_, G> {
    type Output = Sums;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Sums {
        let SumsOp { idw, px, py, pz, g } = self;
        let mut s = Sums { num: [[0.0; LANES]; 3], den: [0.0; LANES], min_d2: [f64::INFINITY; LANES] };
        for i in 0..idw.cx.len() {
            let (cx, cy, cz) = (idw.cx[i], idw.cy[i], idw.cz[i]);
            let (dx, dy, dz) = (idw.dx[i], idw.dy[i], idw.dz[i]);
            for lane in 0..LANES {
                let (a, b, c) = (px[lane] - cx, py[lane] - cy, pz[lane] - cz);
                let d2 = a * a + b * b + c * c;
                let w = g(d2);
                s.min_d2[lane] = s.min_d2[lane].min(d2);
                s.den[lane] += w;
                s.num[0][lane] += w * dx;
                s.num[1][lane] += w * dy;
                s.num[2][lane] += w * dz;
            }
        }
        s
    }
}

const LANES: usize = 8;

struct Sums {
    num: [[f64; LANES]; 3],
    den: [f64; LANES],
    min_d2: [f64; LANES],
}

/// `d⁻ᵖ` from `d²`.
#[inline(always)]
fn inv_pow_sq(d2: f64, power: f64) -> f64 {
    d2.powf(-0.5 * power)
}

/// `‖v‖ₚ` as `numpy.linalg.norm(v, ord=p)` computes it.
#[inline(always)]
fn minkowski(v: &Vector3<f64>, p: u32) -> f64 {
    match p {
        1 => v.x.abs() + v.y.abs() + v.z.abs(),
        2 => v.norm_squared().sqrt(),
        _ => {
            let s: f64 = v.iter().map(|c| c.abs().powi(p as i32)).sum();
            s.powf(1.0 / p as f64)
        }
    }
}

/// ∇‖v‖ₚ (v ≠ 0).
fn minkowski_grad(v: &Vector3<f64>, p: u32) -> Vector3<f64> {
    let n = minkowski(v, p);
    v.map(|c| c.signum() * (c.abs() / n).powi(p as i32 - 1))
}

impl Deformation for Idw {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        let mut d = Vector3::zeros();
        for (i, w) in self.weights(p) {
            d += w * self.displacements[i];
        }
        p + d
    }

    fn deform(&self, points: &mut [Point3<f64>]) {
        if points.len() >= PARALLEL_MIN_POINTS / 4 {
            points.par_chunks_mut(PARALLEL_CHUNK / 4).for_each(|c| self.deform_serial(c));
        } else {
            self.deform_serial(points);
        }
    }

    /// `I + Σᵢ (δᵢ − D(x)) ∇gᵢᵀ / Σⱼ gⱼ`, with `D` the displacement at x. At a control point
    /// the map is flat (J = I) for the paper's weights with p > 1, and not differentiable
    /// (`None`) for p ≤ 1 and for PyGeM's `1/d` weights. The jumps of the cutoff form at
    /// `d = ε` are not part of this derivative.
    fn jacobian(&self, x: &Point3<f64>) -> Option<Matrix3<f64>> {
        let weights = self.weights(x);
        if weights.is_empty() {
            return Some(Matrix3::identity());
        }
        if weights.iter().any(|&(i, _)| self.centres[i] == *x) {
            return match self.variant {
                IdwVariant::Paper { power, .. } if power > 1.0 => Some(Matrix3::identity()),
                _ => None,
            };
        }
        let mut disp = Vector3::zeros();
        for &(i, w) in &weights {
            disp += w * self.displacements[i];
        }
        let mut sum_g = 0.0;
        let mut acc = Matrix3::zeros();
        for &(i, _) in &weights {
            let v = x - self.centres[i];
            let (g, grad) = match self.variant {
                IdwVariant::Paper { power, .. } => {
                    let d2 = v.norm_squared();
                    let g = inv_pow_sq(d2, power);
                    (g, -power * g / d2 * v)
                }
                IdwVariant::PyGem { power } => {
                    let n = minkowski(&v, power);
                    (1.0 / n, -minkowski_grad(&v, power) / (n * n))
                }
            };
            sum_g += g;
            acc += (self.displacements[i] - disp) * grad.transpose();
        }
        Some(Matrix3::identity() + acc / sum_g)
    }
}

impl LinearInParameters for Idw {
    /// `3 · Nc`: `[δx of all control points, δy, δz]`.
    fn n_params(&self) -> usize {
        3 * self.centres.len()
    }
    fn params(&self) -> Vec<f64> {
        [self.dx.as_slice(), &self.dy, &self.dz].concat()
    }
    fn set_params(&mut self, theta: &[f64]) -> Result<()> {
        check_params(theta, self.n_params())?;
        let n = self.centres.len();
        self.dx.copy_from_slice(&theta[..n]);
        self.dy.copy_from_slice(&theta[n..2 * n]);
        self.dz.copy_from_slice(&theta[2 * n..]);
        for i in 0..n {
            self.displacements[i] = Vector3::new(self.dx[i], self.dy[i], self.dz[i]);
        }
        Ok(())
    }
    fn param_weights(&self, p: &Point3<f64>) -> ParamWeights {
        ParamWeights { n_nodes: self.centres.len(), weights: self.weights(p), frame: Matrix3::identity() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minkowski_matches_definition() {
        let v = Vector3::new(1.0, -2.0, 3.0);
        assert_eq!(minkowski(&v, 1), 6.0);
        assert!((minkowski(&v, 2) - 14f64.sqrt()).abs() < 1e-15);
        assert!((minkowski(&v, 3) - 36f64.powf(1.0 / 3.0)).abs() < 1e-15);
        let h = 1e-6;
        let g = minkowski_grad(&v, 3);
        for a in 0..3 {
            let mut e = Vector3::zeros();
            e[a] = h;
            let fd = (minkowski(&(v + e), 3) - minkowski(&(v - e), 3)) / (2.0 * h);
            assert!((g[a] - fd).abs() < 1e-8);
        }
    }

    /// The bulk sums (SIMD, in each instruction set the CPU has) against the point-by-point
    /// formula, with and without the PyGeM variant, points on control points included.
    #[test]
    fn bulk_sums_match_point_by_point_in_every_instruction_set() {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let c: Vec<Point3<f64>> = (0..37).map(|_| Point3::new(next(), next(), next())).collect();
        let d: Vec<Vector3<f64>> = (0..37).map(|_| Vector3::new(next(), next(), next()) * 0.1).collect();
        let pts: Vec<Point3<f64>> =
            (0..203).map(|_| Point3::new(next(), next(), next())).chain([c[0], c[36]]).collect();
        for variant in [IdwVariant::Paper { power: 2.0, cutoff: None }, IdwVariant::PyGem { power: 3 }] {
            let idw = Idw::try_new(&c, &d, variant).unwrap();
            let one: Vec<Point3<f64>> = pts.iter().map(|p| idw.deform_point(p)).collect();
            crate::simd::for_each_isa(|isa| {
                let mut bulk = pts.clone();
                idw.deform(&mut bulk);
                for (k, (a, b)) in bulk.iter().zip(&one).enumerate() {
                    assert!((a - b).amax() <= 1e-14, "{isa} {variant:?} point {k}: {a} vs {b}");
                }
            });
        }
    }

    #[test]
    fn cutoff_excludes_far_points_and_leaves_lonely_points() {
        let c = [Point3::new(0.0, 0.0, 0.0), Point3::new(10.0, 0.0, 0.0)];
        let d = [Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 5.0, 0.0)];
        let idw = Idw::try_new(&c, &d, IdwVariant::Paper { power: 2.0, cutoff: Some(1.0) }).unwrap();
        let p = Point3::new(0.5, 0.0, 0.0);
        assert_eq!(idw.deform_point(&p), Point3::new(1.5, 0.0, 0.0));
        let lonely = Point3::new(5.0, 0.0, 0.0);
        assert_eq!(idw.deform_point(&lonely), lonely);
        assert!(Idw::try_new(&c, &d, IdwVariant::Paper { power: 2.0, cutoff: Some(0.0) }).is_err());
    }
}
