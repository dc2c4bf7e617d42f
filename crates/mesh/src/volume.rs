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
//!
//! With [`BoundaryMorph::multilevel`] set, the interpolant is instead a
//! [`cadmorph_morph::rbf::MultilevelRbf`] (Floater & Iske, "Multistep scattered data
//! interpolation using compactly supported radial basis functions", J. Comput. Appl.
//! Math. 73 (1996)): level 0 is an `Rbf` with the given support on a coarse sample of the
//! constrained nodes, each next level interpolates the remaining miss with half the
//! support on a sample twice as fine, taken where the miss is largest (see
//! [`Multilevel`]). Every level's matrix then has a bounded number of entries per row, so
//! a 10⁶-cell mesh morphs in about a second where the single level with a large support
//! has dense rows (about 1 600 centres per support on the channel of `benches/mesh`) and
//! did not finish in half an hour: on that channel (10⁶ hexahedra, 40 400 constrained
//! nodes, budget 20 000), 8 327 centres in 6 levels match every constrained node to 1e-3
//! of the largest displacement, solve median 1.03 s over 5 runs on 2 cores, 835 MB peak,
//! no inverted cell. Measured figures and commands: `benches/mesh/README.md`.

use nalgebra::{Point3, Unit, Vector3};
use rayon::prelude::*;

use std::collections::{HashMap, HashSet};

use cadmorph_morph::rbf::{CompactRbf, Kernel, MultilevelRbf};
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
    /// Upper limit on the number of centres (all levels together).
    pub max_centres: usize,
    /// Multilevel interpolation ([`Multilevel`]) instead of one level with greedy
    /// selection; `kernel` must then be compactly supported, and its support is level 0's.
    pub multilevel: Option<Multilevel>,
}

/// Options of the multilevel interpolation (Floater & Iske 1996: the support of each
/// level a fixed multiple of its centre spacing, halved from level to level).
///
/// Level k has support `δₖ = δ₀ / 2ᵏ` (δ₀ the kernel's support) and centres at least
/// `δₖ / ratio` apart: a Poisson-disk thinning of the constrained nodes taken in
/// decreasing order of their current miss, so the worst-matched nodes become centres
/// first (the error-driven choice of Rendall & Allen 2009, per level). Level 0 samples all
/// constrained nodes; a later level samples only those within about 2δₖ of a node still
/// missed by more than the tolerance. The levels stop when every constrained node is
/// matched to `greedy_tol` × the largest displacement, at `max_levels`, or when the centre
/// budget `max_centres` is spent (a level that would not fit takes only the nodes
/// around those missed by more than a threshold raised until it fits). A
/// level that would not lower the largest miss (one cut short by the budget can spread
/// more miss around its centres than it removes) is left out, and the levels stop there.
/// With the environment variable `CADMORPH_LEVEL_TRACE` set, each level's support,
/// centres and largest miss (and where) are printed to stderr.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Multilevel {
    /// Support / centre spacing of every level; about `π ratio²` centres lie within a
    /// support on a boundary surface (50 for the default 4).
    pub ratio: f64,
    /// Most levels, level 0 included.
    pub max_levels: usize,
}

impl Default for Multilevel {
    /// Ratio 4, at most 12 levels.
    fn default() -> Self {
        Multilevel { ratio: 4.0, max_levels: 12 }
    }
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
            multilevel: None,
        }
    }

    /// [`BoundaryMorph::wendland`] as a multilevel interpolation ([`Multilevel::default`]):
    /// level 0 has support `support`.
    pub fn wendland_multilevel(support: f64) -> BoundaryMorph {
        BoundaryMorph { multilevel: Some(Multilevel::default()), ..BoundaryMorph::wendland(support) }
    }
}

/// What the interpolation did.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct BoundaryReport {
    /// Constrained (fixed or moved) nodes.
    pub constrained: usize,
    /// Centres used.
    pub centres: usize,
    /// Greedy rounds (single level) or levels (multilevel).
    pub rounds: usize,
    /// Levels of the interpolant (1 for the single level), with the centres of each.
    pub level_centres: Vec<usize>,
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
    /// sliding ones interpolated and projected on their plane. The interpolant is one
    /// greedy level, or with [`BoundaryMorph::multilevel`] the
    /// [`BoundaryMorph::multilevel_interpolant`].
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] when `constraints` is not one per point; RBF build
    /// errors ([`Error::Morph`]: fewer than 4 or coplanar constrained nodes, a singular
    /// system); with `multilevel`, those of [`BoundaryMorph::multilevel_interpolant`].
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
                BoundaryReport {
                    constrained: cands.len(),
                    centres: 0,
                    rounds: 0,
                    level_centres: Vec::new(),
                    max_relative_error: 0.0,
                },
            ));
        }
        if self.multilevel.is_some() {
            let (interp, report) = self.multilevel_interpolant(points, constraints)?;
            let mut disp = vec![Vector3::zeros(); points.len()];
            interp.displacements(points, &mut disp);
            apply_constraints(&mut out, &disp, constraints);
            return Ok((out, report));
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
        let disp: Vec<Vector3<f64>> = moved.par_iter().zip(points).map(|(m, p)| m - p).collect();
        apply_constraints(&mut out, &disp, constraints);
        Ok((
            out,
            BoundaryReport {
                constrained: cands.len(),
                centres: selected.len(),
                rounds,
                level_centres: vec![selected.len()],
                max_relative_error: max_err,
            },
        ))
    }
}

