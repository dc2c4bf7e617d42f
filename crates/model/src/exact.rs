//! The exact FFD (`cadmorph morph --exact`): faces and curves that lie in the lattice's
//! box are replaced by their exact image under the FFD, the composition of the FFD's
//! Bernstein volume with the patch ([`cadmorph_nurbs::BezierVolume`], degree
//! `p·(l+m+n)` for an `(l+1)×(m+1)×(n+1)` lattice), followed by knot removal within a
//! tolerance; faces that cross the box are morphed (and refined) as [`Model::morph`]
//! does.

use cadmorph_brep::{CadDocument, EntityRef};
use cadmorph_morph::Ffd;
use cadmorph_nurbs::math::{Matrix3, Point3};
use cadmorph_nurbs::{BezierVolume, NurbsCurve, NurbsSurface};
use serde::Serialize;

use crate::model::{Model, Progress};
use crate::morph::{MorphOptions, MorphOutcome};
use crate::{Error, Result};

/// Unit-box tolerance within which a control point on the box's faces counts as inside
/// (the FFD's own face tolerance, `cadmorph_morph::ffd::FACE_TOL`).
const INSIDE_TOL: f64 = cadmorph_morph::ffd::FACE_TOL;

/// How far, in units of the largest lattice node coordinate's ulp, lowering the
/// lattice's degrees ([`BezierVolume::lowered`]) may move the map: rounding only, so the
/// exact image stays exact.
const LOWERING_ULPS: f64 = 256.0;

/// An FFD as an exact map of NURBS: the Bézier volume `V` with `V(ψ(x)) = φ(x)` in the
/// box (paper eq. (1)–(2)), and the tolerance of the knot removal that follows each
/// composition.
///
/// # Examples
///
/// ```
/// use cadmorph_model::ExactFfd;
/// use cadmorph_morph::Ffd;
/// let mut ffd = Ffd::unit([2, 3, 2]);
/// ffd.mu_mut().set(1, 1, 1, [0.0, 0.0, 0.1]);
/// let exact = ExactFfd::new(&ffd, 1e-12)?;
/// assert_eq!(exact.degree_factor(), 1 + 2 + 1); // a bicubic face becomes degree 12
/// # Ok::<(), cadmorph_model::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct ExactFfd {
    volume: BezierVolume,
    lattice_degrees: [usize; 3],
    lowering_bound: f64,
    moves: bool,
    removal_tol: f64,
}

/// What the exact path of [`Model::morph_exact`] did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ExactReport {
    /// Faces replaced by their exact image.
    pub exact_faces: usize,
    /// Faces that cross the box (or hold control points at infinity), morphed as by
    /// [`Model::morph`].
    pub other_faces: usize,
    /// Bound curves replaced by their exact image.
    pub exact_curves: usize,
    /// The lattice's degrees per direction (nodes minus one).
    pub lattice_degrees: [usize; 3],
    /// The degrees of the polynomial map the composition used: the lattice's, lowered
    /// where the displacements make a lower-degree polynomial (to rounding,
    /// [`BezierVolume::lowered`]).
    pub map_degrees: [usize; 3],
    /// The bound on how far lowering the degrees moved the map (model units; rounding).
    pub lowering_bound: f64,
    /// Control points of the exact faces as composed, before knot removal.
    pub composed_control_points: usize,
    /// Control points of the exact faces as written.
    pub written_control_points: usize,
    /// The largest bound on how far knot removal moved an exact face (model units).
    pub removal_bound: f64,
    /// The largest bound on how far the degree reduction of an exact image above degree
    /// 25 moved it (model units; 0 when none needed one). With `removal_bound` it stays
    /// within the exact form's tolerance.
    pub reduction_bound: f64,
}

