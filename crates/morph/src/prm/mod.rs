//! PyGeM `.prm` parameter files for FFD, RBF and IDW: reading (with the line of every
//! problem) and writing (byte-identical to PyGeM's writers and its expected test files).
//!
//! The crate sees text, not files: read the file yourself and pass its contents.
//!
//! ```
//! use cadmorph_morph::{prm, Ffd};
//! let ffd = Ffd::unit([2, 2, 2]);
//! let text = ffd.to_prm();
//! assert!(text.starts_with("\n[Box info]\n"));
//! match prm::read(&text)? {
//!     cadmorph_morph::Parameters::Ffd(back) => assert_eq!(back, ffd),
//!     _ => unreachable!(),
//! }
//! # Ok::<(), cadmorph_morph::Error>(())
//! ```

mod ini;
mod pyfmt;

pub use pyfmt::float_str;

use nalgebra::{Point3, Vector3};

use crate::idw::{IdwParameters, IdwVariant};
use crate::rbf::{Kernel, RbfParameters};
use crate::{Displacements, Error, Ffd, Parameters, Result};
use ini::{parse_finite, parse_usize, Entry, Ini};

/// Read a `.prm` file of any of the three kinds; which one is decided by its sections
/// (`[Box info]`, `[Radial Basis Functions]`, `[Inverse Distance Weighting]`). An IDW file
/// gives [`IdwVariant::PyGem`]: that is what PyGeM computes from it.
///
/// # Errors
///
/// Every error names the line: [`Error::Syntax`], [`Error::MissingSection`] (none of the
/// three kinds), [`Error::MissingKey`], [`Error::UnknownKernel`],
/// [`Error::UnknownParameter`], [`Error::CountMismatch`], [`Error::IndexOutOfRange`],
/// [`Error::Duplicate`], [`Error::InvalidParameter`].
pub fn read(text: &str) -> Result<Parameters> {
    let ini = Ini::parse(text)?;
    if ini.section(FFD_BOX).is_some() {
        Ok(Parameters::Ffd(ffd_from_ini(&ini)?))
    } else if ini.section(RBF).is_some() {
        Ok(Parameters::Rbf(rbf_from_ini(&ini)?))
    } else if ini.section(IDW).is_some() {
        Ok(Parameters::Idw(idw_from_ini(&ini)?))
    } else {
        Err(Error::MissingSection { section: FFD_BOX })
    }
}

const FFD_BOX: &str = "Box info";
const FFD_WEIGHTS: &str = "Parameters weights";
const RBF: &str = "Radial Basis Functions";
const IDW: &str = "Inverse Distance Weighting";
const CONTROL: &str = "Control points";

impl Ffd {
    /// Read a PyGeM FFD `.prm` file (sections `[Box info]`, `[Parameters weights]`).
    ///
    /// Weight lines are `i j k value`; omitted nodes have zero displacement.
    ///
    /// # Errors
    ///
    /// As [`read`]; also an index outside the lattice or a node given twice.
    pub fn from_prm(text: &str) -> Result<Ffd> {
        ffd_from_ini(&Ini::parse(text)?)
    }

