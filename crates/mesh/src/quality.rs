//! Mesh quality as OpenFOAM's `checkMesh` (v1912) reports it: the geometry of
//! `primitiveMesh` (face centres and area vectors, cell centres and volumes,
//! `primitiveMeshFaceCentresAndAreas.C`, `primitiveMeshCellCentresAndVols.C`) and the
//! checks of `primitiveMeshCheck.C` / `primitiveMeshTools.C`: closed boundary, closed
//! cells and aspect ratio, face areas, cell volumes, face non-orthogonality, face
//! pyramids, face skewness, and the `-allGeometry` face concavity and flatness.
//!
//! The thresholds are OpenFOAM's: `closedThreshold` 1e-6, `aspectThreshold` 1000,
//! `nonOrthThreshold` 70°, `skewThreshold` 4, face-angle limit 10°, flatness warning 0.8.
//! A check that `checkMesh` counts as failed (its `***` lines) is listed in
//! [`Quality::failed`]; [`Quality::ok`] is its "Mesh OK." verdict.

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;
use serde::Serialize;

use crate::format::foam::{Label, PolyMesh};

mod screen;

/// OpenFOAM's `VSMALL` for double precision.
const VSMALL: f64 = 1e-300;
/// OpenFOAM's `ROOTVSMALL`.
const ROOTVSMALL: f64 = 1e-150;
/// OpenFOAM's `SMALL`.
const SMALL: f64 = 1e-15;
/// `primitiveMesh::closedThreshold_`.
pub const CLOSED_THRESHOLD: f64 = 1e-6;
/// `primitiveMesh::aspectThreshold_`.
pub const ASPECT_THRESHOLD: f64 = 1000.0;
/// `primitiveMesh::nonOrthThreshold_`, degrees.
pub const NON_ORTH_THRESHOLD: f64 = 70.0;
/// `primitiveMesh::skewThreshold_`.
pub const SKEW_THRESHOLD: f64 = 4.0;
/// `primitiveMesh::planarCosAngle_`-independent face-angle limit of `checkFaceAngles`, degrees.
pub const MAX_FACE_ANGLE: f64 = 10.0;
/// Flatness below which `checkFaceFlatness` warns.
pub const WARN_FLATNESS: f64 = 0.8;

/// The primitive geometry of a polyhedral mesh, computed as OpenFOAM computes it.
#[derive(Debug, Clone)]
pub struct Geometry {
    /// Face centres (area-weighted centroids of the triangle fan about the vertex average).
    pub face_centres: Vec<Point3<f64>>,
    /// Face area vectors (½ Σ of the fan's cross products), pointing out of the owner.
    pub face_areas: Vec<Vector3<f64>>,
    /// Cell centres (volume-weighted centroids of the face pyramids about the mean of the face centres).
    pub cell_centres: Vec<Point3<f64>>,
    /// Cell volumes (sum of face-pyramid volumes; negative for an inverted cell).
    pub cell_volumes: Vec<f64>,
}

/// Face centre and area vector of the polygon `f` (`primitiveMeshFaceCentresAndAreas`).
pub fn face_centre_and_area(points: &[Point3<f64>], f: &[Label]) -> (Point3<f64>, Vector3<f64>) {
    let n = f.len();
    if n == 3 {
        let (a, b, c) = (points[f[0] as usize], points[f[1] as usize], points[f[2] as usize]);
        let centre = Point3::from((a.coords + b.coords + c.coords) / 3.0);
        return (centre, 0.5 * (b - a).cross(&(c - a)));
    }
    let mut est = Vector3::zeros();
    for &i in f {
        est += points[i as usize].coords;
    }
    let est = est / n as f64;
    let (mut sum_n, mut sum_a, mut sum_ac) = (Vector3::zeros(), 0.0, Vector3::zeros());
    for k in 0..n {
        let p = points[f[k] as usize].coords;
        let q = points[f[if k + 1 == n { 0 } else { k + 1 }] as usize].coords;
        let c = p + q + est;
        let nv = (q - p).cross(&(est - p));
        let a = nv.norm();
        sum_n += nv;
        sum_a += a;
        sum_ac += a * c;
    }
    if sum_a < ROOTVSMALL {
        (Point3::from(est), Vector3::zeros())
    } else {
        (Point3::from(sum_ac / (3.0 * sum_a)), 0.5 * sum_n)
    }
}

impl Geometry {
    /// The geometry of `mesh`.
    pub fn of(mesh: &PolyMesh) -> Geometry {
        Geometry::with_cells(mesh, &CellFaces::of(mesh), None).0
    }

