//! Any supported mesh file, chosen by its name: an OpenFOAM case or `polyMesh` directory,
//! or a file with one of the extensions below. The one `match` on mesh format.

use std::path::Path;

use nalgebra::Point3;

use crate::error::io;
use crate::format::{
    dyna::KeywordFile, elmer::ElmerNodes, foam::PolyMesh, gmsh::Msh, mdpa::Mdpa, obj::Obj, stl::Stl, unv::Unv,
    vtk::VtkLegacy, vtu::Vtu,
};
use crate::{Cell, Error, Result};

/// A mesh file of any supported format, kept losslessly.
#[derive(Debug, Clone)]
#[non_exhaustive]
#[allow(clippy::large_enum_variant)] // one per program run; boxing would only add an indirection
pub enum MeshFile {
    /// OpenFOAM `polyMesh` directory.
    Foam(PolyMesh),
    /// I-DEAS Universal (`.unv`).
    Unv(Unv),
    /// LS-DYNA keyword (`.k`, `.key`, `.dyn`).
    Dyna(KeywordFile),
    /// Kratos (`.mdpa`).
    Mdpa(Mdpa),
    /// Elmer (`.nodes`, or a directory holding `mesh.nodes`).
    Elmer(ElmerNodes),
    /// STL, ASCII or binary (`.stl`).
    Stl(Stl),
    /// Legacy VTK ASCII (`.vtk`).
    Vtk(VtkLegacy),
    /// Wavefront OBJ (`.obj`).
    Obj(Obj),
    /// Gmsh MSH 2.2 or 4.1 ASCII (`.msh`).
    Msh(Msh),
    /// VTK XML (`.vtu`, `.vtp`).
    Vtu(Vtu),
}

fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(io(path))
}

impl MeshFile {
    /// Read `path`, choosing the format by extension (a directory is an OpenFOAM case or
    /// `polyMesh`, or an Elmer mesh directory).
    ///
    /// # Errors
    ///
    /// [`Error::Unsupported`] for an unknown extension; the reader's error, wrapped in
    /// [`Error::InFile`] with the path.
    pub fn read(path: &Path) -> Result<MeshFile> {
        if path.is_dir() {
            if path.join("mesh.nodes").is_file() {
                let p = path.join("mesh.nodes");
                return ElmerNodes::parse(&read_text(&p)?).map(MeshFile::Elmer).map_err(|e| e.in_file(&p));
            }
            return PolyMesh::read(path).map(MeshFile::Foam);
        }
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        let r = match ext.as_str() {
            "unv" => Unv::parse(&read_text(path)?).map(MeshFile::Unv),
            "k" | "key" | "dyn" => KeywordFile::parse(&read_text(path)?).map(MeshFile::Dyna),
            "mdpa" => Mdpa::parse(&read_text(path)?).map(MeshFile::Mdpa),
            "nodes" => ElmerNodes::parse(&read_text(path)?).map(MeshFile::Elmer),
            "stl" => Stl::parse(&std::fs::read(path).map_err(io(path))?).map(MeshFile::Stl),
            "vtk" => VtkLegacy::parse(&read_text(path)?).map(MeshFile::Vtk),
            "obj" => Obj::parse(&read_text(path)?).map(MeshFile::Obj),
            "msh" => Msh::parse(&read_text(path)?).map(MeshFile::Msh),
            "vtu" | "vtp" => Vtu::parse(&std::fs::read(path).map_err(io(path))?).map(MeshFile::Vtu),
            _ => return Err(Error::Unsupported(format!("{}: unknown mesh extension {ext:?}", path.display()))),
        };
        r.map_err(|e| e.in_file(path))
    }

    /// The node coordinates.
    pub fn points(&self) -> &[Point3<f64>] {
        match self {
            MeshFile::Foam(m) => &m.points,
            MeshFile::Unv(m) => &m.points,
            MeshFile::Dyna(m) => &m.points,
            MeshFile::Mdpa(m) => &m.points,
            MeshFile::Elmer(m) => &m.points,
            MeshFile::Stl(m) => &m.points,
            MeshFile::Vtk(m) => &m.points,
            MeshFile::Obj(m) => &m.points,
            MeshFile::Msh(m) => &m.points,
            MeshFile::Vtu(m) => &m.points,
        }
    }