    /// The `.prm` text PyGeM's `FFD.write_parameters` writes for these parameters, byte for byte.
    pub fn to_prm(&self) -> String {
        let n = self.n_control_points();
        let (len, org, rot) = (self.box_length(), self.box_origin(), self.rot_angle());
        let f = float_str;
        let mut s = String::new();
        s += "\n[Box info]\n";
        s += "# This section collects all the properties of the FFD bounding box.\n";
        s += "\n# n control points indicates the number of control points in each direction (x, y, z).\n";
        s += "# For example, to create a 2 x 3 x 2 grid, use the following: n control points: 2, 3, 2\n";
        s += &format!("n control points x: {}\nn control points y: {}\nn control points z: {}\n", n[0], n[1], n[2]);
        s += "\n# box length indicates the length of the FFD bounding box along the three canonical directions (x, y, z).\n";
        s += "# It uses the local coordinate system.\n";
        s += "# For example to create a 2 x 1.5 x 3 meters box use the following: box length: 2.0, 1.5, 3.0\n";
        s += &format!("box length x: {}\nbox length y: {}\nbox length z: {}\n", f(len.x), f(len.y), f(len.z));
        s += "\n# box origin indicates the x, y, and z coordinates of the origin of the FFD bounding box. That is center of\n";
        s += "# rotation of the bounding box. It corresponds to the point coordinates with position [0][0][0].\n";
        s += "# See section \"Parameters weights\" for more details.\n";
        s += "# For example, if the origin is equal to 0., 0., 0., use the following: box origin: 0., 0., 0.\n";
        s += &format!("box origin x: {}\nbox origin y: {}\nbox origin z: {}\n", f(org.x), f(org.y), f(org.z));
        s += "\n# rotation angle indicates the rotation angle around the x, y, and z axis of the FFD bounding box in degrees.\n";
        s += "# The rotation is done with respect to the box origin.\n";
        s += "# For example, to rotate the box by 2 deg along the z direction, use the following: rotation angle: 0., 0., 2.\n";
        s += &format!(
            "rotation angle x: {}\nrotation angle y: {}\nrotation angle z: {}\n",
            f(rot.x),
            f(rot.y),
            f(rot.z)
        );
        s += "\n\n[Parameters weights]\n";
        s += "# This section describes the weights of the FFD control points.\n";
        s += "# We adopt the following convention:\n";
        s += "# For example with a 2x2x2 grid of control points we have to fill a 2x2x2 matrix of weights.\n";
        s += "# If a weight is equal to zero you can discard the line since the default is zero.\n";
        s += "#\n";
        s += "# | x index | y index | z index | weight |\n";
        s += "#  --------------------------------------\n";
        s += "# |    0    |    0    |    0    |  1.0   |\n";
        s += "# |    0    |    1    |    1    |  0.0   | --> you can erase this line without effects\n";
        s += "# |    0    |    1    |    0    | -2.1   |\n";
        s += "# |    0    |    0    |    1    |  3.4   |\n";
        let mu = self.mu();
        for (axis, values) in [("x", &mu.x), ("y", &mu.y), ("z", &mu.z)] {
            s += &format!(
                "\n# parameter {axis} collects the displacements along {axis}, normalized with the box length {axis}."
            );
            s += &format!("\nparameter {axis}:");
            let mut offset = 1;
            for i in 0..n[0] {
                for j in 0..n[1] {
                    for k in 0..n[2] {
                        let v = values[(i * n[1] + j) * n[2] + k];
                        s += &format!("{}{i}   {j}   {k}   {}\n", " ".repeat(offset), f(v));
                        offset = 13;
                    }
                }
            }
        }
        s
    }
}

