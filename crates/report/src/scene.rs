//! What a report shows, gathered from the models: each face's triangles (trimmed to its
//! bound curves) and control net,
//! the seam lines with their numbers, the FFD lattice before and after, the bounds.

use cadmorph_brep::CadDocument;
use cadmorph_model::Model;
use cadmorph_morph::Ffd;
use cadmorph_seam::SeamReport;
use serde::Serialize;

use crate::colour::Scale;
use crate::grid::{face_mesh, grid_size, parameter_box, trimmed_face_mesh, FaceMesh};
use crate::seamline::{seam_lines, SeamLine};
use crate::trim::Trim;
use crate::{Error, Result};

/// A face as drawn: its name, triangles and control net.
#[derive(Debug, Clone)]
pub struct FaceView {
    /// The face entity (`DE 3`, `#12`).
    pub name: String,
    /// The surface type as the file names it.
    pub kind: String,
    /// Triangles on the parameter grid (inside the trim, for a trimmed face).
    pub mesh: FaceMesh,
    /// Whether the face was drawn to its bound curves (over the box they span, less
    /// what they cut off) rather than over its surface's whole box.
    pub trimmed: bool,
    /// Control points, `n_u × n_v`, row by row (`i * n_v + j`).
    pub net: Vec<[f64; 3]>,
    /// Control points along u.
    pub net_u: usize,
    /// Control points along v.
    pub net_v: usize,
}

/// One state of the model (before or after the morph).
#[derive(Debug, Clone)]
pub struct ModelView {
    /// `before` or `after`.
    pub name: String,
    /// The file it was read from (for captions).
    pub source: String,
    /// The faces.
    pub faces: Vec<FaceView>,
    /// The shared edges.
    pub seams: Vec<SeamLine>,
    /// The seam report the seams came from.
    pub report: SeamReport,
}

/// An FFD lattice: its shape and points before and after the displacements.
#[derive(Debug, Clone, Serialize)]
pub struct Lattice {
    /// Lattice points per direction `[l, m, n]`.
    pub shape: [usize; 3],
    /// Points without displacements, C order of `(i, j, k)`: index `(i·m + j)·n + k`.
    pub original: Vec<[f64; 3]>,
    /// Points with displacements, same order.
    pub moved: Vec<[f64; 3]>,
}

impl Lattice {
    /// The lattice of `ffd`.
    pub fn of(ffd: &Ffd) -> Self {
        let arr = |v: Vec<cadmorph_nurbs::math::Point3<f64>>| v.iter().map(|p| [p.x, p.y, p.z]).collect();
        Self {
            shape: ffd.n_control_points(),
            original: arr(ffd.control_points(false)),
            moved: arr(ffd.control_points(true)),
        }
    }

    /// Pairs of point indices joined by a lattice line (neighbours along i, j and k).
    pub fn lines(&self) -> Vec<[usize; 2]> {
        let [l, m, n] = self.shape;
        let id = |i: usize, j: usize, k: usize| (i * m + j) * n + k;
        let mut out = Vec::new();
        for i in 0..l {
            for j in 0..m {
                for k in 0..n {
                    if i + 1 < l {
                        out.push([id(i, j, k), id(i + 1, j, k)]);
                    }
                    if j + 1 < m {
                        out.push([id(i, j, k), id(i, j + 1, k)]);
                    }
                    if k + 1 < n {
                        out.push([id(i, j, k), id(i, j, k + 1)]);
                    }
                }
            }
        }
        out
    }

    /// The 8 corners of the undisplaced box.
    pub fn corners(&self) -> Vec<[f64; 3]> {
        let [l, m, n] = self.shape;
        let id = |i: usize, j: usize, k: usize| (i * m + j) * n + k;
        let mut out = Vec::with_capacity(8);
        for c in 0..8 {
            let (i, j, k) = (
                if c & 1 == 0 { 0 } else { l - 1 },
                if c & 2 == 0 { 0 } else { m - 1 },
                if c & 4 == 0 { 0 } else { n - 1 },
            );
            out.push(self.original[id(i, j, k)]);
        }
        out
    }
}

/// Everything a report draws.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The model's length unit.
    pub unit: String,
    /// The model size (bounding-box diagonal).
    pub size: f64,
    /// Smallest corner of the box holding every state (and the lattice).
    pub min: [f64; 3],
    /// Largest corner.
    pub max: [f64; 3],
    /// The model as read.
    pub before: ModelView,
    /// The morphed model, if any.
    pub after: Option<ModelView>,
    /// The FFD lattice, if the morph is one.
    pub lattice: Option<Lattice>,
    /// Colour scale of the gaps.
    pub gap_scale: Scale,
    /// Colour scale of the G1 angles.
    pub angle_scale: Scale,
}

/// One model and its seam report, with the name of the file it came from.
pub struct Input<'a, D: CadDocument> {
    /// The model.
    pub model: &'a Model<D>,
    /// Its seams (as `model.seams(..)` or a morph outcome gives them).
    pub seams: &'a SeamReport,
    /// The file, for captions.
    pub source: String,
}

