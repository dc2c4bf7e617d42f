//! The design table: a blade (or propeller) described in TOML, checked field by field.
//!
//! ```toml
//! name = "tutorial blade"
//! unit = "m"                    # length unit of every value and of the written file
//! reflect = true                # BladeX apply_transformations(reflect=True)
//! radii = [1.0, 2.0, 3.0]
//! chord = [2.0, 2.5, 3.0]
//! pitch = [1.0, 2.0, 3.0]
//! rake = [0.1, 0.2, 0.3]
//! skew = [1.0, 3.0, 5.0]        # degrees
//! # thickness = [...]           # optional maximum thickness per section
//! # camber = [...]              # optional maximum camber per section (not the tip)
//! [profile]                     # the profile of every section ...
//! naca = "0012"
//! # [[profiles]]                # ... or one per section
//! # csv = "boeing_707.csv"      # path relative to the table
//! [propeller]                   # optional
//! blades = 4
//! hub_radius = 0.9
//! hub_length = 3.0
//! ```

use std::path::{Path, PathBuf};

use crate::blade::Blade;
use crate::export::LengthUnit;
use crate::naca::{naca, NacaOptions, NacaSpacing};
use crate::prm::{LawParam, ParamFile};
use crate::profile::Profile;
use crate::radial::RadialLaw;
use crate::{Error, Result};

/// One section profile of a table.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(untagged, deny_unknown_fields)]
pub enum ProfileSpec {
    /// A NACA profile.
    Naca {
        /// The 4- or 5-digit code.
        naca: String,
        /// Points per side (240).
        #[serde(default = "default_points")]
        n_points: usize,
        /// `cosine` or `linear` (see [`NacaSpacing`]).
        #[serde(default)]
        spacing: NacaSpacing,
        /// Closed (BladeX) or open trailing edge.
        #[serde(default = "yes")]
        closed_trailing_edge: bool,
    },
    /// A CSV file in the layout of BladeX's `boeing_707.csv`, relative to the table.
    Csv {
        /// The file.
        csv: PathBuf,
    },
    /// Coordinates given inline.
    Coordinates {
        /// Upper x.
        xup: Vec<f64>,
        /// Upper y.
        yup: Vec<f64>,
        /// Lower x.
        xdown: Vec<f64>,
        /// Lower y.
        ydown: Vec<f64>,
    },
}

fn default_points() -> usize {
    240
}
fn yes() -> bool {
    true
}

/// Propeller settings of a table.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropellerSpec {
    /// Number of blades.
    pub blades: usize,
    /// Radius of the cylindrical hub (default: the root radius).
    pub hub_radius: Option<f64>,
    /// Hub length along the axis (default: 3 × the largest chord).
    pub hub_length: Option<f64>,
}

/// Loft settings.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LoftSpec {
    /// Degree along the sections.
    pub u_degree: usize,
    /// Degree across the sections.
    pub v_degree: usize,
}

impl Default for LoftSpec {
    fn default() -> Self {
        Self { u_degree: 3, v_degree: 3 }
    }
}

/// A design table (see the module docs for the TOML form).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DesignTable {
    /// Product name written to the files.
    #[serde(default)]
    pub name: String,
    /// Length unit.
    #[serde(default)]
    pub unit: LengthUnit,
    /// Reflect the sections (BladeX default `true`).
    #[serde(default = "yes")]
    pub reflect: bool,
    /// Section radii, root first.
    pub radii: Vec<f64>,
    /// Chord per section.
    pub chord: Vec<f64>,
    /// Pitch per section.
    pub pitch: Vec<f64>,
    /// Rake per section.
    pub rake: Vec<f64>,
    /// Skew per section, degrees.
    pub skew: Vec<f64>,
    /// Maximum thickness per section.
    #[serde(default)]
    pub thickness: Option<Vec<f64>>,
    /// Maximum camber per section.
    #[serde(default)]
    pub camber: Option<Vec<f64>>,
    /// The profile of every section.
    #[serde(default)]
    pub profile: Option<ProfileSpec>,
    /// One profile per section (instead of `profile`).
    #[serde(default)]
    pub profiles: Option<Vec<ProfileSpec>>,
    /// Loft degrees.
    #[serde(default)]
    pub loft: LoftSpec,
    /// Propeller settings.
    #[serde(default)]
    pub propeller: Option<PropellerSpec>,
    /// Where relative paths are resolved (the table's folder; not part of the TOML).
    #[serde(skip)]
    pub base: PathBuf,
}

impl ProfileSpec {
    /// The profile.
    ///
    /// # Errors
    ///
    /// [`Error::NacaCode`], the CSV's read and parse errors, the coordinate checks.
    pub fn build(&self, base: &Path) -> Result<Profile> {
        match self {
            ProfileSpec::Naca { naca: code, n_points, spacing, closed_trailing_edge } => naca(
                code,
                NacaOptions { n_points: *n_points, spacing: *spacing, closed_trailing_edge: *closed_trailing_edge },
            ),
            ProfileSpec::Csv { csv } => {
                let path = base.join(csv);
                let text = std::fs::read_to_string(&path)
                    .map_err(|e| Error::Io { path: path.display().to_string(), source: e })?;
                Profile::from_csv(&text)
            }
            ProfileSpec::Coordinates { xup, yup, xdown, ydown } => {
                Profile::try_new(xup.clone(), yup.clone(), xdown.clone(), ydown.clone())
            }
        }
    }
}