fn ffd_from_ini(ini: &Ini) -> Result<Ffd> {
    let bx = ini.require(FFD_BOX)?;
    let int = |key: &'static str| -> Result<(usize, usize)> {
        let v = bx.require(FFD_BOX, key)?.scalar()?;
        let n = parse_usize(&v.text, v.line)?;
        if n < 2 {
            return Err(Error::InvalidParameter {
                line: Some(v.line),
                name: "n control points",
                value: n as f64,
                reason: "each lattice dimension must be at least 2",
            });
        }
        Ok((n, v.line))
    };
    let float = |key: &'static str, name: &'static str| -> Result<(f64, usize)> {
        let v = bx.require(FFD_BOX, key)?.scalar()?;
        Ok((parse_finite(&v.text, v.line, name)?, v.line))
    };
    let sizes = [int("n control points x")?, int("n control points y")?, int("n control points z")?];
    let shape = sizes.map(|(n, _)| n);
    let mut length = [0.0; 3];
    for (slot, key) in length.iter_mut().zip(["box length x", "box length y", "box length z"]) {
        let (v, line) = float(key, "box length")?;
        if v <= 0.0 {
            return Err(Error::InvalidParameter {
                line: Some(line),
                name: "box length",
                value: v,
                reason: "must be positive",
            });
        }
        *slot = v;
    }
    let origin = [
        float("box origin x", "box origin")?.0,
        float("box origin y", "box origin")?.0,
        float("box origin z", "box origin")?.0,
    ];
    let angle = [
        float("rotation angle x", "rotation angle")?.0,
        float("rotation angle y", "rotation angle")?.0,
        float("rotation angle z", "rotation angle")?.0,
    ];
    let mut ffd = Ffd::try_new(shape, Point3::from(origin), Vector3::from(length), Vector3::from(angle)).map_err(
        |e| match e {
            // The line of the dimension over its limit, else of the last dimension.
            Error::LatticeTooLarge { line: None, shape, axis, limit } => {
                let line = Some(sizes[axis.unwrap_or(2).min(2)].1);
                Error::LatticeTooLarge { line, shape, axis, limit }
            }
            other => other,
        },
    )?;
    let w = ini.require(FFD_WEIGHTS)?;
    let mut mu = Displacements::zeros(shape);
    for (key, target) in [("parameter x", 0), ("parameter y", 1), ("parameter z", 2)] {
        let entry = w.require(FFD_WEIGHTS, key)?;
        let mut seen: Vec<Option<usize>> = vec![None; shape[0] * shape[1] * shape[2]];
        for row in entry.rows() {
            let tokens: Vec<&str> = row.text.split_whitespace().collect();
            if tokens.len() != 4 {
                return Err(Error::Syntax {
                    line: row.line,
                    expected: "`i j k weight` (four values)",
                    found: row.text.clone(),
                });
            }
            let index = [
                parse_usize(tokens[0], row.line)?,
                parse_usize(tokens[1], row.line)?,
                parse_usize(tokens[2], row.line)?,
            ];
            if index.iter().zip(shape).any(|(&i, n)| i >= n) {
                return Err(Error::IndexOutOfRange { line: row.line, index, shape });
            }
            let value = parse_finite(tokens[3], row.line, "weight")?;
            let flat = (index[0] * shape[1] + index[1]) * shape[2] + index[2];
            if let Some(first) = seen[flat] {
                return Err(Error::Duplicate {
                    line: row.line,
                    first,
                    what: format!("{key} weight ({}, {}, {})", index[0], index[1], index[2]),
                });
            }
            seen[flat] = Some(row.line);
            match target {
                0 => mu.x[flat] = value,
                1 => mu.y[flat] = value,
                _ => mu.z[flat] = value,
            }
        }
    }
    ffd.set_mu(mu)?;
    Ok(ffd)
}

/// Reads `original control points` and `deformed control points` (three numbers a line,
/// the same count in both).
/// Control points before and after the deformation.
type PointPairs = (Vec<Point3<f64>>, Vec<Point3<f64>>);

fn control_points_from_ini(ini: &Ini) -> Result<PointPairs> {
    let cp = ini.require(CONTROL)?;
    let orig_entry = cp.require(CONTROL, "original control points")?;
    let def_entry = cp.require(CONTROL, "deformed control points")?;
    let original = points_of(orig_entry)?;
    let deformed = points_of(def_entry)?;
    if original.is_empty() {
        return Err(Error::Syntax {
            line: orig_entry.line,
            expected: "at least one control point",
            found: String::new(),
        });
    }
    if deformed.len() != original.len() {
        return Err(Error::CountMismatch {
            line: def_entry.line,
            what: "deformed control points (one per original control point)",
            expected: original.len(),
            found: deformed.len(),
        });
    }
    Ok((original, deformed))
}

fn points_of(entry: &Entry) -> Result<Vec<Point3<f64>>> {
    entry
        .rows()
        .map(|row| {
            let t: Vec<&str> = row.text.split_whitespace().collect();
            if t.len() != 3 {
                return Err(Error::Syntax {
                    line: row.line,
                    expected: "three coordinates `x y z`",
                    found: row.text.clone(),
                });
            }
            Ok(Point3::new(
                parse_finite(t[0], row.line, "coordinate")?,
                parse_finite(t[1], row.line, "coordinate")?,
                parse_finite(t[2], row.line, "coordinate")?,
            ))
        })
        .collect()
}

