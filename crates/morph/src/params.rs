//! The parameters of any of the three morphs, and their TOML form (serde).
//!
//! ```toml
//! [ffd]
//! n_control_points = [2, 2, 2]
//! box_origin = [0.0, 0.0, 0.0]
//! box_length = [1.0, 1.0, 1.0]
//! rot_angle = [0.0, 0.0, 0.0]      # degrees, R = Rx·Ry·Rz; optional
//! mu_x = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1]   # L·M·N values, C order (i, j, k); optional
//! mu_y = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
//! mu_z = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
//! ```
//!
//! ```toml
//! [rbf]
//! kernel = "thin_plate_spline"     # any name of rbf::Kernel::NAMES
//! radius = 0.5
//! k = 2                            # thin_plate_spline and polyharmonic_spline only; optional
//! original_control_points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
//! deformed_control_points = [[0.0, 0.0, 0.1], [1.0, 0.0, 0.0]]
//! ```
//!
//! ```toml
//! [idw]
//! variant = "paper"                # or "pygem" (Minkowski distance, weight 1/d)
//! power = 2.0
//! cutoff = 0.5                     # paper variant only; optional
//! original_control_points = [[0.0, 0.0, 0.0]]
//! deformed_control_points = [[0.0, 0.0, 0.1]]
//! ```

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

use crate::idw::{IdwParameters, IdwVariant};
use crate::rbf::{Kernel, RbfParameters};
use crate::{Deformation, Displacements, Error, Ffd, Idw, Rbf, Result};

/// The parameters of an FFD, an RBF or an IDW, as read from a PyGeM `.prm` file
/// ([`crate::prm::read`]) or from TOML ([`Parameters::from_toml`]).
///
/// # Examples
///
/// ```
/// use cadmorph_morph::{Deformation, Parameters};
/// use cadmorph_morph::math::Point3;
/// let text = r#"
/// [idw]
/// variant = "paper"
/// power = 2.0
/// original_control_points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
/// deformed_control_points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.5]]
/// "#;
/// let params = Parameters::from_toml(text)?;
/// assert_eq!(Parameters::from_toml(&params.to_toml())?, params);
/// let morph = params.build()?;
/// assert_eq!(morph.deform_point(&Point3::new(1.0, 0.0, 0.0)), Point3::new(1.0, 0.0, 0.5));
/// # Ok::<(), cadmorph_morph::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
#[allow(clippy::large_enum_variant)] // built once per file; boxing would only cost an indirection
pub enum Parameters {
    /// Free-form deformation.
    Ffd(Ffd),
    /// Radial basis functions.
    Rbf(RbfParameters),
    /// Inverse distance weighting.
    Idw(IdwParameters),
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Doc {
    #[serde(skip_serializing_if = "Option::is_none")]
    ffd: Option<FfdToml>,
    #[serde(skip_serializing_if = "Option::is_none")]
    rbf: Option<RbfToml>,
    #[serde(skip_serializing_if = "Option::is_none")]
    idw: Option<IdwToml>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FfdToml {
    #[serde(deserialize_with = "exact::three")]
    n_control_points: [usize; 3],
    #[serde(deserialize_with = "exact::three")]
    box_origin: [f64; 3],
    #[serde(deserialize_with = "exact::three")]
    box_length: [f64; 3],
    #[serde(default, deserialize_with = "exact::three")]
    rot_angle: [f64; 3],
    #[serde(default)]
    mu_x: Vec<f64>,
    #[serde(default)]
    mu_y: Vec<f64>,
    #[serde(default)]
    mu_z: Vec<f64>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RbfToml {
    kernel: String,
    radius: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    k: Option<u32>,
    #[serde(deserialize_with = "exact::points")]
    original_control_points: Vec<[f64; 3]>,
    #[serde(deserialize_with = "exact::points")]
    deformed_control_points: Vec<[f64; 3]>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct IdwToml {
    variant: String,
    power: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cutoff: Option<f64>,
    #[serde(deserialize_with = "exact::points")]
    original_control_points: Vec<[f64; 3]>,
    #[serde(deserialize_with = "exact::points")]
    deformed_control_points: Vec<[f64; 3]>,
}

/// Arrays of exactly three values. serde's `[T; 3]` takes the first three of a longer
/// array and drops the rest without a word (`box_length = [4, 20, 600, 0, 0.2]` read as
/// `[4, 20, 600]`): these read a list and refuse any other length, at the value's line.
mod exact {
    use serde::de::{Deserialize, Deserializer, Error};

    pub fn three<'de, D: Deserializer<'de>, T: Deserialize<'de> + Copy>(d: D) -> Result<[T; 3], D::Error> {
        let v = Vec::<T>::deserialize(d)?;
        <[T; 3]>::try_from(v.as_slice()).map_err(|_| D::Error::invalid_length(v.len(), &"exactly three values"))
    }

    pub fn points<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 3]>, D::Error> {
        let v = Vec::<Vec<f64>>::deserialize(d)?;
        v.iter()
            .enumerate()
            .map(|(i, p)| {
                <[f64; 3]>::try_from(p.as_slice()).map_err(|_| {
                    D::Error::custom(format!("point {i} has {} coordinates, expected 3 (x, y, z)", p.len()))
                })
            })
            .collect()
    }
}

/// Where the keys of a parsed TOML document are, for errors found after parsing: the
/// 1-based line of `key`'s value in the document's one table, or of the table header
/// when the key is absent, or 0. The spans come from `toml_edit`, so dotted keys, inline
/// tables and keys that are prefixes of others (`k` and `kernel`) are found where they are.
struct Lines<'a> {
    text: &'a str,
    doc: Option<toml_edit::ImDocument<&'a str>>,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str) -> Self {
        Lines { text, doc: toml_edit::ImDocument::parse(text).ok() }
    }

