//! Closed shells as solids: `CLOSED_SHELL` inside a `MANIFOLD_SOLID_BREP` (added for
//! cadmorph-blade, issue 14).

use cadmorph_nurbs::NurbsSurface;

use super::DocumentBuilder;

impl DocumentBuilder {
    /// Adds one solid bounded by `surfaces`, which must close up (every boundary edge
    /// shared by two faces, within `tol`) and be oriented with their natural normals
    /// `S_u × S_v` pointing out of the solid: the faces and their shared edges and
    /// vertices as [`add_shell`](Self::add_shell) makes them, in a `CLOSED_SHELL` held by
    /// a `MANIFOLD_SOLID_BREP`. Returns the number of faces added.
    pub fn add_solid(&mut self, surfaces: &[NurbsSurface], tol: f64) -> usize {
        let n = self.add_shell(surfaces, tol);
        // add_shell ends with OPEN_SHELL then SHELL_BASED_SURFACE_MODEL(#shell).
        let model = self.bodies.len();
        let shell = model - 1;
        self.bodies[shell - 1] = self.bodies[shell - 1].replacen("OPEN_SHELL(", "CLOSED_SHELL(", 1);
        self.bodies[model - 1] = format!("MANIFOLD_SOLID_BREP('',#{shell})");
        n
    }
}