impl ExactFfd {
    /// The exact form of `ffd`, with knot removal within `removal_tol` (model units) after
    /// each composition (`0` keeps every knot the composition makes).
    ///
    /// # Errors
    ///
    /// [`Error::Exact`] when the lattice's degree is above 25 in a direction;
    /// [`Error::Unsupported`] when `removal_tol` is negative or not finite.
    pub fn new(ffd: &Ffd, removal_tol: f64) -> Result<Self> {
        if !(removal_tol.is_finite() && removal_tol >= 0.0) {
            return Err(Error::Unsupported("the knot removal tolerance of the exact FFD must be finite and >= 0"));
        }
        let [l, m, n] = ffd.n_control_points();
        let len = ffd.box_length();
        let to_unit = Matrix3::from_diagonal(&len.map(|x| 1.0 / x)) * ffd.rotation().transpose();
        let nodes = ffd.control_points(true);
        let scale = nodes.iter().flat_map(|p| p.iter()).fold(0.0f64, |a, &c| a.max(c.abs()));
        let lattice_degrees = [l - 1, m - 1, n - 1];
        let full = BezierVolume::try_new(lattice_degrees, nodes, ffd.box_origin(), to_unit)
            .map_err(|source| Error::Exact { what: "the lattice".into(), source })?;
        let (volume, lowering_bound) = full.lowered(LOWERING_ULPS * f64::EPSILON * scale);
        let mu = ffd.mu();
        let moves = mu.x.iter().chain(&mu.y).chain(&mu.z).any(|&v| v != 0.0);
        Ok(Self { volume, lattice_degrees, lowering_bound, moves, removal_tol })
    }

    /// `l + m + n` of the map's degrees (the lattice's, lowered where the displacements
    /// allow; see [`BezierVolume::lowered`]): the factor a patch's degrees are
    /// multiplied by.
    pub fn degree_factor(&self) -> usize {
        self.volume.degree_factor()
    }

    /// The Bézier volume.
    pub fn volume(&self) -> &BezierVolume {
        &self.volume
    }

    /// Whether the FFD moves anything (some μ is not zero).
    pub fn moves(&self) -> bool {
        self.moves
    }

    /// Whether every control point lies in the closed box and every weight is positive:
    /// then the whole curve or surface does (convex hull), and its image is exact.
    fn holds(&self, points: &[Point3<f64>], weights: Option<&[f64]>) -> bool {
        weights.is_none_or(|w| w.iter().all(|&w| w > 0.0)) && points.iter().all(|p| self.volume.contains(p, INSIDE_TOL))
    }

    /// Whether `s` lies in the box (every control point in the closed box, every weight positive) and the FFD moves anything.
    pub fn holds_surface(&self, s: &NurbsSurface) -> bool {
        self.moves && self.holds(s.control_points(), s.weights())
    }

    /// Whether `c` lies in the box and the FFD moves anything.
    pub fn holds_curve(&self, c: &NurbsCurve) -> bool {
        self.moves && self.holds(c.control_points(), c.weights())
    }

    /// The exact image of `s`, reduced to degree 25 where it needs more (within the
    /// tolerance, [`NurbsSurface::composed_within`]), its surplus knots removed within
    /// what the reduction left of the tolerance; returns it with the control points
    /// composed, the removal's bound and the reduction's bound (their sum is within the
    /// tolerance).
    ///
    /// # Errors
    ///
    /// The kernel's [`ComposedDegree`](cadmorph_nurbs::Error::ComposedDegree) (above
    /// degree 64, or above 25 with a zero tolerance),
    /// [`ComposedReduction`](cadmorph_nurbs::Error::ComposedReduction) (the reduction to
    /// 25 would move it further than the tolerance) or a non-finite result, as
    /// [`Error::Exact`] naming `entity`.
    pub fn surface(&self, s: &NurbsSurface, entity: EntityRef) -> Result<(NurbsSurface, usize, f64, f64)> {
        let (mut r, reduction) = s
            .composed_within(&self.volume, self.removal_tol)
            .map_err(|source| Error::Exact { what: format!("face {entity}"), source })?;
        let composed = r.control_points().len();
        let left = self.removal_tol - reduction;
        let bound = if left > 0.0 { r.remove_knots_within(left).bound } else { 0.0 };
        Ok((r, composed, bound, reduction))
    }