    fn of(&self, key: &str) -> usize {
        let Some(doc) = &self.doc else { return 0 };
        let line = |offset: usize| self.text[..offset.min(self.text.len())].matches('\n').count() + 1;
        for (_, item) in doc.iter() {
            let Some(table) = item.as_table_like() else { continue };
            if let Some(span) = table.get(key).and_then(|v| v.span()) {
                return line(span.start);
            }
            if let Some(span) = item.span() {
                return line(span.start);
            }
        }
        0
    }
}

/// Attach the line of `key` to an error that was raised without one.
fn at_line(e: Error, line: usize) -> Error {
    match e {
        Error::CountMismatch { line: 0, what, expected, found } => Error::CountMismatch { line, what, expected, found },
        Error::InvalidParameter { line: None, name, value, reason } => {
            Error::InvalidParameter { line: Some(line), name, value, reason }
        }
        Error::LatticeTooLarge { line: None, shape, axis, limit } => {
            Error::LatticeTooLarge { line: Some(line), shape, axis, limit }
        }
        other => other,
    }
}

/// The bytes as UTF-8 text, or [`Error::Encoding`] naming the first bad byte.
///
/// # Errors
///
/// [`Error::Encoding`].
pub fn utf8(bytes: &[u8]) -> Result<&str> {
    std::str::from_utf8(bytes).map_err(|e| {
        let offset = e.valid_up_to();
        let line = bytes[..offset].iter().filter(|&&b| b == b'\n').count() + 1;
        Error::Encoding { offset, line }
    })
}

fn points(v: &[[f64; 3]]) -> Vec<Point3<f64>> {
    v.iter().map(|p| Point3::from(*p)).collect()
}

fn arrays(v: &[Point3<f64>]) -> Vec<[f64; 3]> {
    v.iter().map(|p| [p.x, p.y, p.z]).collect()
}

