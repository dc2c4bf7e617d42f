//! Boundary → interior: a displacement prescribed on the boundary nodes of a volume mesh
//! (a morph of some patches, fixed walls, sliding planes) carried to every interior node
//! by RBF interpolation (paper §3.3; de Boer, van der Schoot & Bijl, "Mesh deformation
//! based on radial basis function interpolation", Comput. Struct. 85 (2007); greedy centre
//! selection after Rendall & Allen, "Efficient mesh motion using radial basis functions
//! with data reduction algorithms", J. Comput. Phys. 228 (2009)).
//!
//! The interpolant is [`cadmorph_morph::Rbf`] (kernel plus linear term). Compactly
//! supported Wendland kernels give sparse systems; the greedy selection keeps only the
//! boundary nodes the interpolant needs: it starts from a farthest-point sample, then
//! repeatedly adds the worst-interpolated constrained nodes (doubling the set) until every
//! constrained node is matched to `tol` × the largest displacement. Nodes not chosen as
//! centres are then set to their prescribed displacement exactly; sliding nodes keep only
//! the tangential part of the interpolated displacement.

use nalgebra::{Point3, Unit, Vector3};
use rayon::prelude::*;

use cadmorph_morph::rbf::Kernel;
use cadmorph_morph::{Deformation, Rbf};

use crate::format::foam::PolyMesh;
use crate::morph::MorphReport;
use crate::{Error, Result};

/// What a node is allowed to do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Constraint {
    /// An interior node: it follows the interpolant.
    Free,
    /// A node that must not move.
    Fixed,
    /// A node with a prescribed displacement.
    Moved(Vector3<f64>),
    /// A node that slides in the plane with this normal: it follows the interpolant's
    /// tangential part.
    Slip(Unit<Vector3<f64>>),
}

/// How a boundary patch moves (for [`patch_constraints`]).
#[derive(Clone, Copy)]
pub enum PatchMotion<'a> {
    /// Its nodes stay.
    Fixed,
    /// Its nodes slide along the patch (normal: the mean of the adjacent face normals).
    Slip,
    /// Its nodes move by this deformation.
    Follow(&'a dyn Deformation),
}

/// Options of the boundary → interior interpolation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryMorph {
    /// The kernel: compact Wendland (`Kernel::WendlandC2 { support }`) or any global one.
    pub kernel: Kernel,
    /// Greedy selection: stop when every constrained node is matched to `tol` × the
    /// largest prescribed displacement. `None` uses every constrained node as a centre.
    pub greedy_tol: Option<f64>,
    /// Initial farthest-point sample size of the greedy selection.
    pub initial_centres: usize,
    /// Upper limit on the number of centres.
    pub max_centres: usize,
}

impl BoundaryMorph {
    /// Wendland C² with support `support`, greedy selection to 1e-3 of the largest
    /// displacement, starting from 64 centres, at most 20 000.
    pub fn wendland(support: f64) -> BoundaryMorph {
        BoundaryMorph {
            kernel: Kernel::WendlandC2 { support },
            greedy_tol: Some(1e-3),
            initial_centres: 64,
            max_centres: 20_000,
        }
    }
}

/// What the interpolation did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BoundaryReport {
    /// Constrained (fixed or moved) nodes.
    pub constrained: usize,
    /// Centres used.
    pub centres: usize,
    /// Greedy rounds.
    pub rounds: usize,
    /// Largest miss at a constrained node before it was set exactly, relative to the
    /// largest prescribed displacement.
    pub max_relative_error: f64,
}

/// Farthest-point sample of `k` of `cands` (indices into `points`), starting at `first`.
fn farthest_points(points: &[Point3<f64>], cands: &[usize], first: usize, k: usize) -> Vec<usize> {
    let mut chosen = vec![first];
    let mut dist: Vec<f64> = cands.iter().map(|&c| (points[c] - points[cands[first]]).norm_squared()).collect();
    while chosen.len() < k.min(cands.len()) {
        let (j, _) = dist.iter().enumerate().fold((0, -1.0), |b, (i, &d)| if d > b.1 { (i, d) } else { b });
        chosen.push(j);
        let pj = points[cands[j]];
        for (i, &c) in cands.iter().enumerate() {
            dist[i] = dist[i].min((points[c] - pj).norm_squared());
        }
    }
    chosen
}