    /// [`Geometry::of`] with the cells' faces already listed: the faces in parallel, then
    /// the cells in parallel, each summing over its faces in the order OpenFOAM's loops
    /// add them (so the numbers are the same as its sequential loops give). With
    /// `closedness`, the cell pass also runs [`cell_closedness`] on each cell while its
    /// faces are in the cache, and returns the largest openness and aspect ratio of
    /// each chunk of [`FACE_CHUNK`] cells, in cell order.
    fn with_cells(mesh: &PolyMesh, cf: &CellFaces, closedness: Option<&Closedness>) -> (Geometry, Vec<CellWorst>) {
        let nf = mesh.n_faces();
        let (face_centres, face_areas): (Vec<_>, Vec<_>) =
            (0..nf).into_par_iter().map(|i| face_centre_and_area(&mesh.points, mesh.face(i))).unzip();
        let nc = mesh.n_cells();
        // Filled in parallel (the fresh pages faulted in by both threads), then written
        // in place chunk by chunk.
        let mut cell_centres = Vec::with_capacity(nc);
        cell_centres.par_extend(rayon::iter::repeat_n(Point3::origin(), nc));
        let mut cell_volumes = vec![0.0; nc];
        let worst = cell_centres
            .par_chunks_mut(FACE_CHUNK)
            .zip(cell_volumes.par_chunks_mut(FACE_CHUNK))
            .enumerate()
            .map(|(k, (centres, volumes))| {
                let mut worst = NO_CELL;
                for (j, (centre, volume)) in centres.iter_mut().zip(volumes.iter_mut()).enumerate() {
                    let c = k * FACE_CHUNK + j;
                    (*centre, *volume) = cell_centre_and_volume(cf, &face_centres, &face_areas, c);
                    if let Some(cl) = closedness {
                        add_cell_closedness(&mut worst, cf, &face_areas, cl, *volume, c);
                    }
                }
                worst
            })
            .collect();
        (Geometry { face_centres, face_areas, cell_centres, cell_volumes }, worst)
    }
}

/// Cell `c`'s centre and volume from its face pyramids about the mean of its face
/// centres (`primitiveMeshCellCentresAndVols.C`).
#[inline]
fn cell_centre_and_volume(
    cf: &CellFaces,
    face_centres: &[Point3<f64>],
    face_areas: &[Vector3<f64>],
    c: usize,
) -> (Point3<f64>, f64) {
    let faces = cf.faces(c);
    let mut est = Vector3::zeros();
    for (f, _) in faces.clone() {
        est += face_centres[f].coords;
    }
    est /= cf.count(c).max(1) as f64;
    let (mut ctr, mut vol) = (Vector3::zeros(), 0.0);
    for (f, owned) in faces {
        let fc = face_centres[f].coords;
        let pyr3 = if owned { face_areas[f].dot(&(fc - est)) } else { face_areas[f].dot(&(est - fc)) };
        ctr += pyr3 * (0.75 * fc + 0.25 * est);
        vol += pyr3;
    }
    let centre = if vol.abs() > VSMALL { Point3::from(ctr / vol) } else { Point3::from(est) };
    (centre, vol / 3.0)
}

/// The mesh's solution directions (`polyMesh::calcDirections`): empty patches remove the
/// directions their normals take; `area(f)` is face `f`'s area vector.
fn closedness(mesh: &PolyMesh, area: impl Fn(usize) -> Vector3<f64>) -> Closedness {
    let mut empty_dir = Vector3::zeros();
    for p in mesh.patches().iter().filter(|p| p.kind == "empty") {
        for f in p.start_face..p.start_face + p.n_faces {
            empty_dir += area(f).abs();
        }
    }
    let norm = empty_dir.norm();
    let mut dirs = [1i8; 3];
    if norm > VSMALL {
        for k in 0..3 {
            if empty_dir[k] / norm > 1e-6 {
                dirs[k] = -1;
            }
        }
    }
    Closedness { dirs, n_dims: dirs.iter().filter(|&&d| d == 1).count() }
}

/// The largest cell openness and aspect ratio of a run of cells (the first cell where
/// each is reached).
type CellWorst = (Worst, Worst);

/// [`CellWorst`] of no cell.
const NO_CELL: CellWorst = (Worst { index: 0, value: f64::NEG_INFINITY }, Worst { index: 0, value: f64::NEG_INFINITY });

/// Fold cell `c`'s [`cell_closedness`] into `worst` (the cells before it, in order).
#[inline]
fn add_cell_closedness(
    worst: &mut CellWorst,
    cf: &CellFaces,
    face_areas: &[Vector3<f64>],
    cl: &Closedness,
    volume: f64,
    c: usize,
) {
    let (o, a) = cell_closedness(cf, face_areas, cl, volume, worst.1.value, c);
    higher(&mut worst.0, Worst { index: c, value: o });
    higher(&mut worst.1, Worst { index: c, value: a });
}

/// What [`cell_closedness`] needs besides the cell: the mesh's solution directions
/// (`1` used, `-1` removed by empty patches) and how many are used.
struct Closedness {
    dirs: [i8; 3],
    n_dims: usize,
}

