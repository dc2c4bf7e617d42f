//! Watertight tessellation of a closed model of curved NURBS faces: a "pillow" box whose
//! six biquadratic faces bulge by different amounts, so that each face is tessellated
//! with a different number of points along the shared (straight) edges.

use cadmorph_mesh::format::stl::{Solid, Stl};
use cadmorph_mesh::tessellate::{shared_sides, tessellate_watertight};
use cadmorph_nurbs::{KnotVector, NurbsSurface, SurfaceProject};
use nalgebra::{Point3, Vector3};
use std::collections::HashMap;

/// Chordal tolerance of the tessellation (model size 1).
const TOL: f64 = 2e-3;

/// The face of the unit cube with outward normal `n`, as a biquadratic patch whose centre
/// control point is pushed out by `bulge`; parametrised so that S_u × S_v points out.
fn face(n: Vector3<f64>, bulge: f64) -> NurbsSurface {
    // Two in-face directions with e1 × e2 = n.
    let e1 = if n.x.abs() > 0.5 { Vector3::y() } else { Vector3::x() } * 1.0;
    let e1 = e1 - n * n.dot(&e1);
    let e2 = n.cross(&e1);
    let centre = Point3::new(0.5, 0.5, 0.5) + 0.5 * n;
    let mut cps = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            let (a, b) = (i as f64 / 2.0 - 0.5, j as f64 / 2.0 - 0.5);
            let mut p = centre + a * e1 + b * e2;
            if i == 1 && j == 1 {
                p += bulge * n;
            }
            cps.push(p);
        }
    }
    let k = || KnotVector::new_unchecked(vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    NurbsSurface::new((2, 2), (k(), k()), (3, 3), cps, None)
}

fn pillow() -> Vec<NurbsSurface> {
    let dirs = [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y(), Vector3::z(), -Vector3::z()];
    dirs.iter().enumerate().map(|(k, &n)| face(n, 0.05 + 0.07 * k as f64)).collect()
}

fn edge_use(tris: &[[usize; 3]]) -> HashMap<(usize, usize), usize> {
    let mut m = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *m.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    m
}

#[test]
fn pillow_box_is_watertight() {
    let faces = pillow();
    let seams = shared_sides(&faces, 1e-12);
    assert_eq!(seams.len(), 12, "a box has 12 edges");
    // Without stitching the seams have T-junctions: face meshes differ along them.
    let loose = tessellate_watertight(&faces, &[], TOL).unwrap();
    let open = edge_use(&loose.triangles).values().filter(|&&c| c == 1).count();
    assert!(open > 0);
    let w = tessellate_watertight(&faces, &seams, TOL).unwrap();
    let uses = edge_use(&w.triangles);
    let bad: Vec<_> = uses.iter().filter(|(_, &c)| c != 2).collect();
    assert!(bad.is_empty(), "{} edges not shared by exactly two triangles: {:?}", bad.len(), &bad[..bad.len().min(5)]);
    // Euler characteristic of a sphere: V − E + F = 2.
    assert_eq!(w.points.len() as i64 - uses.len() as i64 + w.triangles.len() as i64, 2);
    // Every triangle lies within the chordal tolerance of its face (centroid and an edge
    // midpoint projected on the surface).
    let mut worst: f64 = 0.0;
    for (t, &f) in w.triangles.iter().zip(&w.face_of) {
        let [a, b, c] = t.map(|i| w.points[i]);
        for p in [Point3::from((a.coords + b.coords + c.coords) / 3.0), Point3::from((a.coords + b.coords) / 2.0)] {
            worst = worst.max(faces[f].project(&p, 1e-12).distance_sq.sqrt());
        }
    }
    assert!(worst <= TOL, "chordal deviation {worst}");
    // The triangles as an STL with one solid per face: reads back with the same topology.
    let mut order: Vec<usize> = (0..w.triangles.len()).collect();
    order.sort_by_key(|&i| w.face_of[i]);
    let tris: Vec<[usize; 3]> = order.iter().map(|&i| w.triangles[i]).collect();
    let solids = (0..faces.len())
        .map(|f| {
            let s = order.partition_point(|&i| w.face_of[i] < f);
            let e = order.partition_point(|&i| w.face_of[i] <= f);
            Solid { name: format!("face{f}"), triangles: s..e }
        })
        .collect();
    let stl = Stl::from_triangles(w.points.clone(), tris, solids).unwrap();
    let back = Stl::parse(stl.write_ascii().as_bytes()).unwrap();
    assert_eq!(back.points.len(), w.points.len());
    assert_eq!(back.solids.len(), 6);
    assert!(edge_use(&back.triangles).values().all(|&c| c == 2));
}