impl BoundaryMorph {
    /// The displacement of every node: prescribed ones exactly, free ones interpolated,
    /// sliding ones interpolated and projected on their plane.
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] when `constraints` is not one per point; RBF build
    /// errors ([`Error::Morph`]: fewer than 4 or coplanar constrained nodes, a singular
    /// system).
    pub fn solve(
        &self,
        points: &[Point3<f64>],
        constraints: &[Constraint],
    ) -> Result<(Vec<Vector3<f64>>, BoundaryReport)> {
        if constraints.len() != points.len() {
            return Err(Error::CountMismatch {
                what: "constraints (one per point)".into(),
                expected: points.len(),
                found: constraints.len(),
            });
        }
        let cands: Vec<usize> =
            (0..points.len()).filter(|&i| matches!(constraints[i], Constraint::Fixed | Constraint::Moved(_))).collect();
        let target = |i: usize| match constraints[i] {
            Constraint::Moved(d) => d,
            _ => Vector3::zeros(),
        };
        let dmax = cands.iter().map(|&i| target(i).norm()).fold(0.0, f64::max);
        let mut out = vec![Vector3::zeros(); points.len()];
        if dmax == 0.0 {
            return Ok((
                out,
                BoundaryReport { constrained: cands.len(), centres: 0, rounds: 0, max_relative_error: 0.0 },
            ));
        }
        let first =
            (0..cands.len()).max_by(|&a, &b| target(cands[a]).norm().total_cmp(&target(cands[b]).norm())).unwrap_or(0);
        let mut selected: Vec<usize> = match self.greedy_tol {
            Some(_) => farthest_points(points, &cands, first, self.initial_centres.max(8)),
            None => (0..cands.len()).collect(),
        };
        let mut in_set = vec![false; cands.len()];
        for &s in &selected {
            in_set[s] = true;
        }
        let mut rounds = 0;
        let (rbf, max_err) = loop {
            rounds += 1;
            let centres: Vec<Point3<f64>> = selected.iter().map(|&s| points[cands[s]]).collect();
            let disp: Vec<Vector3<f64>> = selected.iter().map(|&s| target(cands[s])).collect();
            let rbf = Rbf::try_new(&centres, &disp, self.kernel)?;
            let err: Vec<f64> = cands
                .par_iter()
                .map(|&c| (rbf.deform_point(&points[c]) - points[c] - target(c)).norm() / dmax)
                .collect();
            let max_err = err.iter().copied().fold(0.0, f64::max);
            let Some(tol) = self.greedy_tol else { break (rbf, max_err) };
            if max_err <= tol || selected.len() >= self.max_centres.min(cands.len()) {
                break (rbf, max_err);
            }
            let mut worst: Vec<usize> = (0..cands.len()).filter(|&i| !in_set[i] && err[i] > tol).collect();
            worst.sort_unstable_by(|&a, &b| err[b].total_cmp(&err[a]));
            let room = self.max_centres.min(cands.len()) - selected.len();
            for &w in worst.iter().take(selected.len().min(room).max(1)) {
                in_set[w] = true;
                selected.push(w);
            }
        };
        let moved = rbf.deformed(points);
        out.par_iter_mut().enumerate().for_each(|(i, d)| {
            *d = match constraints[i] {
                Constraint::Fixed => Vector3::zeros(),
                Constraint::Moved(t) => t,
                Constraint::Free => moved[i] - points[i],
                Constraint::Slip(n) => {
                    let v = moved[i] - points[i];
                    v - n.into_inner() * n.dot(&v)
                }
            }
        });
        Ok((
            out,
            BoundaryReport { constrained: cands.len(), centres: selected.len(), rounds, max_relative_error: max_err },
        ))
    }
}

/// The constraints of a polyMesh's nodes from a motion per patch (by name); nodes of
/// patches not named are fixed, interior nodes free. A node on several patches follows the
/// strongest: `Follow` over `Fixed` over `Slip`.
///
/// # Errors
///
/// [`Error::Topology`] for a patch name the mesh does not have.
pub fn patch_constraints(mesh: &PolyMesh, motions: &[(&str, PatchMotion<'_>)]) -> Result<Vec<Constraint>> {
    for (name, _) in motions {
        if !mesh.patches().iter().any(|p| p.name == *name) {
            return Err(Error::Topology(format!(
                "no patch named {name:?} (patches: {})",
                mesh.patches().iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
            )));
        }
    }
    let np = mesh.points.len();
    let mut rank = vec![0u8; np]; // 0 free, 1 slip, 2 fixed, 3 follow
    let mut cons = vec![Constraint::Free; np];
    let mut slip_normal = vec![Vector3::zeros(); np];
    for p in mesh.patches() {
        let motion = motions.iter().find(|m| m.0 == p.name).map(|m| m.1).unwrap_or(PatchMotion::Fixed);
        for f in p.start_face..p.start_face + p.n_faces {
            let face = mesh.face(f);
            let (_, area) = crate::quality::face_centre_and_area(&mesh.points, face);
            for &v in face {
                match motion {
                    PatchMotion::Follow(d) => {
                        if rank[v] < 3 {
                            rank[v] = 3;
                            cons[v] = Constraint::Moved(d.deform_point(&mesh.points[v]) - mesh.points[v]);
                        }
                    }
                    PatchMotion::Fixed => {
                        if rank[v] < 2 {
                            rank[v] = 2;
                            cons[v] = Constraint::Fixed;
                        }
                    }
                    PatchMotion::Slip => {
                        if rank[v] <= 1 {
                            rank[v] = 1;
                            slip_normal[v] += area;
                        }
                    }
                }
            }
        }
    }
    for v in 0..np {
        if rank[v] == 1 {
            cons[v] = match Unit::try_new(slip_normal[v], 0.0) {
                Some(n) => Constraint::Slip(n),
                None => Constraint::Fixed,
            };
        }
    }
    Ok(cons)
}

/// Move a polyMesh's nodes by the interpolated boundary displacement and check the
/// result, refusing a degrading morph unless `allow_degrade` (as
/// [`crate::morph::morph_checked`]).
///
/// # Errors
///
/// As [`BoundaryMorph::solve`]; [`Error::Degraded`].
pub fn morph_volume(
    mesh: &mut PolyMesh,
    constraints: &[Constraint],
    options: &BoundaryMorph,
    allow_degrade: bool,
) -> Result<(MorphReport, BoundaryReport)> {
    let (disp, br) = options.solve(&mesh.points, constraints)?;
    let moved: Vec<Point3<f64>> = mesh.points.iter().zip(&disp).map(|(p, d)| p + d).collect();
    let report = crate::morph::move_checked(mesh, moved, allow_degrade)?;
    Ok((report, br))
}