/// OpenFOAM's `cellClosedness` for cell `c` of volume `volume`: the openness (its outward
/// face area vectors summed, over the sum of their magnitudes, largest component) and the
/// aspect ratio. When the aspect ratio surely stays below `below` (the largest so far),
/// the power `volume^(2/3)` is not taken: the value returned is then below `below` too,
/// and only the largest one is reported.
#[inline]
fn cell_closedness(
    cf: &CellFaces,
    face_areas: &[Vector3<f64>],
    cl: &Closedness,
    volume: f64,
    below: f64,
    c: usize,
) -> (f64, f64) {
    let (mut sc, mut smc) = (Vector3::zeros(), Vector3::zeros());
    for (f, owned) in cf.faces(c) {
        if owned {
            sc += face_areas[f];
        } else {
            sc -= face_areas[f];
        }
        smc += face_areas[f].abs();
    }
    let open = (0..3).map(|k| sc[k].abs() / (smc[k] + ROOTVSMALL)).fold(0.0, f64::max);
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    for k in 0..3 {
        if cl.dirs[k] == 1 {
            lo = lo.min(smc[k]);
            hi = hi.max(smc[k]);
        }
    }
    let mut ar = hi / (lo + ROOTVSMALL);
    if cl.n_dims == 3 {
        let v = volume.max(ROOTVSMALL);
        let q = smc.sum() / 6.0;
        // q / v^(2/3) < m  ⇔  q³ < m³ v², with a margin far above the rounding of both
        // sides, in a range where the cubes neither overflow nor underflow.
        let m = below * (1.0 - 1e-9);
        let sane = |x: f64| x > 1e-60 && x < 1e60;
        let surely_below = sane(q) && sane(v) && sane(m) && q * q * q < m * m * m * v * v;
        if !surely_below {
            ar = ar.max(q / v.powf(2.0 / 3.0));
        }
    }
    (open, ar)
}

/// The faces of each cell in the order OpenFOAM's cell loops visit them
/// (`primitiveMeshCellCentresAndVols.C`, `cellClosedness`: over the owner list, then over
/// the neighbour list): the faces it owns in face order, then those it neighbours. A
/// counting sort of the owner and neighbour lists.
pub(crate) struct CellFaces {
    /// The faces each cell owns, in face order (CSR over the cells).
    owned: Csr,
    /// The faces each cell neighbours, in face order.
    neighboured: Csr,
}

/// Lists per cell: cell `c`'s entries are `items[offsets[c]..offsets[c + 1]]`.
struct Csr {
    offsets: Vec<usize>,
    items: Vec<Label>,
}

impl Csr {
    /// The faces `f` of each cell `cells[f]` (a counting sort, stable: in face order).
    /// Each cell's count is summed into the end of its run; then the faces are placed
    /// from the back, which leaves each cell's offset at the start of its run.
    fn by_cell(cells: &[Label], nc: usize) -> Csr {
        let mut offsets = vec![0usize; nc + 1];
        for &c in cells {
            offsets[c as usize] += 1;
        }
        let mut sum = 0;
        for o in offsets.iter_mut() {
            sum += *o;
            *o = sum;
        }
        let mut items = vec![0; sum];
        // Face numbers fit a label: `PolyMesh` holds fewer than 2³² faces.
        for (f, &c) in cells.iter().enumerate().rev() {
            let c = c as usize;
            offsets[c] -= 1;
            items[offsets[c]] = f as Label;
        }
        Csr { offsets, items }
    }

    #[inline]
    fn of(&self, c: usize) -> &[Label] {
        &self.items[self.offsets[c]..self.offsets[c + 1]]
    }
}

impl CellFaces {
    /// The owner and the neighbour list sorted by cell, the two in parallel.
    fn of(mesh: &PolyMesh) -> CellFaces {
        let nc = mesh.n_cells();
        let (owned, neighboured) =
            rayon::join(|| Csr::by_cell(mesh.owner(), nc), || Csr::by_cell(mesh.neighbour(), nc));
        CellFaces { owned, neighboured }
    }

    /// Cell `c`'s faces: (face, whether `c` owns it), those it owns first.
    #[inline]
    fn faces(&self, c: usize) -> impl Iterator<Item = (usize, bool)> + Clone + '_ {
        let own = self.owned.of(c).iter().map(|&f| (f as usize, true));
        own.chain(self.neighboured.of(c).iter().map(|&f| (f as usize, false)))
    }

    /// The number of faces of cell `c`.
    #[inline]
    fn count(&self, c: usize) -> usize {
        self.owned.of(c).len() + self.neighboured.of(c).len()
    }
}

/// Where the worst value of a check is: a face or a cell index, and the value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Worst {
    /// Face or cell index (0-based, OpenFOAM's numbering).
    pub index: usize,
    /// The value there.
    pub value: f64,
}

/// The numbers `checkMesh` prints under "Mesh stats" and "Checking geometry...".
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Quality {
    /// Points.
    pub points: usize,
    /// Faces.
    pub faces: usize,
    /// Internal faces.
    pub internal_faces: usize,
    /// Cells.
    pub cells: usize,
    /// Solution directions (`1` used, `-1` empty), as "Mesh has N solution directions".
    pub solution_directions: [i8; 3],
    /// "Boundary openness (x y z)": sum of boundary area vectors over the sum of their magnitudes.
    pub boundary_openness: [f64; 3],
    /// "Max cell openness".
    pub max_cell_openness: Worst,
    /// "Max aspect ratio".
    pub max_aspect_ratio: Worst,
    /// "Minimum face area".
    pub min_face_area: Worst,
    /// "Maximum face area".
    pub max_face_area: Worst,
    /// "Min volume".
    pub min_volume: Worst,
    /// "Max volume".
    pub max_volume: Worst,
    /// "Total volume".
    pub total_volume: f64,
    /// Cells with volume below `VSMALL` (inverted or collapsed).
    pub negative_volumes: usize,
    /// "Mesh non-orthogonality Max", degrees, over internal faces.
    pub max_non_orthogonality: Worst,
    /// "average", degrees: the angle of the mean cosine.
    pub average_non_orthogonality: f64,
    /// "Number of severely non-orthogonal (> 70 degrees) faces".
    pub severely_non_orthogonal: usize,
    /// Faces beyond 90° (OpenFOAM's non-orthogonality errors).
    pub non_orthogonality_errors: usize,
    /// Face pyramids of negative volume ("Error in face pyramids").
    pub pyramid_errors: usize,
    /// Smallest face-pyramid volume (apex at the owner or neighbour centre).
    pub min_pyramid_volume: Worst,
    /// "Max skewness", over all faces.
    pub max_skewness: Worst,
    /// Faces with skewness above 4 ("highly skew faces").
    pub highly_skew_faces: usize,
    /// `-allGeometry` "Max face angle" (concavity), degrees; 0 when no face is concave.
    pub max_concave_angle: Worst,
    /// Faces with a concave angle above 10°.
    pub concave_faces: usize,
    /// `-allGeometry` face flatness minimum (1 flat, 0 butterfly), over faces of 4+ points.
    pub min_flatness: Worst,
    /// Face flatness average.
    pub average_flatness: f64,
    /// Faces with flatness below 0.8.
    pub warped_faces: usize,
    /// The checks `checkMesh` would fail (its `***` lines), in its order.
    pub failed: Vec<String>,
}