impl DesignTable {
    /// Parses a table; `base` is the folder relative paths start from.
    ///
    /// # Errors
    ///
    /// [`Error::Toml`] with TOML's line and column, then the checks of [`blade`](Self::blade).
    pub fn parse(text: &str, base: &Path) -> Result<Self> {
        let mut t: DesignTable = toml::from_str(text).map_err(|e| Error::Toml(e.to_string()))?;
        t.base = base.to_path_buf();
        t.blade()?;
        Ok(t)
    }

    /// Reads a table file.
    ///
    /// # Errors
    ///
    /// [`Error::Io`], then as [`parse`](Self::parse).
    pub fn read(path: &Path) -> Result<Self> {
        let text =
            std::fs::read_to_string(path).map_err(|e| Error::Io { path: path.display().to_string(), source: e })?;
        Self::parse(&text, path.parent().unwrap_or(Path::new("."))).map_err(|e| {
            if let Error::Toml(m) = e {
                Error::Toml(format!("{}: {m}", path.display()))
            } else {
                e
            }
        })
    }

    /// The TOML text of the table.
    ///
    /// # Errors
    ///
    /// [`Error::Toml`] (not expected for a table that was read).
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::Toml(e.to_string()))
    }

    /// The blade of the table, checked.
    ///
    /// # Errors
    ///
    /// [`Error::Table`] naming the field and section: `profiles` of the wrong length, an
    /// unknown NACA code (field `profiles`/`profile`, with the section), and those of
    /// [`Blade::check`].
    pub fn blade(&self) -> Result<Blade> {
        let n = self.radii.len();
        let sections: Vec<Profile> = match (&self.profile, &self.profiles) {
            (Some(_), Some(_)) => return Err(Error::table("profiles", None, "give `profile` or `profiles`, not both")),
            (None, Some(list)) => {
                if list.len() != n {
                    return Err(Error::table("profiles", None, format!("{} profiles for {n} sections", list.len())));
                }
                list.iter()
                    .enumerate()
                    .map(|(i, s)| s.build(&self.base).map_err(|e| Error::table("profiles", Some(i), e.to_string())))
                    .collect::<Result<_>>()?
            }
            (p, None) => {
                let spec = p.clone().unwrap_or(ProfileSpec::Naca {
                    naca: "0012".into(),
                    n_points: 240,
                    spacing: NacaSpacing::Cosine,
                    closed_trailing_edge: true,
                });
                let prof = spec.build(&self.base).map_err(|e| Error::table("profile", None, e.to_string()))?;
                cadmorph_morph::budget::check("sections × profile points", &[n, prof.xup.len(), 4], 8)
                    .map_err(|e| Error::table("radii", None, e.to_string()))?;
                vec![prof; n]
            }
        };
        let b = Blade {
            sections,
            radii: self.radii.clone(),
            chord: self.chord.clone(),
            pitch: self.pitch.clone(),
            rake: self.rake.clone(),
            skew: self.skew.clone(),
            thickness: self.thickness.clone(),
            camber: self.camber.clone(),
        };
        b.check()?;
        if let Some(p) = &self.propeller {
            if p.blades == 0 {
                return Err(Error::table("propeller.blades", None, "at least one blade"));
            }
            if let Some(h) = p.hub_radius {
                if !(h > 0.0 && h <= b.radii[0]) {
                    return Err(Error::table(
                        "propeller.hub_radius",
                        None,
                        format!("{h} must be in (0, root radius {}]", b.radii[0]),
                    ));
                }
            }
        }
        Ok(b)
    }

    /// Deforms the table's radial distributions with the B-spline settings and
    /// control-point deformations of a BladeX parameter file (the paper's radial laws,
    /// §3.1.2): for every law with a non-zero deformation, a B-spline of the file's degree
    /// and number of control points is fitted to the table's own distribution (BladeX
    /// `_optimum_control_points`, with `rbf_points` RBF samples), its control points are
    /// moved, and the law is evaluated exactly at the table's radii. The file's
    /// `[Original parameters]` are not used (they describe BladeX's blade, often
    /// normalised). A camber law needs a `camber` row in the table.
    ///
    /// # Errors
    ///
    /// [`Error::RadialLaw`] for a law that cannot be fitted, [`Error::Table`] for a
    /// camber law without camber, and the table checks on the result.
    pub fn deform(&mut self, prm: &ParamFile, rbf_points: usize) -> Result<()> {
        for p in LawParam::ALL {
            let s = &prm.settings[p.index()];
            if s.deformations.iter().all(|d| *d == 0.0) {
                continue;
            }
            let radii = self.radii.clone();
            let values: &mut Vec<f64> = match p {
                LawParam::Chord => &mut self.chord,
                LawParam::Pitch => &mut self.pitch,
                LawParam::Rake => &mut self.rake,
                LawParam::Skew => &mut self.skew,
                LawParam::Camber => match &mut self.camber {
                    Some(c) => c,
                    None => {
                        return Err(Error::table(
                            "camber",
                            None,
                            "the parameter file deforms camber; the table has none",
                        ))
                    }
                },
            };
            let mut law = RadialLaw::fit(p, &radii, values, s.degree, s.nbasis, rbf_points)?;
            law.deform(&s.deformations)?;
            for (v, r) in values.iter_mut().zip(&radii) {
                *v = law.value_at(*r)?;
            }
        }
        self.blade()?;
        Ok(())
    }
}