impl Parameters {
    /// Read the TOML form (one of the tables `[ffd]`, `[rbf]`, `[idw]`).
    ///
    /// # Errors
    ///
    /// [`Error::Toml`] with line and column for syntax errors, unknown keys and wrong types;
    /// the checks of the morphs' constructors ([`Error::CountMismatch`],
    /// [`Error::InvalidParameter`], [`Error::UnknownKernel`]) with the line of the key.
    pub fn from_toml(text: &str) -> Result<Parameters> {
        let lines = Lines::new(text);
        let line_of = |_: &str, key: &str| lines.of(key);
        let doc: Doc = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map_or((0, 0), |s| {
                let before = &text[..s.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                (line, column)
            });
            Error::Toml { line, column, message: e.message().to_string() }
        })?;
        let count = doc.ffd.is_some() as usize + doc.rbf.is_some() as usize + doc.idw.is_some() as usize;
        if count != 1 {
            return Err(Error::Toml {
                line: 0,
                column: 0,
                message: format!("expected exactly one of the tables [ffd], [rbf], [idw], found {count}"),
            });
        }
        if let Some(f) = doc.ffd {
            let mut ffd = Ffd::try_new(
                f.n_control_points,
                Point3::from(f.box_origin),
                Vector3::from(f.box_length),
                Vector3::from(f.rot_angle),
            )
            .map_err(|e| match e {
                e @ Error::LatticeTooLarge { .. } => at_line(e, line_of(text, "n_control_points")),
                e => at_line(e, line_of(text, "n_control_points").max(line_of(text, "box_length"))),
            })?;
            let n = f.n_control_points.iter().product::<usize>();
            let fill = |v: Vec<f64>| if v.is_empty() { vec![0.0; n] } else { v };
            for (key, v) in [("mu_x", &f.mu_x), ("mu_y", &f.mu_y), ("mu_z", &f.mu_z)] {
                if !v.is_empty() && v.len() != n {
                    return Err(Error::CountMismatch {
                        line: line_of(text, key),
                        what: "mu values (L·M·N)",
                        expected: n,
                        found: v.len(),
                    });
                }
                if let Some(&bad) = v.iter().find(|x| !x.is_finite()) {
                    return Err(Error::InvalidParameter {
                        line: Some(line_of(text, key)),
                        name: "mu",
                        value: bad,
                        reason: "must be finite",
                    });
                }
            }
            let mu = Displacements::try_from_arrays(f.n_control_points, fill(f.mu_x), fill(f.mu_y), fill(f.mu_z))?;
            ffd.set_mu(mu)?;
            return Ok(Parameters::Ffd(ffd));
        }
        let check_counts = |orig: &[[f64; 3]], def: &[[f64; 3]]| -> Result<()> {
            if orig.len() != def.len() {
                return Err(Error::CountMismatch {
                    line: line_of(text, "deformed_control_points"),
                    what: "deformed control points (one per original control point)",
                    expected: orig.len(),
                    found: def.len(),
                });
            }
            Ok(())
        };
        if let Some(r) = doc.rbf {
            check_counts(&r.original_control_points, &r.deformed_control_points)?;
            let uses_k = matches!(r.kernel.as_str(), "thin_plate_spline" | "polyharmonic_spline");
            if r.k.is_some() && !uses_k {
                return Err(Error::UnknownParameter { line: line_of(text, "k"), name: "k".into(), context: r.kernel });
            }
            let kernel = Kernel::from_name(&r.kernel, r.radius, r.k)
                .ok_or_else(|| Error::UnknownKernel { line: line_of(text, "kernel"), name: r.kernel.clone() })?;
            kernel.validate().map_err(|e| at_line(e, line_of(text, "radius")))?;
            return Ok(Parameters::Rbf(RbfParameters {
                kernel,
                original: points(&r.original_control_points),
                deformed: points(&r.deformed_control_points),
            }));
        }
        let i = doc.idw.expect("exactly one table is present");
        check_counts(&i.original_control_points, &i.deformed_control_points)?;
        let variant = match i.variant.as_str() {
            "paper" => IdwVariant::Paper { power: i.power, cutoff: i.cutoff },
            "pygem" => {
                if i.cutoff.is_some() {
                    return Err(Error::UnknownParameter {
                        line: line_of(text, "cutoff"),
                        name: "cutoff".into(),
                        context: "the pygem IDW variant".into(),
                    });
                }
                if !(i.power >= 1.0 && i.power <= 64.0 && i.power.fract() == 0.0) {
                    return Err(Error::InvalidParameter {
                        line: Some(line_of(text, "power")),
                        name: "power",
                        value: i.power,
                        reason: "the pygem variant needs an integer power in 1..=64",
                    });
                }
                IdwVariant::PyGem { power: i.power as u32 }
            }
            other => {
                return Err(Error::Syntax {
                    line: line_of(text, "variant"),
                    expected: "variant \"paper\" or \"pygem\"",
                    found: other.to_string(),
                });
            }
        };
        let params = IdwParameters {
            variant,
            original: points(&i.original_control_points),
            deformed: points(&i.deformed_control_points),
        };
        // Validate now (power, cutoff, finiteness) so that a bad file fails where it is read.
        Idw::from_parameters(&params).map_err(|e| at_line(e, line_of(text, "power")))?;
        Ok(Parameters::Idw(params))
    }

    /// The TOML form; [`Parameters::from_toml`] reads it back to equal parameters.
    pub fn to_toml(&self) -> String {
        let doc = match self {
            Parameters::Ffd(f) => Doc {
                ffd: Some(FfdToml {
                    n_control_points: f.n_control_points(),
                    box_origin: f.box_origin().coords.into(),
                    box_length: f.box_length().into(),
                    rot_angle: f.rot_angle().into(),
                    mu_x: f.mu().x.clone(),
                    mu_y: f.mu().y.clone(),
                    mu_z: f.mu().z.clone(),
                }),
                rbf: None,
                idw: None,
            },
            Parameters::Rbf(r) => Doc {
                ffd: None,
                rbf: Some(RbfToml {
                    kernel: r.kernel.name().to_string(),
                    radius: r.kernel.radius(),
                    k: r.kernel.k(),
                    original_control_points: arrays(&r.original),
                    deformed_control_points: arrays(&r.deformed),
                }),
                idw: None,
            },
            Parameters::Idw(i) => {
                let (variant, power, cutoff) = match i.variant {
                    IdwVariant::Paper { power, cutoff } => ("paper", power, cutoff),
                    IdwVariant::PyGem { power } => ("pygem", power as f64, None),
                };
                Doc {
                    ffd: None,
                    rbf: None,
                    idw: Some(IdwToml {
                        variant: variant.into(),
                        power,
                        cutoff,
                        original_control_points: arrays(&i.original),
                        deformed_control_points: arrays(&i.deformed),
                    }),
                }
            }
        };
        toml::to_string(&doc).expect("plain numbers and strings always serialise")
    }

    /// Read a parameter file's bytes: `toml` picks the TOML form, otherwise PyGeM's `.prm`.
    ///
    /// # Errors
    ///
    /// [`Error::Encoding`] with the byte offset and line of the first byte that is not
    /// UTF-8; otherwise as [`Parameters::from_toml`] or [`crate::prm::read`].
    pub fn from_bytes(bytes: &[u8], toml: bool) -> Result<Parameters> {
        let text = utf8(bytes)?;
        if toml {
            Parameters::from_toml(text)
        } else {
            crate::prm::read(text)
        }
    }

    /// Read a PyGeM `.prm` file (see [`crate::prm::read`]).
    ///
    /// # Errors
    ///
    /// As [`crate::prm::read`].
    pub fn from_prm(text: &str) -> Result<Parameters> {
        crate::prm::read(text)
    }

    /// The PyGeM `.prm` text.
    ///
    /// # Errors
    ///
    /// As [`IdwParameters::to_prm`] (the paper's IDW has no `.prm` form).
    pub fn to_prm(&self) -> Result<String> {
        match self {
            Parameters::Ffd(f) => Ok(f.to_prm()),
            Parameters::Rbf(r) => Ok(r.to_prm()),
            Parameters::Idw(i) => i.to_prm(),
        }
    }

    /// Build the deformation (solving the RBF system, building the IDW tree).
    ///
    /// # Errors
    ///
    /// As [`Rbf::try_new`] and [`Idw::try_new`].
    pub fn build(&self) -> Result<Box<dyn Deformation + Send>> {
        Ok(match self {
            Parameters::Ffd(f) => Box::new(f.clone()),
            Parameters::Rbf(r) => Box::new(Rbf::from_parameters(r)?),
            Parameters::Idw(i) => Box::new(Idw::from_parameters(i)?),
        })
    }
}