/// Shortest round-trip digits, in scientific notation for very small or large magnitudes.
fn num(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-4 || v.abs() >= 1e7) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

fn max_by(values: impl Iterator<Item = f64>) -> Worst {
    let mut w = Worst { index: 0, value: f64::NEG_INFINITY };
    for (i, v) in values.enumerate() {
        if v > w.value {
            w = Worst { index: i, value: v };
        }
    }
    w
}

fn min_by(values: impl Iterator<Item = f64>) -> Worst {
    let mut w = Worst { index: 0, value: f64::INFINITY };
    for (i, v) in values.enumerate() {
        if v < w.value {
            w = Worst { index: i, value: v };
        }
    }
    w
}

/// OpenFOAM's `faceSkewness` (internal face) and `boundaryFaceSkewness`.
fn skewness(
    points: &[Point3<f64>],
    f: &[Label],
    fc: &Point3<f64>,
    fa: &Vector3<f64>,
    own: &Point3<f64>,
    nei: Option<&Point3<f64>>,
) -> f64 {
    let cpf = fc - own;
    let (d, factor) = match nei {
        Some(n) => (n - own, 0.2),
        None => {
            let normal = fa / (fa.norm() + ROOTVSMALL);
            (normal * normal.dot(&cpf), 0.4)
        }
    };
    let sv = cpf - (fa.dot(&cpf) / (fa.dot(&d) + ROOTVSMALL)) * d;
    let sv_hat = sv / (sv.norm() + ROOTVSMALL);
    let mut fd = factor * d.norm() + ROOTVSMALL;
    for &p in f {
        fd = fd.max(sv_hat.dot(&(points[p as usize] - fc)).abs());
    }
    sv.norm() / fd
}

/// The skewness of every face of `mesh`, as `checkMesh`'s `checkFaceSkewness` measures
/// it (`primitiveMeshTools::faceSkewness`, `boundaryFaceSkewness`); coupled faces
/// (cyclic, processor patches) get 0, as `checkMesh` leaves them out.
///
/// ```text
/// internal face f, owner centre C_o, neighbour centre C_n, face centre C_f, area S_f:
///   d  = C_n − C_o,   s = C_f − C_o − (S_f·(C_f − C_o)) / (S_f·d) · d
///   skewness = |s| / max(0.2 |d|, max over the face's points p of |ŝ·(p − C_f)|)
/// boundary face: d = n̂ (n̂·(C_f − C_o)) with n̂ = S_f/|S_f|, and 0.4 |d| instead of 0.2 |d|
/// ```
///
/// `s` is the distance from the face centre to where the line between the two cell
/// centres crosses the face's plane; the denominator makes it relative to the face's
/// extent in that direction. `checkMesh` fails the mesh when a face exceeds
/// [`SKEW_THRESHOLD`] (4); [`Quality::max_skewness`] is the largest of these values.
///
/// # Examples
///
/// ```
/// use cadmorph_mesh::{format::foam::PolyMesh, quality::{face_skewness, Geometry}, Cell, CellKind};
/// use cadmorph_morph::math::Point3;
/// let p = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]];
/// let mesh = PolyMesh::from_cells(p.iter().map(|&c| Point3::from(c)).collect(), &[Cell::new(CellKind::Hexahedron, (0..8).collect())])?;
/// let skew = face_skewness(&mesh, &Geometry::of(&mesh));
/// assert_eq!(skew.len(), 6);
/// assert!(skew.iter().all(|s| s.abs() < 1e-12)); // a cube's faces are centred on the axis
/// # Ok::<(), cadmorph_mesh::Error>(())
/// ```
pub fn face_skewness(mesh: &PolyMesh, g: &Geometry) -> Vec<f64> {
    let pts = &mesh.points;
    let (own, nei) = (mesh.owner(), mesh.neighbour());
    let (nf, ni) = (mesh.n_faces(), mesh.n_internal_faces());
    let mut skip = vec![false; nf];
    for p in mesh.patches().iter().filter(|p| coupled(&p.kind)) {
        for s in &mut skip[p.start_face..p.start_face + p.n_faces] {
            *s = true;
        }
    }
    (0..nf)
        .into_par_iter()
        .map(|f| {
            if skip[f] {
                return 0.0;
            }
            let n = if f < ni { Some(&g.cell_centres[nei[f] as usize]) } else { None };
            skewness(pts, mesh.face(f), &g.face_centres[f], &g.face_areas[f], &g.cell_centres[own[f] as usize], n)
        })
        .collect()
}

