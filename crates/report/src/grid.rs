//! Triangles of a face on a fixed parameter grid.
//!
//! The views tessellate each face on a uniform grid of its parameter box instead of the
//! adaptive [`tessellate`](cadmorph_nurbs::NurbsSurface::tessellate): a morphed model
//! keeps its faces' parameter domains (refinement inserts knots), so the same grid
//! before and after puts the vertices of every part the morph did not move at the same
//! places, and a picture of the two differs only where the surface moved. The grid has
//! `4 × (poles − 1)` intervals per direction of the *original* face, between 16 and 96.
//!
//! A trimmed face is drawn trimmed ([`trimmed_face_mesh`]): the grid of the box its
//! bound curves span, less the triangles whose centroid lies outside the face ([`Trim`]: outside the
//! outer loop or inside a hole). The grid, and so the vertices, stay those of the whole
//! box; only triangles are left out, so the drawn area converges to the face's area as
//! the grid is refined, with an error of the order of the boundary's length times a
//! grid cell's size.

use cadmorph_brep::Face;
use cadmorph_nurbs::{NurbsSurface, Surface};

use crate::trim::Trim;

/// A face's triangles.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceMesh {
    /// Vertex positions, model units.
    pub positions: Vec<[f64; 3]>,
    /// Unit vertex normals, flipped for reversed faces (zero where the surface has none).
    pub normals: Vec<[f64; 3]>,
    /// Grid size: `nu × nv` vertices, row-major in v (`index = j * nu + i`).
    pub nu: usize,
    /// See `nu`.
    pub nv: usize,
    /// Vertex indices of each triangle, counter-clockwise seen from the face's outside.
    pub triangles: Vec<[u32; 3]>,
}

/// Grid vertices per direction of `s`: `4 × (poles − 1) + 1`, between 17 and 97.
pub fn grid_size(s: &NurbsSurface) -> (usize, usize) {
    let n = |poles: usize| (4 * poles.saturating_sub(1)).clamp(16, 96) + 1;
    (n(s.n_u()), n(s.n_v()))
}

/// The parameter box drawn for `face`, in its NURBS surface's parameters: the face's
/// own box where it is a B-spline box inside the surface's domain, else the whole domain.
pub fn parameter_box(face: &Face) -> ((f64, f64), (f64, f64)) {
    let (ud, vd) = face.surface.domain();
    let whole = ((*ud.start(), *ud.end()), (*vd.start(), *vd.end()));
    if face.kind.is_analytic() {
        return whole;
    }
    let ((u0, u1), (v0, v1)) = face.parameter_box;
    let inside =
        |(a, b): (f64, f64), (lo, hi): (f64, f64)| a.is_finite() && b.is_finite() && a < b && a >= lo && b <= hi;
    if inside((u0, u1), whole.0) && inside((v0, v1), whole.1) {
        ((u0, u1), (v0, v1))
    } else {
        whole
    }
}

/// Tessellates `face` on an `nu × nv` grid of its parameter box.
pub fn face_mesh(face: &Face, grid: (usize, usize)) -> FaceMesh {
    face_mesh_over(face, grid, parameter_box(face))
}

/// Tessellates `face` on an `nu × nv` grid of the parameter box `((u0, u1), (v0, v1))`.
fn face_mesh_over(face: &Face, (nu, nv): (usize, usize), ((u0, u1), (v0, v1)): ((f64, f64), (f64, f64))) -> FaceMesh {
    let (nu, nv) = (nu.max(2), nv.max(2));
    let s = &face.surface;
    let flip = if face.reversed { -1.0 } else { 1.0 };
    let mut positions = Vec::with_capacity(nu * nv);
    let mut normals = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        let v = v0 + (v1 - v0) * j as f64 / (nv - 1) as f64;
        for i in 0..nu {
            let u = u0 + (u1 - u0) * i as f64 / (nu - 1) as f64;
            let p = s.eval(u, v);
            positions.push([p.x, p.y, p.z]);
            let n = s.normal(u, v).map_or([0.0; 3], |n| [n.x * flip, n.y * flip, n.z * flip]);
            normals.push(n);
        }
    }
    let mut triangles = Vec::with_capacity(2 * (nu - 1) * (nv - 1));
    for j in 0..nv - 1 {
        for i in 0..nu - 1 {
            let a = (j * nu + i) as u32;
            let (b, c, d) = (a + 1, a + nu as u32, a + nu as u32 + 1);
            if face.reversed {
                triangles.push([a, c, b]);
                triangles.push([b, c, d]);
            } else {
                triangles.push([a, b, c]);
                triangles.push([b, d, c]);
            }
        }
    }
    FaceMesh { positions, normals, nu, nv, triangles }
}