/// The trim of face `k` of `m` ([`Trim::of`] on its bound curves).
fn trim_of<D: CadDocument>(m: &Model<D>, k: usize) -> Option<Trim> {
    let p = &m.patches()[k];
    let bounds: Vec<_> = m.bound_curves().iter().filter(|b| b.face == k).collect();
    Trim::of(p, &bounds, parameter_box(p))
}

fn view<D: CadDocument>(
    name: &str,
    i: &Input<D>,
    grids: &[(usize, usize)],
    trims: &[Option<Trim>],
) -> Result<ModelView> {
    let faces = i
        .model
        .patches()
        .iter()
        .zip(grids)
        .zip(trims)
        .map(|((p, &g), t)| {
            let mesh = match t {
                Some(t) => trimmed_face_mesh(p, g, t),
                None => face_mesh(p, g),
            };
            if mesh.positions.iter().flatten().any(|c| !c.is_finite()) {
                return Err(Error::NotFinite { what: format!("face {}", p.entity) });
            }
            Ok(FaceView {
                name: p.entity.to_string(),
                kind: p.type_name.clone(),
                trimmed: t.is_some(),
                mesh,
                net: p.surface.control_points().iter().map(|q| [q.x, q.y, q.z]).collect(),
                net_u: p.surface.n_u(),
                net_v: p.surface.n_v(),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(ModelView {
        name: name.into(),
        source: i.source.clone(),
        faces,
        seams: seam_lines(i.model, i.seams),
        report: i.seams.clone(),
    })
}

impl Scene {
    /// The scene of `before` and, optionally, its morphed `after` (the same faces in the
    /// same order) and the FFD that made it; gaps are coloured around `gap_tol` (model
    /// units) and angles around `angle_tol` degrees ([`Scale::around`]).
    ///
    /// # Errors
    ///
    /// [`Error::Empty`] for a model without faces; [`Error::FaceCountMismatch`] when
    /// `after` has other faces; [`Error::NotFinite`] for a face with a non-finite point.
    pub fn new<D: CadDocument, E: CadDocument>(
        before: Input<D>,
        after: Option<Input<E>>,
        ffd: Option<&Ffd>,
        gap_tol: f64,
        angle_tol: f64,
    ) -> Result<Self> {
        let patches = before.model.patches();
        if patches.is_empty() {
            return Err(Error::Empty);
        }
        if let Some(a) = &after {
            if a.model.patches().len() != patches.len() {
                return Err(Error::FaceCountMismatch { before: patches.len(), after: a.model.patches().len() });
            }
        }
        let grids: Vec<_> = patches.iter().map(|p| grid_size(&p.surface)).collect();
        // The faces of `after` are trimmed as `before`'s where their parameter boxes
        // agree (a morph keeps them: the same triangles are drawn before and after), by
        // their own bound curves elsewhere.
        let b_trims: Vec<_> = (0..patches.len()).map(|k| trim_of(before.model, k)).collect();
        let b = view("before", &before, &grids, &b_trims)?;
        let a = after
            .map(|a| {
                let t: Vec<Option<Trim>> = patches
                    .iter()
                    .zip(a.model.patches())
                    .zip(&b_trims)
                    .enumerate()
                    .map(|(k, ((p, q), bt))| {
                        let (x, y) = (parameter_box(p), parameter_box(q));
                        let tol = 1e-9 * ((x.0 .1 - x.0 .0).abs() + (x.1 .1 - x.1 .0).abs());
                        let same = [x.0 .0 - y.0 .0, x.0 .1 - y.0 .1, x.1 .0 - y.1 .0, x.1 .1 - y.1 .1]
                            .iter()
                            .all(|d| d.abs() <= tol);
                        if same {
                            bt.clone()
                        } else {
                            trim_of(a.model, k)
                        }
                    })
                    .collect();
                view("after", &a, &grids, &t)
            })
            .transpose()?;
        let lattice = ffd.map(Lattice::of);
        let (mut min, mut max) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        let mut grow = |p: &[f64; 3]| {
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        };
        for v in std::iter::once(&b).chain(a.as_ref()) {
            v.faces.iter().flat_map(|f| &f.mesh.positions).for_each(&mut grow);
        }
        if let Some(l) = &lattice {
            l.original.iter().chain(&l.moved).for_each(&mut grow);
        }
        let size = ((max[0] - min[0]).powi(2) + (max[1] - min[1]).powi(2) + (max[2] - min[2]).powi(2)).sqrt();
        Ok(Self {
            unit: before.model.unit().to_string(),
            size,
            min,
            max,
            before: b,
            after: a,
            lattice,
            gap_scale: Scale::around(gap_tol),
            angle_scale: Scale::around(angle_tol),
        })
    }

    /// The state shown by default: after if there is one, else before.
    pub fn shown(&self) -> &ModelView {
        self.after.as_ref().unwrap_or(&self.before)
    }
}