/// The skewness of every cell of `mesh`: the largest [`face_skewness`] of its faces,
/// as `checkMesh -writeFields '(skewness)'` writes its cell field (`writeFields.C`:
/// the maximum over owner and neighbour faces). Its maximum over the cells is
/// [`Quality::max_skewness`].
pub fn cell_skewness(mesh: &PolyMesh, g: &Geometry) -> Vec<f64> {
    let skew = face_skewness(mesh, g);
    let mut out = vec![0.0f64; mesh.n_cells()];
    for (f, &c) in mesh.owner().iter().enumerate() {
        out[c as usize] = out[c as usize].max(skew[f]);
    }
    for (f, &c) in mesh.neighbour().iter().enumerate() {
        out[c as usize] = out[c as usize].max(skew[f]);
    }
    out
}

/// OpenFOAM's `faceConcavity`: the largest sine of a concave corner (0 for convex faces).
fn concavity(points: &[Point3<f64>], f: &[Label], fa: &Vector3<f64>) -> f64 {
    let n = f.len();
    let normal = fa / (fa.norm() + VSMALL);
    let mut max_sin: f64 = 0.0;
    if n == 0 {
        return max_sin;
    }
    // The unit edge from point k to point k + 1 (each edge serves two corners).
    let edge = |k: usize| {
        let d = points[f[if k + 1 == n { 0 } else { k + 1 }] as usize] - points[f[k] as usize];
        d / (d.norm() + VSMALL)
    };
    let mut e_prev = edge(n - 1);
    for k in 0..n {
        let e_next = edge(k);
        let en = e_prev.cross(&e_next);
        e_prev = e_next;
        if en.dot(&normal) < SMALL {
            let m = en.norm();
            if m > VSMALL {
                max_sin = max_sin.max(m);
            }
        }
    }
    max_sin
}

/// OpenFOAM's `faceFlatness`: |area| over the sum of the fan triangles' areas.
fn flatness(points: &[Point3<f64>], f: &[Label], fc: &Point3<f64>, fa: &Vector3<f64>) -> Option<f64> {
    let mag = fa.norm();
    if f.len() <= 3 || mag <= ROOTVSMALL {
        return None;
    }
    let n = f.len();
    let mut sum = 0.0;
    for k in 0..n {
        let p = points[f[k] as usize];
        let q = points[f[if k + 1 == n { 0 } else { k + 1 }] as usize];
        sum += (0.5 * (q - p).cross(&(fc - p))).norm();
    }
    Some(mag / (sum + ROOTVSMALL))
}

fn coupled(kind: &str) -> bool {
    matches!(kind, "cyclic" | "cyclicAMI" | "cyclicACMI" | "processor" | "processorCyclic" | "cyclicSlip")
}

/// Faces (or cells) per task of the checks: a fixed size, so that sums come out the same
/// for any number of threads.
const FACE_CHUNK: usize = 16384;

/// What the per-face checks of [`Quality`] gather (each `Worst` keeps the first face
/// where the extreme is reached, as a sequential scan does).
#[derive(Debug, Clone, Copy)]
struct FaceChecks {
    min_area: Worst,
    max_area: Worst,
    /// Smallest cosine between the face normal and the owner→neighbour line.
    min_cos: Worst,
    cos_sum: f64,
    severe: usize,
    ortho_errors: usize,
    pyramid_errors: usize,
    min_pyramid: Worst,
    max_skew: Worst,
    highly_skew: usize,
    max_sin: Worst,
    concave: usize,
    min_flat: Worst,
    flat_sum: f64,
    flat_count: usize,
    warped: usize,
}

fn lower(a: &mut Worst, b: Worst) {
    if b.value < a.value {
        *a = b;
    }
}

fn higher(a: &mut Worst, b: Worst) {
    if b.value > a.value {
        *a = b;
    }
}

impl FaceChecks {
    fn empty() -> FaceChecks {
        let lo = Worst { index: 0, value: f64::INFINITY };
        let hi = Worst { index: 0, value: f64::NEG_INFINITY };
        FaceChecks {
            min_area: lo,
            max_area: hi,
            min_cos: lo,
            cos_sum: 0.0,
            severe: 0,
            ortho_errors: 0,
            pyramid_errors: 0,
            min_pyramid: lo,
            max_skew: hi,
            highly_skew: 0,
            max_sin: hi,
            concave: 0,
            min_flat: Worst { index: 0, value: 1.0 },
            flat_sum: 0.0,
            flat_count: 0,
            warped: 0,
        }
    }