fn rbf_from_ini(ini: &Ini) -> Result<RbfParameters> {
    let s = ini.require(RBF)?;
    let basis = s.require(RBF, "basis function")?.scalar()?;
    let radius_v = s.require(RBF, "radius")?.scalar()?;
    let radius = parse_finite(&radius_v.text, radius_v.line, "radius")?;
    if radius <= 0.0 {
        return Err(Error::InvalidParameter {
            line: Some(radius_v.line),
            name: "radius",
            value: radius,
            reason: "must be positive",
        });
    }
    if !Kernel::NAMES.contains(&basis.text.as_str()) {
        return Err(Error::UnknownKernel { line: basis.line, name: basis.text.clone() });
    }
    let mut k = None;
    for e in &s.entries {
        match e.key.as_str() {
            "basis function" | "radius" => {}
            "k" if matches!(basis.text.as_str(), "thin_plate_spline" | "polyharmonic_spline") => {
                let v = e.scalar()?;
                let kv = parse_usize(&v.text, v.line)?;
                if kv == 0 || kv > 64 {
                    return Err(Error::InvalidParameter {
                        line: Some(v.line),
                        name: "k",
                        value: kv as f64,
                        reason: "must be in 1..=64",
                    });
                }
                k = Some(kv as u32);
            }
            other => {
                return Err(Error::UnknownParameter {
                    line: e.line,
                    name: other.to_string(),
                    context: basis.text.clone(),
                });
            }
        }
    }
    let kernel = Kernel::from_name(&basis.text, radius, k)
        .ok_or_else(|| Error::UnknownKernel { line: basis.line, name: basis.text.clone() })?;
    let (original, deformed) = control_points_from_ini(ini)?;
    Ok(RbfParameters { kernel, original, deformed })
}

fn idw_from_ini(ini: &Ini) -> Result<IdwParameters> {
    let s = ini.require(IDW)?;
    let p = s.require(IDW, "power")?.scalar()?;
    let power = parse_usize(&p.text, p.line)?;
    if power == 0 || power > 64 {
        return Err(Error::InvalidParameter {
            line: Some(p.line),
            name: "power",
            value: power as f64,
            reason: "PyGeM's Minkowski distance needs a power in 1..=64",
        });
    }
    if let Some(e) = s.entries.iter().find(|e| e.key != "power") {
        return Err(Error::UnknownParameter { line: e.line, name: e.key.clone(), context: format!("[{IDW}]") });
    }
    let (original, deformed) = control_points_from_ini(ini)?;
    Ok(IdwParameters { variant: IdwVariant::PyGem { power: power as u32 }, original, deformed })
}

fn write_points(s: &mut String, label: &str, points: &[Point3<f64>], pad: usize) {
    s.push_str(label);
    let mut first = true;
    for p in points {
        if !first {
            s.push_str(&" ".repeat(pad));
        }
        first = false;
        s.push_str(&format!("{}   {}   {}\n", float_str(p.x), float_str(p.y), float_str(p.z)));
    }
}

impl RbfParameters {
    /// Read a PyGeM RBF `.prm` file (sections `[Radial Basis Functions]`, `[Control points]`).
    ///
    /// Extra kernel parameters: `k` for `thin_plate_spline` and `polyharmonic_spline`
    /// (an integer, as PyGeM evaluates it); anything else is an error.
    ///
    /// # Errors
    ///
    /// As [`read`] (for example PyGeM's `parameters_rbf_bugged_01.prm`, nine deformed
    /// points for eight original ones, and `_02.prm`, the unknown `gaussian_splines`).
    pub fn from_prm(text: &str) -> Result<RbfParameters> {
        rbf_from_ini(&Ini::parse(text)?)
    }

