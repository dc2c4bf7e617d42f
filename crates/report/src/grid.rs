//! Triangles of a face on a fixed parameter grid.
//!
//! The views tessellate each face on a uniform grid of its parameter box instead of the
//! adaptive [`tessellate`](cadmorph_nurbs::NurbsSurface::tessellate): a morphed model
//! keeps its faces' parameter domains (refinement inserts knots), so the same grid
//! before and after puts the vertices of every part the morph did not move at the same
//! places, and a picture of the two differs only where the surface moved. The grid has
//! `4 × (poles − 1)` intervals per direction of the *original* face, between 16 and 96.
//!
//! Trimming curves are not applied: a trimmed face is drawn over its parameter box
//! (B-spline faces) or the surface's whole domain.

use cadmorph_brep::Face;
use cadmorph_nurbs::{NurbsSurface, Surface};

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

/// The parameter box drawn for `face`: the face's own box where it is a B-spline box
/// inside the surface's domain, else the whole domain.
fn parameter_box(face: &Face) -> ((f64, f64), (f64, f64)) {
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
pub fn face_mesh(face: &Face, (nu, nv): (usize, usize)) -> FaceMesh {
    let (nu, nv) = (nu.max(2), nv.max(2));
    let ((u0, u1), (v0, v1)) = parameter_box(face);
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