    /// Fold the checks of the faces after `self`'s into it.
    fn then(mut self, b: FaceChecks) -> FaceChecks {
        lower(&mut self.min_area, b.min_area);
        higher(&mut self.max_area, b.max_area);
        lower(&mut self.min_cos, b.min_cos);
        self.cos_sum += b.cos_sum;
        self.severe += b.severe;
        self.ortho_errors += b.ortho_errors;
        self.pyramid_errors += b.pyramid_errors;
        lower(&mut self.min_pyramid, b.min_pyramid);
        higher(&mut self.max_skew, b.max_skew);
        self.highly_skew += b.highly_skew;
        higher(&mut self.max_sin, b.max_sin);
        self.concave += b.concave;
        lower(&mut self.min_flat, b.min_flat);
        self.flat_sum += b.flat_sum;
        self.flat_count += b.flat_count;
        self.warped += b.warped;
        self
    }

    /// The checks of faces `range`.
    fn of_faces(mesh: &PolyMesh, g: &Geometry, skip: &[bool], range: std::ops::Range<usize>) -> FaceChecks {
        let pts = &mesh.points;
        let (own, nei) = (mesh.owner(), mesh.neighbour());
        let ni = nei.len();
        let severe = NON_ORTH_THRESHOLD.to_radians().cos();
        let sin_limit = MAX_FACE_ANGLE.to_radians().sin();
        let mut a = FaceChecks::empty();
        for f in range {
            let (fc, fa) = (&g.face_centres[f], &g.face_areas[f]);
            let face = mesh.face(f);
            let mag = fa.norm();
            lower(&mut a.min_area, Worst { index: f, value: mag });
            higher(&mut a.max_area, Worst { index: f, value: mag });
            let co = &g.cell_centres[own[f] as usize];
            let cn = (f < ni).then(|| &g.cell_centres[nei[f] as usize]);
            if let Some(cn) = cn {
                let d = cn - co;
                let cos = d.dot(fa) / (d.norm() * mag + ROOTVSMALL);
                if cos < severe {
                    if cos > SMALL {
                        a.severe += 1;
                    } else {
                        a.ortho_errors += 1;
                    }
                }
                lower(&mut a.min_cos, Worst { index: f, value: cos });
                a.cos_sum += cos;
            }
            // Face pyramids: apex at the owner centre, then at the neighbour's.
            let v_own = fa.dot(&(fc - co)) / 3.0;
            let sides = [Some(v_own), cn.map(|cn| -(fa.dot(&(fc - cn)) / 3.0))];
            for v in sides.into_iter().flatten() {
                if v < -SMALL {
                    a.pyramid_errors += 1;
                }
                lower(&mut a.min_pyramid, Worst { index: f, value: v });
            }
            // A face whose skewness is surely below both the largest so far and the
            // threshold changes neither (`screen`); the others get the exact value.
            let limit = a.max_skew.value.min(SKEW_THRESHOLD);
            if !cn.is_some_and(|cn| !skip[f] && screen::skew_surely_below(fc, fa, co, cn, limit)) {
                let skew = if skip[f] { 0.0 } else { skewness(pts, face, fc, fa, co, cn) };
                higher(&mut a.max_skew, Worst { index: f, value: skew });
                if skew > SKEW_THRESHOLD {
                    a.highly_skew += 1;
                }
            }
            // A surely convex face has no concave corner: `concavity` would give 0.
            let sin = if screen::surely_convex(pts, face, fa) { 0.0 } else { concavity(pts, face, fa) };
            higher(&mut a.max_sin, Worst { index: f, value: sin });
            if sin > sin_limit {
                a.concave += 1;
            }
            if let Some(v) = flatness(pts, face, fc, fa) {
                lower(&mut a.min_flat, Worst { index: f, value: v });
                a.flat_sum += v;
                a.flat_count += 1;
                if v < WARN_FLATNESS {
                    a.warped += 1;
                }
            }
        }
        a
    }

    /// The checks of every face, in fixed chunks in parallel, folded in face order.
    fn of(mesh: &PolyMesh, g: &Geometry, skip: &[bool]) -> FaceChecks {
        let nf = mesh.n_faces();
        let parts: Vec<FaceChecks> = (0..nf.div_ceil(FACE_CHUNK))
            .into_par_iter()
            .map(|k| FaceChecks::of_faces(mesh, g, skip, k * FACE_CHUNK..((k + 1) * FACE_CHUNK).min(nf)))
            .collect();
        parts.into_iter().fold(FaceChecks::empty(), FaceChecks::then)
    }
}

impl Quality {
    /// Run the checks on `mesh`.
    ///
    /// # Examples
    ///
    /// ```
    /// use cadmorph_mesh::{format::foam::PolyMesh, quality::Quality, Cell, CellKind};
    /// use cadmorph_morph::math::Point3;
    /// // One unit cube.
    /// let p = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]];
    /// let points = p.iter().map(|&c| Point3::from(c)).collect();
    /// let mesh = PolyMesh::from_cells(points, &[Cell::new(CellKind::Hexahedron, (0..8).collect())])?;
    /// let q = Quality::of(&mesh);
    /// assert!(q.ok());
    /// assert!((q.total_volume - 1.0).abs() < 1e-15);
    /// assert!((q.max_aspect_ratio.value - 1.0).abs() < 1e-15);
    /// # Ok::<(), cadmorph_mesh::Error>(())
    /// ```
    pub fn of(mesh: &PolyMesh) -> Quality {
        let cf = CellFaces::of(mesh);
        // The solution directions need only the boundary faces' areas: computed first, so
        // that the cell geometry pass also checks each cell's closedness.
        let boundary_areas = |f: usize| face_centre_and_area(&mesh.points, mesh.face(f)).1;
        let cl = closedness(mesh, boundary_areas);
        let (g, cells) = Geometry::with_cells(mesh, &cf, Some(&cl));
        Quality::checks(mesh, &g, &cl, cells)
    }

