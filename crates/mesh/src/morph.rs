//! Morphing a mesh's nodes by any [`Deformation`] (paper §3.1.1: the same FFD/RBF/IDW laws
//! that move CAD control points move mesh nodes), with the quality check before and after
//! that refuses a morph which would spoil a volume mesh.

use cadmorph_morph::Deformation;

use crate::format::foam::PolyMesh;
use crate::quality::Quality;
use crate::{Error, Result};

/// The quality of a volume mesh before and after a morph.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MorphReport {
    /// Before.
    pub before: Quality,
    /// After.
    pub after: Quality,
}

impl MorphReport {
    /// Whether the morph made the mesh worse in a way `checkMesh` (or its `-allGeometry`
    /// face-angle check) flags: more failed checks, more inverted cells or pyramids, more
    /// concave faces.
    pub fn degraded(&self) -> bool {
        let (b, a) = (&self.before, &self.after);
        a.failed.len() > b.failed.len()
            || a.negative_volumes > b.negative_volumes
            || a.pyramid_errors > b.pyramid_errors
            || a.concave_faces > b.concave_faces
    }
}

/// Move every point of `mesh` by `deformation` and check the result.
///
/// When the morph degrades the mesh ([`MorphReport::degraded`]) and `allow_degrade` is
/// not set, the points are put back and [`Error::Degraded`] says which checks failed and
/// where; nothing is changed then. With `allow_degrade` the morphed mesh is kept and the
/// report says where it is bad.
///
/// # Errors
///
/// [`Error::Degraded`], or [`Error::NonFinite`] when the deformation produced NaN.
pub fn morph_checked<D: Deformation + ?Sized>(
    mesh: &mut PolyMesh,
    deformation: &D,
    allow_degrade: bool,
) -> Result<MorphReport> {
    let moved = deformation.deformed(&mesh.points);
    move_checked(mesh, moved, allow_degrade)
}

/// Give `mesh` the points `moved` (one per point) if that does not degrade it, as
/// [`morph_checked`] does for a deformation.
///
/// # Errors
///
/// [`Error::CountMismatch`] for a wrong count; [`Error::NonFinite`]; [`Error::Degraded`].
pub fn move_checked(
    mesh: &mut PolyMesh,
    moved: Vec<nalgebra::Point3<f64>>,
    allow_degrade: bool,
) -> Result<MorphReport> {
    if moved.len() != mesh.points.len() {
        return Err(Error::CountMismatch {
            what: "moved points".into(),
            expected: mesh.points.len(),
            found: moved.len(),
        });
    }
    crate::text::check_finite(&moved)?;
    let before = Quality::of(mesh);
    let original = std::mem::replace(&mut mesh.points, moved);
    let after = Quality::of(mesh);
    let report = MorphReport { before, after };
    if report.degraded() && !allow_degrade {
        mesh.points = original;
        let mut summary = report.after.failed.join("; ");
        if report.after.concave_faces > report.before.concave_faces {
            if !summary.is_empty() {
                summary.push_str("; ");
            }
            summary.push_str(&format!(
                "{} concave face(s), worst {:.3}° at face {}",
                report.after.concave_faces, report.after.max_concave_angle.value, report.after.max_concave_angle.index
            ));
        }
        return Err(Error::Degraded { failed: report.after.failed.len().max(1), summary });
    }
    Ok(report)
}

/// Morph any mesh file: every node moves by `deformation`; when the file has volume cells
/// the quality is checked before and after and a degrading morph is refused (points put
/// back) unless `allow_degrade`, as [`morph_checked`]. Surface and nodes-only files are
/// morphed without a check and give `None`.
///
/// # Errors
///
/// As [`morph_checked`]; [`PolyMesh::from_cells`] errors for inconsistent cells.
pub fn morph_file<D: Deformation + ?Sized>(
    file: &mut crate::MeshFile,
    deformation: &D,
    allow_degrade: bool,
) -> Result<Option<MorphReport>> {
    if let crate::MeshFile::Foam(m) = file {
        return morph_checked(m, deformation, allow_degrade).map(Some);
    }
    match file.volume_mesh()? {
        Some(mut poly) => {
            let report = morph_checked(&mut poly, deformation, allow_degrade)?;
            file.points_mut().copy_from_slice(&poly.points);
            Ok(Some(report))
        }
        None => {
            let original = file.points().to_vec();
            deformation.deform(file.points_mut());
            if let Err(e) = crate::text::check_finite(file.points()) {
                file.points_mut().copy_from_slice(&original);
                return Err(e);
            }
            Ok(None)
        }
    }
}
