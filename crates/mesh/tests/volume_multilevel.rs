//! The multilevel boundary → interior interpolation (`BoundaryMorph::multilevel`,
//! Floater & Iske 1996) against closed forms and invariants, and a hex block morph that
//! must keep every cell positive.

use cadmorph_mesh::format::foam::PolyMesh;
use cadmorph_mesh::quality::{Geometry, Quality};
use cadmorph_mesh::volume::{BoundaryMorph, Constraint, Multilevel};
use cadmorph_mesh::{Cell, CellKind};
use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::rbf::Kernel;
use cadmorph_morph::Deformation;

/// A CG solve to 1e-12 of the right-hand side: a translation is reproduced to this, relative.
const RIGID_MATCH: f64 = 1e-9;
/// One level against the single-level build on the same centres: the same system solved
/// with the centres in another order (dense null-space method), so equal to rounding.
const SAME_SYSTEM: f64 = 1e-10;

/// Nodes of an `n`×`n`×`n` grid of cells over [0, 3] × [0, 1] × [0, 1], graded towards
/// y = 0 (cell height ratio 4, as the blockMesh channel of `benches/mesh`).
fn channel_points(n: usize) -> Vec<Point3<f64>> {
    let g = 4f64.powf(1.0 / (n as f64 - 1.0));
    let mut ys = vec![0.0];
    let h0 = (g - 1.0) / (g.powi(n as i32) - 1.0);
    for j in 0..n {
        ys.push(ys[j] + h0 * g.powi(j as i32));
    }
    let mut pts = Vec::new();
    for k in 0..=n {
        for &y in &ys {
            for i in 0..=n {
                pts.push(Point3::new(3.0 * i as f64 / n as f64, y, k as f64 / n as f64));
            }
        }
    }
    pts
}

fn channel_mesh(n: usize) -> PolyMesh {
    let id = |i: usize, j: usize, k: usize| (k * (n + 1) + j) * (n + 1) + i;
    let mut cells = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let nodes = vec![
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                cells.push(Cell::new(CellKind::Hexahedron, nodes));
            }
        }
    }
    PolyMesh::from_cells(channel_points(n), &cells).unwrap()
}

/// The bench's lift of the floor y = 0 (y += 0.1 sin²(πx/3)), the other walls y = 1,
/// x = 0, x = 3 fixed, the sides z = 0, 1 sliding, the inside free.
fn channel_constraints(pts: &[Point3<f64>]) -> Vec<Constraint> {
    let z = Vector3::z_axis();
    pts.iter()
        .map(|p| {
            let s = (std::f64::consts::PI * p.x / 3.0).sin();
            if p.y == 0.0 {
                Constraint::Moved(Vector3::new(0.0, 0.1 * s * s, 0.0))
            } else if p.y == 1.0 || p.x == 0.0 || p.x == 3.0 {
                Constraint::Fixed
            } else if p.z == 0.0 || p.z == 1.0 {
                Constraint::Slip(z)
            } else {
                Constraint::Free
            }
        })
        .collect()
}

fn target(c: &Constraint) -> Option<Vector3<f64>> {
    match c {
        Constraint::Moved(d) => Some(*d),
        Constraint::Fixed => Some(Vector3::zeros()),
        _ => None,
    }
}

/// Every constrained node is matched by the interpolant itself (not only after the
/// constraints are imposed) to the asked tolerance, for tolerances from 1e-2 to 1e-4, and
/// the report states that miss. More levels for a tighter tolerance.
#[test]
fn constrained_nodes_matched_to_the_tolerance() {
    let pts = channel_points(30);
    let cons = channel_constraints(&pts);
    let mut last_levels = 0;
    for tol in [1e-2, 1e-3, 1e-4] {
        let opts = BoundaryMorph { greedy_tol: Some(tol), ..BoundaryMorph::wendland_multilevel(0.6) };
        let (ml, report) = opts.multilevel_interpolant(&pts, &cons).unwrap();
        eprintln!(
            "tol {tol}: {} constrained, levels {:?}, miss {:e}",
            report.constrained, report.level_centres, report.max_relative_error
        );
        let moved = ml.deformed(&pts);
        let miss = cons
            .iter()
            .enumerate()
            .filter_map(|(i, c)| target(c).map(|t| (moved[i] - pts[i] - t).norm()))
            .fold(0.0, f64::max)
            / 0.1;
        assert!(miss <= tol, "tol {tol}: miss {miss}");
        assert!((miss - report.max_relative_error).abs() <= 1e-12, "{miss} vs {}", report.max_relative_error);
        assert!(report.centres <= opts.max_centres);
        assert_eq!(report.level_centres.iter().sum::<usize>(), report.centres);
        assert_eq!(report.level_centres.len(), ml.levels().len() + 1);
        assert!(report.rounds >= last_levels, "tol {tol}: {} levels after {last_levels}", report.rounds);
        last_levels = report.rounds;
        // Every level's rows stay sparse: the support follows the centre spacing.
        for level in ml.levels() {
            let per_row = level.nnz() as f64 / level.n_centres() as f64;
            assert!(per_row < 150.0, "{per_row} entries per row");
        }
    }
    assert!(last_levels >= 3, "1e-4 needs several levels ({last_levels})");
}