    /// Run the checks with a precomputed [`Geometry`].
    pub fn from_geometry(mesh: &PolyMesh, g: &Geometry) -> Quality {
        let cf = CellFaces::of(mesh);
        let cl = closedness(mesh, |f| g.face_areas[f]);
        let nc = mesh.n_cells();
        let cells = (0..nc.div_ceil(FACE_CHUNK))
            .into_par_iter()
            .map(|k| {
                let mut worst = NO_CELL;
                for c in k * FACE_CHUNK..((k + 1) * FACE_CHUNK).min(nc) {
                    add_cell_closedness(&mut worst, &cf, &g.face_areas, &cl, g.cell_volumes[c], c);
                }
                worst
            })
            .collect();
        Quality::checks(mesh, g, &cl, cells)
    }

    /// The checks, given the geometry and the largest cell openness and aspect ratio of
    /// each chunk of cells.
    fn checks(mesh: &PolyMesh, g: &Geometry, cl: &Closedness, cells: Vec<CellWorst>) -> Quality {
        let pts = &mesh.points;
        let (nf, ni, nc) = (mesh.n_faces(), mesh.n_internal_faces(), mesh.n_cells());
        let mut failed = Vec::new();

        let dirs = cl.dirs;

        // checkClosedBoundary.
        let (mut sum_closed, mut sum_mag) = (Vector3::zeros(), 0.0);
        for p in mesh.patches().iter().filter(|p| !coupled(&p.kind)) {
            for f in p.start_face..p.start_face + p.n_faces {
                sum_closed += g.face_areas[f];
                sum_mag += g.face_areas[f].norm();
            }
        }
        let openness = sum_closed / (sum_mag + VSMALL);
        if openness.abs().max() > CLOSED_THRESHOLD {
            failed.push(format!(
                "boundary openness ({:e} {:e} {:e}): possible hole in the boundary",
                openness.x, openness.y, openness.z
            ));
        }

        // checkClosedCells (cellClosedness), run with the cell geometry: the chunks'
        // largest values folded in cell order.
        let lo = Worst { index: 0, value: f64::NEG_INFINITY };
        let (mut max_cell_openness, mut max_aspect_ratio) = (lo, lo);
        for (o, a) in cells {
            higher(&mut max_cell_openness, o);
            higher(&mut max_aspect_ratio, a);
        }
        if max_cell_openness.value > CLOSED_THRESHOLD {
            failed.push(format!(
                "open cells: max cell openness {:e} at cell {}",
                max_cell_openness.value, max_cell_openness.index
            ));
        }
        if max_aspect_ratio.value > ASPECT_THRESHOLD {
            failed.push(format!(
                "high aspect ratio cells: max {:e} at cell {}",
                max_aspect_ratio.value, max_aspect_ratio.index
            ));
        }

        // checkCellVolumes.
        let min_volume = min_by(g.cell_volumes.iter().copied());
        let max_volume = max_by(g.cell_volumes.iter().copied());
        let total_volume: f64 = g.cell_volumes.iter().sum();
        let negative_volumes = g.cell_volumes.iter().filter(|&&v| v < VSMALL).count();
        if negative_volumes > 0 {
            failed.push(format!(
                "{negative_volumes} zero or negative cell volume(s): minimum {:e} at cell {}",
                min_volume.value, min_volume.index
            ));
        }

        // checkFaceAreas, checkFaceOrthogonality (internal faces), checkFacePyramids,
        // checkFaceSkewness (all faces but coupled ones) and the -allGeometry face
        // concavity and flatness, in one pass over the faces.
        let mut skip = vec![false; nf];
        for p in mesh.patches().iter().filter(|p| coupled(&p.kind)) {
            for s in &mut skip[p.start_face..p.start_face + p.n_faces] {
                *s = true;
            }
        }
        let fq = FaceChecks::of(mesh, g, &skip);
        let (min_face_area, max_face_area) = (fq.min_area, fq.max_area);
        if min_face_area.value < VSMALL {
            failed.push(format!("zero or negative face area at face {}", min_face_area.index));
        }
        let (severely_non_orthogonal, non_orthogonality_errors) = (fq.severe, fq.ortho_errors);
        let deg = |c: f64| c.clamp(-1.0, 1.0).acos().to_degrees();
        let max_non_orthogonality = if ni > 0 {
            Worst { index: fq.min_cos.index, value: deg(fq.min_cos.value) }
        } else {
            Worst { index: 0, value: 0.0 }
        };
        let average_non_orthogonality = if ni > 0 { deg(fq.cos_sum / ni as f64) } else { 0.0 };
        if non_orthogonality_errors > 0 {
            failed.push(format!(
                "{non_orthogonality_errors} non-orthogonality error(s) (> 90°): max {} at face {}",
                max_non_orthogonality.value, max_non_orthogonality.index
            ));
        }
        let (pyramid_errors, min_pyr) = (fq.pyramid_errors, fq.min_pyramid);
        if pyramid_errors > 0 {
            failed.push(format!(
                "{pyramid_errors} incorrectly oriented face pyramid(s): minimum volume {:e} at face {}",
                min_pyr.value, min_pyr.index
            ));
        }
        let (max_skewness, highly_skew_faces) = (fq.max_skew, fq.highly_skew);
        if highly_skew_faces > 0 {
            failed.push(format!(
                "max skewness {} at face {}: {highly_skew_faces} highly skew face(s)",
                max_skewness.value, max_skewness.index
            ));
        }
        // -allGeometry checks are reported, not counted as failures, as in checkMesh
        // without -allGeometry.
        let max_sin = fq.max_sin;
        let concave_faces = fq.concave;
        let max_concave_angle = Worst { index: max_sin.index, value: max_sin.value.min(1.0).asin().to_degrees() };
        let min_flatness = fq.min_flat;
        let average_flatness = if fq.flat_count == 0 { 1.0 } else { fq.flat_sum / fq.flat_count as f64 };
        let warped_faces = fq.warped;

        Quality {
            points: pts.len(),
            faces: nf,
            internal_faces: ni,
            cells: nc,
            solution_directions: dirs,
            boundary_openness: [openness.x, openness.y, openness.z],
            max_cell_openness,
            max_aspect_ratio,
            min_face_area,
            max_face_area,
            min_volume,
            max_volume,
            total_volume,
            negative_volumes,
            max_non_orthogonality,
            average_non_orthogonality,
            severely_non_orthogonal,
            non_orthogonality_errors,
            pyramid_errors,
            min_pyramid_volume: min_pyr,
            max_skewness,
            highly_skew_faces,
            max_concave_angle,
            concave_faces,
            min_flatness,
            average_flatness,
            warped_faces,
            failed,
        }
    }

