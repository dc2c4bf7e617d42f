//! BladeX's per-point interpolation error report (`Blade._write_blade_errors`,
//! `errors.txt`): every section point (×1000, BladeX's metre → millimetre factor) and its
//! distance to the face.

use crate::blade::BladeCoordinates;
use crate::prm::py_float;
use crate::solid::BladeSolid;
use crate::Result;

/// The report text in BladeX's layout: an upper-face block then a lower-face block, one
/// line per point `section  point  X  Y  Z  distance`, tab-separated as BladeX writes it.
/// Sections are numbered from the root (BladeX numbers from the tip, its array order).
/// Distances are measured at each point's interpolation parameters (see
/// [`BladeSolid::section_errors`]), in the same ×1000 units.
///
/// # Errors
///
/// Those of [`BladeSolid::section_errors`].
pub fn errors_txt(solid: &BladeSolid, c: &BladeCoordinates) -> Result<String> {
    let s = &solid.wrapped.surface;
    let (u, v) = (&solid.wrapped.u, &solid.wrapped.v);
    let le = solid.le_index;
    let mut out = String::from("\n");
    for (title, side, upper) in [("UPPER", &c.up, true), ("LOWER", &c.down, false)] {
        out.push_str(&format!("########## {title} FACE ##########\n\n"));
        out.push_str("N_section\t\tN_point\t\t\tX_crds\t\t\t\tY_crds\t\t\t\t\tZ_crds\t\t\t\t\tDISTANCE\n\n");
        for (i, sec) in side.iter().enumerate() {
            for (j, p) in sec.iter().enumerate() {
                let k = if upper { le - j } else { le + j };
                let d = (cadmorph_nurbs::Surface::eval(s, u[k], v[i]) - p).norm();
                out.push_str(&format!(
                    "{i}\t\t\t{j}\t\t\t{}\t\t\t{}\t\t\t{}\t\t\t{}\n",
                    py_float(1000.0 * p.x),
                    py_float(1000.0 * p.y),
                    py_float(1000.0 * p.z),
                    py_float(1000.0 * d)
                ));
            }
        }
    }
    Ok(out)
}