    /// The node coordinates, to morph.
    pub fn points_mut(&mut self) -> &mut [Point3<f64>] {
        match self {
            MeshFile::Foam(m) => &mut m.points,
            MeshFile::Unv(m) => &mut m.points,
            MeshFile::Dyna(m) => &mut m.points,
            MeshFile::Mdpa(m) => &mut m.points,
            MeshFile::Elmer(m) => &mut m.points,
            MeshFile::Stl(m) => &mut m.points,
            MeshFile::Vtk(m) => &mut m.points,
            MeshFile::Obj(m) => &mut m.points,
            MeshFile::Msh(m) => &mut m.points,
            MeshFile::Vtu(m) => &mut m.points,
        }
    }

    /// The cells the file defines (empty for a nodes-only file, and for OpenFOAM, whose
    /// cells are face-based: see [`MeshFile::volume_mesh`]).
    pub fn cells(&self) -> Vec<Cell> {
        match self {
            MeshFile::Foam(_) | MeshFile::Elmer(_) => Vec::new(),
            MeshFile::Unv(m) => m.cells.clone(),
            MeshFile::Dyna(m) => m.cells.clone(),
            MeshFile::Mdpa(m) => m.cells.iter().map(|c| c.1.clone()).collect(),
            MeshFile::Stl(m) => m.triangles.iter().map(|t| Cell::new(crate::CellKind::Triangle, t.to_vec())).collect(),
            MeshFile::Vtk(m) => m.cells.clone(),
            MeshFile::Obj(m) => m.cells.clone(),
            MeshFile::Msh(m) => m.cells.iter().map(|c| c.1.clone()).collect(),
            MeshFile::Vtu(m) => m.cells.clone(),
        }
    }

    /// The polyhedral mesh for the quality checks: the OpenFOAM mesh itself, or the one
    /// built from the volume cells; `None` when the file has no volume cell.
    ///
    /// # Errors
    ///
    /// As [`PolyMesh::from_cells`].
    pub fn volume_mesh(&self) -> Result<Option<PolyMesh>> {
        if let MeshFile::Foam(m) = self {
            return Ok(Some(m.clone()));
        }
        let cells = self.cells();
        if !cells.iter().any(|c| c.kind.dim() == 3) {
            return Ok(None);
        }
        PolyMesh::from_cells(self.points().to_vec(), &cells).map(Some)
    }

    /// Write the mesh to `path` in its own format (atomically: a temporary sibling, then
    /// a rename).
    ///
    /// # Errors
    ///
    /// [`Error::Io`] naming the path; [`Error::CountMismatch`] when the point count
    /// changed.
    pub fn write(&self, path: &Path) -> Result<()> {
        let read = match self {
            MeshFile::Foam(_) => self.points().len(),
            MeshFile::Unv(m) => m.labels.len(),
            MeshFile::Dyna(m) => m.ids.len(),
            MeshFile::Mdpa(m) => m.ids.len(),
            MeshFile::Elmer(m) => m.ids.len(),
            MeshFile::Stl(m) => m.n_points_read(),
            MeshFile::Vtk(m) => m.n_points_read(),
            MeshFile::Obj(m) => m.n_points_read(),
            MeshFile::Msh(m) => m.tags.len(),
            MeshFile::Vtu(m) => m.n_points_read(),
        };
        if read != self.points().len() {
            return Err(Error::CountMismatch {
                what: format!("points of {} (a morph keeps the count)", path.display()),
                expected: read,
                found: self.points().len(),
            });
        }
        let text = match self {
            MeshFile::Foam(m) => {
                let dir = if path.join("constant").is_dir() || path.join("system").is_dir() {
                    path.join("constant/polyMesh")
                } else {
                    path.to_path_buf()
                };
                return m.write(&dir);
            }
            MeshFile::Unv(m) => m.write(),
            MeshFile::Dyna(m) => m.write(),
            MeshFile::Mdpa(m) => m.write(),
            MeshFile::Elmer(m) => m.write(),
            MeshFile::Stl(m) => return crate::atomic::write_atomic(path, &m.write()),
            MeshFile::Vtu(m) => return crate::atomic::write_atomic(path, &m.write()),
            MeshFile::Vtk(m) => m.write(),
            MeshFile::Obj(m) => m.write(),
            MeshFile::Msh(m) => m.write(),
        };
        let path = if path.is_dir() { path.join("mesh.nodes") } else { path.to_path_buf() };
        crate::atomic::write_atomic(&path, text.as_bytes())
    }
}