    /// `checkMesh`'s "Mesh OK." verdict: no failed check.
    pub fn ok(&self) -> bool {
        self.failed.is_empty()
    }

    /// Whether a morph leaves the mesh usable: no failed check, and no face that turned
    /// concave beyond 10° (`-allGeometry`'s face angles).
    pub fn acceptable(&self) -> bool {
        self.ok() && self.concave_faces == 0
    }

    /// The report as an aligned text table, one check per line (checkMesh's wording).
    pub fn table(&self) -> String {
        let mut rows: Vec<(String, String)> = vec![
            ("points".into(), self.points.to_string()),
            ("faces".into(), self.faces.to_string()),
            ("internal faces".into(), self.internal_faces.to_string()),
            ("cells".into(), self.cells.to_string()),
            (
                "boundary openness".into(),
                format!(
                    "({:e} {:e} {:e})",
                    self.boundary_openness[0], self.boundary_openness[1], self.boundary_openness[2]
                ),
            ),
            (
                "max cell openness".into(),
                format!("{:e} (cell {})", self.max_cell_openness.value, self.max_cell_openness.index),
            ),
            (
                "max aspect ratio".into(),
                format!("{} (cell {})", num(self.max_aspect_ratio.value), self.max_aspect_ratio.index),
            ),
            ("min face area".into(), format!("{:e} (face {})", self.min_face_area.value, self.min_face_area.index)),
            ("max face area".into(), format!("{:e} (face {})", self.max_face_area.value, self.max_face_area.index)),
            ("min volume".into(), format!("{:e} (cell {})", self.min_volume.value, self.min_volume.index)),
            ("max volume".into(), format!("{:e} (cell {})", self.max_volume.value, self.max_volume.index)),
            ("total volume".into(), format!("{:e}", self.total_volume)),
            ("negative volumes".into(), self.negative_volumes.to_string()),
            (
                "max non-orthogonality".into(),
                format!("{} deg (face {})", num(self.max_non_orthogonality.value), self.max_non_orthogonality.index),
            ),
            ("average non-orthogonality".into(), format!("{} deg", num(self.average_non_orthogonality))),
            ("faces > 70 deg".into(), self.severely_non_orthogonal.to_string()),
            ("faces > 90 deg".into(), self.non_orthogonality_errors.to_string()),
            ("face pyramid errors".into(), self.pyramid_errors.to_string()),
            ("max skewness".into(), format!("{} (face {})", num(self.max_skewness.value), self.max_skewness.index)),
            ("faces skewness > 4".into(), self.highly_skew_faces.to_string()),
            (
                "max concave angle".into(),
                format!("{} deg (face {})", num(self.max_concave_angle.value), self.max_concave_angle.index),
            ),
            ("concave faces > 10 deg".into(), self.concave_faces.to_string()),
            ("min flatness".into(), format!("{} (face {})", num(self.min_flatness.value), self.min_flatness.index)),
            ("average flatness".into(), num(self.average_flatness)),
            ("faces flatness < 0.8".into(), self.warped_faces.to_string()),
        ];
        rows.push((
            "verdict".into(),
            if self.ok() { "Mesh OK.".into() } else { format!("Failed {} mesh checks.", self.failed.len()) },
        ));
        let w = rows.iter().map(|r| r.0.len()).max().unwrap_or(0);
        let mut s = String::new();
        for (k, v) in rows {
            s += &format!("{k:<w$}  {v}\n");
        }
        for f in &self.failed {
            s += &format!("*** {f}\n");
        }
        s
    }
}