/// `face` on the grid of the box its trim spans ([`Trim::parameter_box`]), less the
/// triangles whose centroid (in the surface's parameters) lies outside `trim`. All
/// vertices of the grid are kept (so the same grid indices hold for any trim); when the
/// trim would leave no triangle, the whole box is drawn.
pub fn trimmed_face_mesh(face: &Face, grid: (usize, usize), trim: &Trim) -> FaceMesh {
    let bx = trim.parameter_box();
    let mut m = face_mesh_over(face, grid, bx);
    let ((u0, u1), (v0, v1)) = bx;
    let (nu, nv) = (m.nu, m.nv);
    let uv = |k: u32| {
        let (i, j) = (k as usize % nu, k as usize / nu);
        (u0 + (u1 - u0) * i as f64 / (nu - 1) as f64, v0 + (v1 - v0) * j as f64 / (nv - 1) as f64)
    };
    let kept: Vec<[u32; 3]> = m
        .triangles
        .iter()
        .copied()
        .filter(|t| {
            let (a, b, c) = (uv(t[0]), uv(t[1]), uv(t[2]));
            trim.contains((a.0 + b.0 + c.0) / 3.0, (a.1 + b.1 + c.1) / 3.0)
        })
        .collect();
    if !kept.is_empty() {
        m.triangles = kept;
    }
    m
}

/// The area of the triangles of `m`, model units squared.
pub fn mesh_area(m: &FaceMesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| m.positions[k as usize]);
            let (e, f) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
            let n = [e[1] * f[2] - e[2] * f[1], e[2] * f[0] - e[0] * f[2], e[0] * f[1] - e[1] * f[0]];
            0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use cadmorph_brep::{EntityRef, Format, SurfaceKind};
    use nalgebra::Matrix4;

    fn square(reversed: bool) -> Face {
        let surface = NurbsSurface::bilinear([[0., 0., 0.], [2., 0., 0.], [0., 1., 0.], [2., 1., 0.]]);
        let e = EntityRef::new(Format::Iges, 1);
        Face {
            entity: e,
            surface_entity: e,
            surface,
            parameter_box: ((0.0, 1.0), (0.0, 1.0)),
            reversed,
            trimmed: false,
            kind: SurfaceKind::BSpline,
            type_name: "IGES 128".into(),
            placement: Matrix4::identity(),
        }
    }

    #[test]
    fn grid_of_a_plane() {
        let m = face_mesh(&square(false), (3, 2));
        assert_eq!(m.positions.len(), 6);
        assert_eq!(m.positions[2], [2.0, 0.0, 0.0]);
        assert_eq!(m.positions[5], [2.0, 1.0, 0.0]);
        assert_eq!(m.triangles.len(), 4);
        // Counter-clockwise seen along +z, the surface normal.
        let t = m.triangles[0].map(|k| m.positions[k as usize]);
        let cross = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
        assert!(cross > 0.0);
        assert_eq!(m.normals[0], [0.0, 0.0, 1.0]);
        let r = face_mesh(&square(true), (3, 2));
        assert_eq!(r.normals[0], [0.0, 0.0, -1.0]);
        let t = r.triangles[0].map(|k| r.positions[k as usize]);
        let cross = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
        assert!(cross < 0.0);
    }
}