/// `out[i]`: the prescribed displacement of a fixed or moved node, the interpolated one
/// `disp[i]` of a free node, its tangential part for a sliding node.
fn apply_constraints(out: &mut [Vector3<f64>], disp: &[Vector3<f64>], constraints: &[Constraint]) {
    out.par_iter_mut().enumerate().for_each(|(i, d)| {
        *d = match constraints[i] {
            Constraint::Fixed => Vector3::zeros(),
            Constraint::Moved(t) => t,
            Constraint::Free => disp[i],
            Constraint::Slip(n) => disp[i] - n.into_inner() * n.dot(&disp[i]),
        }
    });
}

/// The integer cell of `p` in a grid of side `1 / inv_h`.
fn cell_of(p: &Point3<f64>, inv_h: f64) -> [i64; 3] {
    [(p.x * inv_h).floor() as i64, (p.y * inv_h).floor() as i64, (p.z * inv_h).floor() as i64]
}

/// Poisson-disk thinning: the points of `order` (indices into `pts`, in priority order)
/// taken one by one, each kept when no kept point lies closer than `h`, at most `limit`.
fn poisson_disk(pts: &[Point3<f64>], order: &[usize], h: f64, limit: usize) -> Vec<usize> {
    let inv_h = 1.0 / h;
    let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let mut kept = Vec::new();
    for &i in order {
        if kept.len() >= limit {
            break;
        }
        let c = cell_of(&pts[i], inv_h);
        let mut free = true;
        'around: for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(v) = cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        if v.iter().any(|&j| (pts[j] - pts[i]).norm_squared() < h * h) {
                            free = false;
                            break 'around;
                        }
                    }
                }
            }
        }
        if free {
            cells.entry(c).or_default().push(i);
            kept.push(i);
        }
    }
    kept
}