    /// The `.prm` text for these parameters, in the layout of PyGeM's writer and expected
    /// files (`parameters_rbf_cube_out_true.prm` byte for byte; a `k` other than 2 is
    /// written as in `parameters_rbf_extra.prm`). Unlike PyGeM's writer, which always
    /// writes `gaussian_spline`, the kernel written is the actual one.
    pub fn to_prm(&self) -> String {
        let mut s = String::new();
        s += "\n[Radial Basis Functions]\n";
        s += "# This section describes the radial basis functions shape.\n";
        s += "\n# basis funtion is the name of the basis functions to use in the transformation. The functions\n";
        s += "# implemented so far are: gaussian_spline, multi_quadratic_biharmonic_spline,\n";
        s += "# inv_multi_quadratic_biharmonic_spline, thin_plate_spline, beckert_wendland_c2_basis, polyharmonic_spline.\n";
        s += "# For a comprehensive list with details see the class RBF.\n";
        s += &format!("basis function: {}\n", self.kernel.name());
        s += "\n# radius is the scaling parameter r that affects the shape of the basis functions. See the documentation\n";
        s += "# of the class RBF for details.\n";
        s += &format!("radius: {}\n", float_str(self.kernel.radius()));
        match self.kernel.k() {
            Some(k) if k != crate::rbf::DEFAULT_K => {
                s += "\n# Any additional parameter to pass to the basis function (eg the `k` power for poliharmonic_spline)\n";
                s += &format!("k: {k}\n");
                s += "\n[Control points]\n";
            }
            _ => s += "\n\n\n[Control points]\n",
        }
        s += "# This section describes the RBF control points.\n";
        s += "\n# original control points collects the coordinates of the interpolation control points before the deformation.\n";
        write_points(&mut s, "original control points: ", &self.original, 25);
        s += "\n# deformed control points collects the coordinates of the interpolation control points after the deformation.\n";
        write_points(&mut s, "deformed control points: ", &self.deformed, 25);
        s
    }
}

impl IdwParameters {
    /// Read a PyGeM IDW `.prm` file (sections `[Inverse Distance Weighting]`,
    /// `[Control points]`). The result uses [`IdwVariant::PyGem`], which reproduces what
    /// PyGeM computes from the same file.
    ///
    /// # Errors
    ///
    /// As [`read`].
    pub fn from_prm(text: &str) -> Result<IdwParameters> {
        idw_from_ini(&Ini::parse(text)?)
    }

    /// The `.prm` text PyGeM's `IDW.write_parameters` writes, byte for byte (except that the
    /// first deformed point is the deformed one: PyGeM writes the original one there).
    ///
    /// # Errors
    ///
    /// [`Error::InvalidParameter`] for [`IdwVariant::Paper`]: a `.prm` file always means
    /// PyGeM's variant; use the TOML form ([`crate::Parameters`]) for the paper's.
    pub fn to_prm(&self) -> Result<String> {
        let IdwVariant::PyGem { power } = self.variant else {
            return Err(Error::InvalidParameter {
                line: None,
                name: "IDW variant",
                value: f64::NAN,
                reason: "a .prm file describes PyGeM's IDW; write the paper variant as TOML",
            });
        };
        let mut s = String::new();
        s += "\n[Inverse Distance Weighting]\n";
        s += "# This section describes the settings of idw.\n\n";
        s += "# the power parameter\n";
        s += &format!("power = {power}\n");
        s += "\n\n[Control points]\n";
        s += "# This section describes the IDW control points.\n\n";
        s += "# original control points collects the coordinates\n";
        s += "# of the interpolation control points before the\n";
        s += "# deformation.\n";
        write_points(&mut s, "original control points: ", &self.original, 25);
        s += "\n";
        s += "# deformed control points collects the coordinates\n";
        s += "# of the interpolation control points after the\n";
        s += "# deformation.\n";
        write_points(&mut s, "deformed control points: ", &self.deformed, 25);
        Ok(s)
    }
}