/// No prescribed motion: nothing moves.
#[test]
fn zero_displacement_gives_zero() {
    let pts = channel_points(12);
    let cons: Vec<Constraint> = channel_constraints(&pts)
        .into_iter()
        .map(|c| if let Constraint::Moved(_) = c { Constraint::Fixed } else { c })
        .collect();
    let opts = BoundaryMorph::wendland_multilevel(0.6);
    let (d, report) = opts.solve(&pts, &cons).unwrap();
    assert!(d.iter().all(|v| *v == Vector3::zeros()));
    assert_eq!(report.centres, 0);
    let (ml, _) = opts.multilevel_interpolant(&pts, &cons).unwrap();
    assert!(ml.deformed(&pts).iter().zip(&pts).all(|(a, b)| (a - b).norm() <= 1e-15));
}

/// Every constrained node translated by the same t: the linear term of level 0 is t and
/// the kernel weights vanish, so every node (free and constrained) moves by t, sliding
/// ones by its tangential part, with one level.
#[test]
fn rigid_translation_reproduced_everywhere() {
    let pts = channel_points(14);
    let t = Vector3::new(0.03, -0.02, 0.01);
    let cons: Vec<Constraint> = channel_constraints(&pts)
        .into_iter()
        .map(|c| match c {
            Constraint::Moved(_) | Constraint::Fixed => Constraint::Moved(t),
            c => c,
        })
        .collect();
    let (d, report) = BoundaryMorph::wendland_multilevel(0.6).solve(&pts, &cons).unwrap();
    assert_eq!(report.rounds, 1, "level 0 is exact");
    for (i, c) in cons.iter().enumerate() {
        let want = match c {
            Constraint::Slip(n) => t - n.into_inner() * n.dot(&t),
            _ => t,
        };
        assert!((d[i] - want).norm() <= RIGID_MATCH * t.norm(), "node {i}: {} vs {want}", d[i]);
    }
}

/// With one level whose centre spacing is below the node spacing, every constrained node
/// is a centre and the multilevel interpolant is the single-level RBF on all nodes.
#[test]
fn one_level_is_the_single_level_rbf() {
    let pts = channel_points(6);
    let cons = channel_constraints(&pts);
    let single = BoundaryMorph { greedy_tol: None, ..BoundaryMorph::wendland(0.8) };
    let multi = BoundaryMorph { multilevel: Some(Multilevel { ratio: 1e6, max_levels: 1 }), ..single };
    let (a, ra) = single.solve(&pts, &cons).unwrap();
    let (b, rb) = multi.solve(&pts, &cons).unwrap();
    assert_eq!(ra.centres, ra.constrained);
    assert_eq!(rb.centres, ra.centres);
    assert_eq!(rb.rounds, 1);
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).norm() <= SAME_SYSTEM, "{x} vs {y}");
    }
}

/// A kernel without compact support has no multilevel form.
#[test]
fn global_kernel_refused() {
    let pts = channel_points(4);
    let cons = channel_constraints(&pts);
    let opts =
        BoundaryMorph { kernel: Kernel::ThinPlate { radius: 1.0, k: 2 }, ..BoundaryMorph::wendland_multilevel(1.0) };
    assert!(matches!(opts.solve(&pts, &cons), Err(cadmorph_mesh::Error::Unsupported(_))));
}

/// The bench case in small (24³ hexahedra, graded 4:1 towards the lifted floor): the
/// multilevel morph leaves no inverted cell, the floor is where it was sent, the fixed
/// walls stay, the sides slide in their planes, and the first cell layer above the
/// floor keeps most of its volume.
#[test]
fn multilevel_morph_keeps_every_cell_positive() {
    let mut mesh = channel_mesh(24);
    let original = mesh.points.clone();
    let cons = channel_constraints(&original);
    let before = Geometry::of(&mesh).cell_volumes;
    let (report, br) =
        cadmorph_mesh::volume::morph_volume(&mut mesh, &cons, &BoundaryMorph::wendland_multilevel(0.6), false).unwrap();
    assert!(br.rounds > 1, "{:?}", br.level_centres);
    assert!(br.max_relative_error <= 1e-3);
    assert_eq!(report.after.negative_volumes, 0);
    assert_eq!(Quality::of(&mesh).negative_volumes, 0);
    let after = Geometry::of(&mesh).cell_volumes;
    let min_ratio = before.iter().zip(&after).map(|(a, b)| b / a).fold(f64::INFINITY, f64::min);
    assert!(min_ratio > 0.5, "smallest volume ratio {min_ratio}");
    for (i, c) in cons.iter().enumerate() {
        let d = mesh.points[i] - original[i];
        match c {
            Constraint::Moved(t) => assert!((d - t).norm() < 1e-15),
            Constraint::Fixed => assert_eq!(d, Vector3::zeros()),
            Constraint::Slip(n) => assert!(d.dot(n).abs() < 1e-15),
            Constraint::Free => {}
        }
    }
}
