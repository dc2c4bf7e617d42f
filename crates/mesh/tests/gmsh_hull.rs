//! Issue 15: an unstructured tetrahedral mesh around the sample hull, made by gmsh from
//! `samples/hull3.stp` (`tests/mesh/hull_tets.py`), follows the bow-dome FFD of the CAD.
//!
//! The boundary deformation comes from the CAD morph itself: each hull node is projected
//! onto the original faces, and moves to the morphed face at the same parameters (a morph
//! moves control points and keeps each face's parametrisation), so it lies on the morphed CAD;
//! the far box is fixed, the centreplane and the deck plane slide. RBF (Wendland C²,
//! greedy centres) carries the motion to the interior nodes. No tetrahedron may invert.

use std::collections::BTreeSet;
use std::path::PathBuf;
use std::process::Command;

use cadmorph_mesh::format::gmsh::Msh;
use cadmorph_mesh::volume::{BoundaryMorph, Constraint};
use cadmorph_mesh::CellKind;
use cadmorph_model::{Model, MorphOptions};
use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::Ffd;
use cadmorph_nurbs::{Surface, SurfaceProject};
use cadmorph_testkit::{sample, Scratch};
use nalgebra::Unit;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn signed_volume(p: &[Point3<f64>], t: &[usize]) -> f64 {
    (p[t[1]] - p[t[0]]).cross(&(p[t[2]] - p[t[0]])).dot(&(p[t[3]] - p[t[0]])) / 6.0
}

#[test]
#[ignore = "needs gmsh (the venv of tests/mesh/setup.sh)"]
fn gmsh_tetrahedra_around_the_hull_follow_the_cad_morph() {
    let scratch = Scratch::new("gmsh-hull");
    let msh_path = scratch.dir().join("hull.msh");
    let out = Command::new(root().join("tests/mesh/.venv/bin/python"))
        .arg(root().join("tests/mesh/hull_tets.py"))
        .arg(sample("hull3.stp"))
        .arg(&msh_path)
        .output()
        .expect("run tests/mesh/setup.sh first");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let hull_tags: BTreeSet<i64> = info["hull"].as_array().unwrap().iter().map(|t| t.as_i64().unwrap()).collect();
    let msh = Msh::parse(&std::fs::read_to_string(&msh_path).unwrap()).unwrap();
    let tets: Vec<&[usize]> =
        msh.cells.iter().filter(|(_, c)| c.kind == CellKind::Tetra).map(|(_, c)| c.nodes.as_slice()).collect();
    assert_eq!(tets.len() as u64, info["tetrahedra"].as_u64().unwrap());
    let mut hull_nodes = BTreeSet::new();
    let mut outer_nodes = BTreeSet::new();
    for (tag, c) in &msh.cells {
        if c.kind == CellKind::Triangle {
            let set = if hull_tags.contains(tag) { &mut hull_nodes } else { &mut outer_nodes };
            set.extend(c.nodes.iter().copied());
        }
    }
    let outer_nodes: Vec<usize> = outer_nodes.difference(&hull_nodes).copied().collect();

    // The CAD before and after the bow-dome FFD (without seam refinement, which keeps the
    // parametrisation and so would change nothing below but the time).
    let bytes = std::fs::read(sample("hull3.stp")).unwrap();
    let before: Model<cadmorph_step::Document> = Model::from_bytes(&bytes).unwrap();
    let mut after: Model<cadmorph_step::Document> = Model::from_bytes(&bytes).unwrap();
    let ffd = Ffd::from_prm(&std::fs::read_to_string(sample("prm/bow_dome.prm")).unwrap()).unwrap();
    after.morph(&ffd, &MorphOptions::default()).unwrap();
    let length = before.size();

    // Each hull node on the original faces: the closest face and its parameters.
    let p0 = &msh.points;
    let mut constraints = vec![Constraint::Free; p0.len()];
    let mut worst_on_cad: f64 = 0.0;
    let mut targets = Vec::new();
    let mut largest: f64 = 0.0;
    for &n in &hull_nodes {
        let (face, pr) = before
            .patches()
            .iter()
            .enumerate()
            .map(|(i, f)| (i, f.surface.project(&p0[n], 1e-12 * length)))
            .min_by(|a, b| a.1.distance_sq.total_cmp(&b.1.distance_sq))
            .unwrap();
        worst_on_cad = worst_on_cad.max(pr.distance_sq.sqrt());
        let moved = after.patches()[face].surface.eval(pr.u, pr.v);
        largest = largest.max((moved - p0[n]).norm());
        constraints[n] = Constraint::Moved(moved - p0[n]);
        targets.push((n, face));
    }
    eprintln!(
        "{} tetrahedra, {} hull nodes (on the CAD to {worst_on_cad:.2e} m), {} other boundary nodes; largest hull motion {largest:.4} m",
        tets.len(),
        hull_nodes.len(),
        outer_nodes.len()
    );
    assert!(worst_on_cad <= 1e-6 * length, "gmsh's nodes are {worst_on_cad:e} off the CAD");
    assert!(largest > 0.1, "the morph must move the hull for the test to mean anything ({largest})");
    let tol = 1e-9 * length;
    for &n in &outer_nodes {
        let p = p0[n];
        constraints[n] = if p.y.abs() <= tol {
            Constraint::Slip(Unit::new_normalize(Vector3::y()))
        } else if (p.z - 12.5).abs() <= tol {
            Constraint::Slip(Unit::new_normalize(Vector3::z()))
        } else {
            Constraint::Fixed
        };
    }

    let (d, report) = BoundaryMorph::wendland(60.0).solve(p0, &constraints).unwrap();
    eprintln!("{report:?}");
    let p1: Vec<Point3<f64>> = p0.iter().zip(&d).map(|(p, d)| p + d).collect();

    // Every hull node on the morphed CAD (to 1e-9 × length).
    let mut worst_after: f64 = 0.0;
    for &(n, face) in &targets {
        let s = &after.patches()[face].surface;
        worst_after = worst_after.max(s.project(&p1[n], 1e-13 * length).distance_sq.sqrt());
    }
    // No tetrahedron inverted; the smallest volume ratio.
    let mut inverted = 0;
    let mut min_ratio = f64::INFINITY;
    for t in &tets {
        let (v0, v1) = (signed_volume(p0, t), signed_volume(&p1, t));
        if v0.signum() != v1.signum() || v1 == 0.0 {
            inverted += 1;
        }
        min_ratio = min_ratio.min(v1 / v0);
    }
    eprintln!("hull nodes off the morphed CAD: {worst_after:.2e} m; inverted {inverted}; smallest volume ratio {min_ratio:.4}");
    assert!(worst_after <= 1e-9 * length, "{worst_after:e}");
    assert_eq!(inverted, 0);
    assert!(min_ratio > 0.0);
}