impl BoundaryMorph {
    /// The multilevel interpolant ([`Multilevel`]; [`Multilevel::default`] when
    /// [`BoundaryMorph::multilevel`] is `None`) of the fixed and moved nodes'
    /// displacements, before the constraints are applied: what [`BoundaryMorph::solve`]
    /// evaluates at every node. The report's `max_relative_error` is its largest miss at
    /// a constrained node, relative to the largest prescribed displacement.
    ///
    /// # Errors
    ///
    /// [`Error::CountMismatch`] when `constraints` is not one per point;
    /// [`Error::Unsupported`] for a kernel without compact support or a ratio that is not
    /// positive; [`Error::Morph`] from a level's build (fewer than 4 or coplanar centres
    /// on level 0, a singular system).
    pub fn multilevel_interpolant(
        &self,
        points: &[Point3<f64>],
        constraints: &[Constraint],
    ) -> Result<(MultilevelRbf, BoundaryReport)> {
        if constraints.len() != points.len() {
            return Err(Error::CountMismatch {
                what: "constraints (one per point)".into(),
                expected: points.len(),
                found: constraints.len(),
            });
        }
        let ml = self.multilevel.unwrap_or_default();
        let cands: Vec<usize> =
            (0..points.len()).filter(|&i| matches!(constraints[i], Constraint::Fixed | Constraint::Moved(_))).collect();
        let Some(support) = self.kernel.support() else {
            return Err(Error::Unsupported(format!(
                "multilevel interpolation needs a compactly supported kernel, not {}",
                self.kernel.name()
            )));
        };
        if !(ml.ratio.is_finite() && ml.ratio > 0.0) {
            return Err(Error::Unsupported(format!("multilevel ratio {} (must be positive)", ml.ratio)));
        }
        let pts: Vec<Point3<f64>> = cands.iter().map(|&c| points[c]).collect();
        let mut res: Vec<Vector3<f64>> = cands
            .iter()
            .map(|&c| match constraints[c] {
                Constraint::Moved(d) => d,
                _ => Vector3::zeros(),
            })
            .collect();
        let dmax = res.iter().map(|r| r.norm()).fold(0.0, f64::max);
        let tol = self.greedy_tol.unwrap_or(0.0) * dmax;
        let budget = self.max_centres.max(4);
        let mut used = 0;
        let mut level_centres = Vec::new();
        let mut interp: Option<MultilevelRbf> = None;
        let mut delta = support;
        let trace = std::env::var_os("CADMORPH_LEVEL_TRACE").is_some();
        let mut max_err = 0.0;
        for level in 0..ml.max_levels.max(1) {
            let mag: Vec<f64> = res.iter().map(|r| r.norm()).collect();
            let h = delta / ml.ratio;
            let room = budget - used;
            // The sample of the nodes within about 2δ of a node missed by more than `thr`,
            // worst first (all nodes on level 0).
            let sample = |thr: f64, limit: usize| -> Vec<usize> {
                let inv = 1.0 / delta;
                let bad: HashSet<[i64; 3]> =
                    (0..pts.len()).filter(|&i| mag[i] > thr).map(|i| cell_of(&pts[i], inv)).collect();
                let mut order: Vec<usize> = (0..pts.len())
                    .filter(|&i| {
                        let c = cell_of(&pts[i], inv);
                        (-1..=1).any(|dz| {
                            (-1..=1).any(|dy| (-1..=1).any(|dx| bad.contains(&[c[0] + dx, c[1] + dy, c[2] + dz])))
                        })
                    })
                    .collect();
                order.sort_by(|&a, &b| mag[b].total_cmp(&mag[a]).then(a.cmp(&b)));
                poisson_disk(&pts, &order, h, limit)
            };
            let chosen = if level == 0 {
                sample(-1.0, room)
            } else {
                let full = sample(tol, usize::MAX);
                if full.len() <= room {
                    full
                } else {
                    // Over budget: raise the threshold (bisection on its logarithm) until
                    // the sample, with its margin around the missed nodes, fits, rather
                    // than cutting the sample off.
                    let (mut lo, mut hi) = (tol.max(1e-300 * dmax).ln(), mag.iter().copied().fold(0.0, f64::max).ln());
                    let mut best = Vec::new();
                    for _ in 0..12 {
                        let mid = 0.5 * (lo + hi);
                        let c = sample(mid.exp(), usize::MAX);
                        if c.len() <= room {
                            hi = mid;
                            best = c;
                        } else {
                            lo = mid;
                        }
                    }
                    best
                }
            };
            if chosen.is_empty() {
                break;
            }
            let centres: Vec<Point3<f64>> = chosen.iter().map(|&i| pts[i]).collect();
            let values: Vec<Vector3<f64>> = chosen.iter().map(|&i| res[i]).collect();
            let kernel = self.kernel.with_radius(delta);
            let mut change = vec![Vector3::zeros(); pts.len()];
            match &mut interp {
                None => {
                    let base = Rbf::try_new(&centres, &values, kernel)?;
                    let moved = base.deformed(&pts);
                    change.par_iter_mut().zip(moved.par_iter().zip(&pts)).for_each(|(c, (m, p))| *c = m - p);
                    interp = Some(MultilevelRbf::new(base));
                }
                Some(m) => {
                    let s = CompactRbf::try_new(&centres, &values, kernel)?;
                    s.accumulate(&pts, &mut change);
                    let miss = res.par_iter().zip(&change).map(|(r, c)| (r - c).norm()).reduce(|| 0.0, f64::max);
                    if miss >= max_err * dmax {
                        // A level cut short by the budget can spread more miss around
                        // its centres than it removes: it is left out.
                        break;
                    }
                    m.push(s);
                }
            }
            res.par_iter_mut().zip(&change).for_each(|(r, c)| *r -= c);
            used += chosen.len();
            level_centres.push(chosen.len());
            let miss = res.iter().map(|r| r.norm()).fold(0.0, f64::max);
            max_err = if dmax > 0.0 { miss / dmax } else { 0.0 };
            if trace {
                let w = (0..pts.len()).max_by(|&a, &b| res[a].norm().total_cmp(&res[b].norm())).unwrap_or(0);
                eprintln!(
                    "level {level}: support {delta}, {} centres, largest miss {max_err:.3e} at {:?}",
                    chosen.len(),
                    pts[w].coords.as_slice()
                );
            }
            if miss <= tol || used >= budget {
                break;
            }
            delta *= 0.5;
        }
        let interp = interp.ok_or_else(|| Error::Topology("no fixed or moved node to interpolate".into()))?;
        Ok((
            interp,
            BoundaryReport {
                constrained: cands.len(),
                centres: used,
                rounds: level_centres.len(),
                level_centres,
                max_relative_error: max_err,
            },
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
            for v in face.iter().map(|&v| v as usize) {
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