    /// The exact image of `c`, reduced and its surplus knots removed as
    /// [`surface`](Self::surface) does.
    ///
    /// # Errors
    ///
    /// As [`surface`](Self::surface).
    pub fn curve(&self, c: &NurbsCurve, entity: EntityRef) -> Result<NurbsCurve> {
        let (mut r, reduction) = c
            .composed_within(&self.volume, self.removal_tol)
            .map_err(|source| Error::Exact { what: format!("curve {entity}"), source })?;
        let left = self.removal_tol - reduction;
        if left > 0.0 {
            r.remove_knots_within(left);
        }
        Ok(r)
    }
}

impl<D: CadDocument> Model<D> {
    /// Morphs the model with `ffd`, exactly where it can: every face whose control
    /// points lie in the box (and, in STEP, every edge curve bounding such a face that
    /// does too; IGES trimming curves are traced on the exact face as by
    /// [`morph`](Self::morph), because OCCT's IGES reader fails to re-parameterize the
    /// exact image of a conic arc against its parameter-space curve) becomes its exact
    /// image under the FFD ([`ExactFfd`]: degree `p·(l+m+n)`, reduced to 25 within the
    /// exact form's tolerance where it is higher, then knot removal within what is left
    /// of that tolerance), analytic faces through their
    /// exact B-spline form; the other faces go the way of [`morph`](Self::morph), with
    /// `opts`' refinement for the edges that touch them. Exact faces keep their
    /// parameters, so edges shared by two of them have the input's gaps mapped by the
    /// FFD (zero stays zero, to rounding and the removal tolerance).
    ///
    /// # Errors
    ///
    /// [`Error::Exact`] before the document changes when a face or curve in the box
    /// would need a degree above 25 that cannot be reduced to 25 within the exact form's
    /// tolerance (or above 64), naming the degree; [`Error::Unsupported`] with
    /// `opts.repair` or `opts.uniform_knots` (they edit the nets the composition
    /// replaces); those of [`morph`](Self::morph).
    pub fn morph_exact(
        &mut self,
        ffd: &Ffd,
        exact: &ExactFfd,
        opts: &MorphOptions,
        progress: &dyn Progress,
    ) -> Result<(MorphOutcome, ExactReport)> {
        if opts.repair || opts.uniform_knots.is_some() {
            return Err(Error::Unsupported("the exact FFD takes no --repair or --uniform-knots"));
        }
        let inside: Vec<bool> = self.faces.iter().map(|f| exact.holds_surface(&f.surface)).collect();
        // Refuse before anything changes: every face or curve whose exact image needs a
        // degree above 25 is composed and reduced here once (the others always compose).
        let d = exact.degree_factor();
        let over = |p: usize| p * d > cadmorph_nurbs::MAX_DEGREE;
        for (face, _) in self.faces.iter().zip(&inside).filter(|(_, &i)| i) {
            if over(face.surface.u_degree()) || over(face.surface.v_degree()) {
                exact.surface(&face.surface, face.entity)?;
            }
        }
        for b in self.bounds.iter().filter(|b| inside[b.face] && exact.holds_curve(&b.curve)) {
            if over(b.curve.degree()) {
                exact.curve(&b.curve, b.label)?;
            }
        }
        let mut report = ExactReport {
            lattice_degrees: exact.lattice_degrees,
            map_degrees: exact.volume.degrees(),
            lowering_bound: exact.lowering_bound,
            ..ExactReport::default()
        };
        let outcome = self.morph_impl(ffd, opts, progress, Some((exact, &inside, &mut report)))?;
        report.exact_faces = inside.iter().filter(|&&i| i).count();
        report.other_faces = inside.len() - report.exact_faces;
        report.written_control_points =
            self.faces.iter().zip(&inside).filter(|(_, &i)| i).map(|(f, _)| f.surface.control_points().len()).sum();
        Ok((outcome, report))
    }
}
