//! The design space: `campaign.toml` (issue 16, Deliver 1; the paper's campaigns of §3.1.2).
//!
//! ```toml
//! [campaign]
//! output = "bow_dome.out"          # the campaign folder, relative to this file (default: <stem>.out)
//!
//! [base]
//! geometry = "hull3.igs"           # IGES or STEP, relative to this file
//!
//! [deformation]
//! ffd = "prm/bow_dome.prm"         # exactly one of ffd, rbf, idw: PyGeM .prm or cadmorph TOML
//!
//! [settings]
//! refine_tol = 1.45e-5             # seam gap kept after the morph (model units); optional
//! angle_tol = 0.01                 # with refine_tol: largest normal angle across a seam, degrees
//! formats = ["igs"]                # outputs of every variant: "igs", "stp" (default: the base's)
//!
//! [sampling]
//! method = "lhs"                   # full_factorial, one_at_a_time, random, lhs, sobol
//! n = 130                          # random, lhs, sobol
//! seed = 5415
//! criterion = "maximin"            # lhs: none, maximin, correlation (default none)
//! candidates = 20                  # lhs with a criterion: designs drawn to pick from
//! levels = 3                       # full_factorial, one_at_a_time: levels of each range
//! scramble = true                  # sobol: Owen scrambling (default true)
//!
//! [[parameter]]
//! name = "dome_width"
//! entry = "mu_y[1,1,1]"            # FFD mu_x/mu_y/mu_z[i,j,k]; RBF/IDW d_x/d_y/d_z[n]
//! range = [0.0, 0.08]              # or set = [0.0, 0.02, 0.05]
//! ```
//!
//! A parameter's value replaces its entry in the deformation file; entries no parameter
//! names keep the file's values. Every error names the line and the field.

use std::path::{Path, PathBuf};

use cadmorph::morph::Parameters;
use cadmorph::Format;
use serde::Deserialize;
use sha2::{Digest, Sha256};
use toml::Spanned;

use crate::entry::Entry;
use crate::error::{io, Error, Result};
use crate::sampler::{Criterion, Method};

/// The values a parameter takes.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Every value in `[lo, hi]`, `lo < hi`.
    Range {
        /// Lower end.
        lo: f64,
        /// Upper end.
        hi: f64,
    },
    /// One of these values (distinct, at least one).
    Set(Vec<f64>),
}

impl Values {
    /// The value at `u ∈ [0, 1]`: `lo + u (hi − lo)` for a range, the `⌊u·n⌋`-th value
    /// (the last for `u = 1`) for a set of `n`.
    pub fn at(&self, u: f64) -> f64 {
        match self {
            Values::Range { lo, hi } => lo + u * (hi - lo),
            Values::Set(v) => v[((u * v.len() as f64) as usize).min(v.len() - 1)],
        }
    }

    /// `levels` evenly spaced values of a range (ends included; the midpoint for 1), or
    /// every value of a set.
    pub fn levels(&self, levels: usize) -> Vec<f64> {
        match self {
            Values::Range { lo, hi } if levels == 1 => vec![0.5 * (lo + hi)],
            Values::Range { lo, hi } => (0..levels).map(|i| lo + (hi - lo) * i as f64 / (levels - 1) as f64).collect(),
            Values::Set(v) => v.clone(),
        }
    }

    /// The smallest and largest value.
    pub fn bounds(&self) -> (f64, f64) {
        match self {
            Values::Range { lo, hi } => (*lo, *hi),
            Values::Set(v) => v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x))),
        }
    }

    /// The base value of one-at-a-time designs: the midpoint of a range, the first value
    /// of a set.
    pub fn base(&self) -> f64 {
        match self {
            Values::Range { lo, hi } => 0.5 * (lo + hi),
            Values::Set(v) => v[0],
        }
    }
}

/// A named campaign parameter bound to one entry of the deformation.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Its name (a CSV column).
    pub name: String,
    /// The entry it sets.
    pub entry: Entry,
    /// Its index in the deformation's parameter vector θ.
    pub theta: usize,
    /// The values it takes.
    pub values: Values,
}

/// Fixed settings of every variant.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Seam-keeping refinement tolerance (model units), if any.
    pub refine_tol: Option<f64>,
    /// Normal angle tolerance of the refinement, degrees.
    pub angle_tol: f64,
    /// Output formats of every variant.
    pub formats: Vec<Format>,
}

/// A parsed, checked `campaign.toml`.
#[derive(Debug, Clone)]
pub struct DesignSpace {
    /// The campaign file.
    pub path: PathBuf,
    /// The base geometry.
    pub geometry: PathBuf,
    /// The deformation file.
    pub deformation_path: PathBuf,
    /// The deformation as the file gives it (the base of every variant).
    pub deformation: Parameters,
    /// The parameters, in file order.
    pub parameters: Vec<Parameter>,
    /// The sampling plan.
    pub method: Method,
    /// The seed of every random choice.
    pub seed: u64,
    /// Fixed settings.
    pub settings: Settings,
    /// The campaign folder.
    pub output: PathBuf,
    /// SHA-256 of the inputs: base geometry bytes, deformation bytes, parameters,
    /// settings and sampling (hex).
    pub hash: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    #[serde(default)]
    campaign: Option<RawCampaign>,
    base: Option<Spanned<RawBase>>,
    deformation: Option<Spanned<RawDeformation>>,
    #[serde(default)]
    settings: Option<RawSettings>,
    sampling: Option<Spanned<RawSampling>>,
    #[serde(default)]
    parameter: Vec<Spanned<RawParameter>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCampaign {
    output: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBase {
    geometry: Spanned<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDeformation {
    ffd: Option<Spanned<String>>,
    rbf: Option<Spanned<String>>,
    idw: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSettings {
    refine_tol: Option<Spanned<f64>>,
    angle_tol: Option<Spanned<f64>>,
    formats: Option<Spanned<Vec<String>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSampling {
    method: Spanned<String>,
    n: Option<Spanned<i64>>,
    seed: Option<Spanned<i64>>,
    criterion: Option<Spanned<String>>,
    candidates: Option<Spanned<i64>>,
    levels: Option<Spanned<i64>>,
    scramble: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawParameter {
    name: Spanned<String>,
    entry: Spanned<String>,
    range: Option<Spanned<Vec<f64>>>,
    set: Option<Spanned<Vec<f64>>>,
}

/// 1-based line of byte offset `at` in `text`.
fn line_at(text: &str, at: usize) -> usize {
    text[..at.min(text.len())].matches('\n').count() + 1
}

struct Ctx<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Ctx<'_> {
    fn err<T>(&self, span: std::ops::Range<usize>, field: impl Into<String>, message: impl Into<String>) -> Result<T> {
        Err(self.error(span, field, message))
    }
    fn error(&self, span: std::ops::Range<usize>, field: impl Into<String>, message: impl Into<String>) -> Error {
        let line = if span == (0..0) { 0 } else { line_at(self.text, span.start) };
        Error::Field { path: self.path.to_owned(), line, field: field.into(), message: message.into() }
    }
    fn resolve(&self, p: &str) -> PathBuf {
        let dir = self.path.parent().unwrap_or(Path::new("."));
        dir.join(p)
    }
    fn count(&self, v: &Option<Spanned<i64>>, field: &str, min: i64, default: Option<i64>) -> Result<usize> {
        match v {
            Some(s) if *s.get_ref() < min => {
                self.err(s.span(), field, format!("expected an integer ≥ {min}, found {}", s.get_ref()))
            }
            Some(s) => Ok(*s.get_ref() as usize),
            None => default
                .map(|d| d as usize)
                .ok_or_else(|| self.error(0..0, field, format!("missing: this sampling method needs `{field}`"))),
        }
    }
}

fn sha_hex(bytes: &[u8]) -> String {
    let d = Sha256::digest(bytes);
    d.iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 of `bytes`, lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    sha_hex(bytes)
}

impl DesignSpace {
    /// Reads and checks the campaign file at `path`, with the base geometry's and the
    /// deformation's files (not yet the geometry itself).
    ///
    /// # Errors
    ///
    /// [`Error::Field`] with the line and field for a syntax error, an unknown or missing
    /// field, a parameter bound to an entry the deformation does not have, an empty or
    /// reversed range, an empty set, a bad method or count; [`Error::Io`];
    /// [`Error::Morph`] for a deformation file that does not read.
    pub fn read(path: &Path) -> Result<DesignSpace> {
        let text = std::fs::read_to_string(path).map_err(io(path))?;
        Self::parse(path, &text)
    }

    /// [`read`](Self::read) with the file's text given.
    ///
    /// # Errors
    ///
    /// As [`read`](Self::read).
    pub fn parse(path: &Path, text: &str) -> Result<DesignSpace> {
        let cx = Ctx { path, text };
        let raw: Raw = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            let field = e.message().split('`').nth(1).unwrap_or("(syntax)").to_string();
            cx.error(span, field, e.message().trim().to_string())
        })?;
        let base = raw.base.ok_or_else(|| cx.error(0..0, "base.geometry", "missing table [base]"))?;
        let geometry = cx.resolve(base.get_ref().geometry.get_ref());
        let geometry_bytes = std::fs::read(&geometry).map_err(|e| {
            cx.error(base.get_ref().geometry.span(), "base.geometry", format!("{}: {e}", geometry.display()))
        })?;
        let def = raw.deformation.ok_or_else(|| cx.error(0..0, "deformation", "missing table [deformation]"))?;
        let def_span = def.span();
        let def = def.into_inner();
        let given: Vec<(&str, Spanned<String>)> = [("ffd", def.ffd), ("rbf", def.rbf), ("idw", def.idw)]
            .into_iter()
            .filter_map(|(k, v)| v.map(|v| (k, v)))
            .collect();
        if given.len() != 1 {
            return cx.err(
                def_span,
                "deformation",
                format!("expected exactly one of ffd, rbf, idw, found {}", given.len()),
            );
        }
        let (kind, file) = &given[0];
        let deformation_path = cx.resolve(file.get_ref());
        let def_text = std::fs::read_to_string(&deformation_path).map_err(|e| {
            cx.error(file.span(), format!("deformation.{kind}"), format!("{}: {e}", deformation_path.display()))
        })?;
        let is_toml = deformation_path.extension().is_some_and(|e| e == "toml");
        let deformation = if is_toml { Parameters::from_toml(&def_text) } else { Parameters::from_prm(&def_text) }
            .map_err(|error| Error::Morph { context: format!("reading {}", deformation_path.display()), error })?;
        let found = match deformation {
            Parameters::Ffd(_) => "ffd",
            Parameters::Rbf(_) => "rbf",
            Parameters::Idw(_) => "idw",
        };
        if found != *kind {
            return cx.err(file.span(), format!("deformation.{kind}"), format!("the file holds {found} parameters"));
        }

        let s = raw.settings.unwrap_or(RawSettings { refine_tol: None, angle_tol: None, formats: None });
        let refine_tol = match s.refine_tol {
            Some(t) if !(*t.get_ref() > 0.0 && t.get_ref().is_finite()) => {
                return cx.err(
                    t.span(),
                    "settings.refine_tol",
                    format!("expected a positive tolerance, found {}", t.get_ref()),
                )
            }
            t => t.map(|t| *t.get_ref()),
        };
        let angle_tol = match s.angle_tol {
            Some(t) if !(*t.get_ref() > 0.0 && t.get_ref().is_finite()) => {
                return cx.err(
                    t.span(),
                    "settings.angle_tol",
                    format!("expected a positive angle, found {}", t.get_ref()),
                )
            }
            t => t.map_or(0.01, |t| *t.get_ref()),
        };
        let base_format = cadmorph::sniff(&geometry_bytes).ok_or_else(|| {
            cx.error(
                base.get_ref().geometry.span(),
                "base.geometry",
                format!("{} is not an IGES or STEP file", geometry.display()),
            )
        })?;
        let formats = match s.formats {
            None => vec![base_format],
            Some(f) => {
                let mut out = Vec::new();
                for name in f.get_ref() {
                    let fmt = Format::from_extension(Path::new(&format!("x.{name}"))).ok_or_else(|| {
                        cx.error(f.span(), "settings.formats", format!("expected \"igs\" or \"stp\", found {name:?}"))
                    })?;
                    if !out.contains(&fmt) {
                        out.push(fmt);
                    }
                }
                if out.is_empty() {
                    return cx.err(f.span(), "settings.formats", "expected at least one format");
                }
                out
            }
        };

        let mut parameters: Vec<Parameter> = Vec::new();
        if raw.parameter.is_empty() {
            return cx.err(0..0, "parameter", "expected at least one [[parameter]]");
        }
        for (n, p) in raw.parameter.iter().enumerate() {
            let field = |f: &str| format!("parameter[{n}].{f}");
            let r = p.get_ref();
            let name = r.name.get_ref().trim().to_string();
            if name.is_empty() || name.contains([',', '"', '\n']) {
                return cx.err(
                    r.name.span(),
                    field("name"),
                    format!("expected a name without commas or quotes, found {name:?}"),
                );
            }
            if parameters.iter().any(|q| q.name == name) {
                return cx.err(r.name.span(), field("name"), format!("a second parameter named {name:?}"));
            }
            let entry = Entry::parse(r.entry.get_ref()).map_err(|m| cx.error(r.entry.span(), field("entry"), m))?;
            let theta = entry.theta_index(&deformation).map_err(|m| cx.error(r.entry.span(), field("entry"), m))?;
            if let Some(q) = parameters.iter().find(|q| q.theta == theta) {
                return cx.err(r.entry.span(), field("entry"), format!("{entry} is already bound to {:?}", q.name));
            }
            let values = match (&r.range, &r.set) {
                (Some(range), None) => match range.get_ref()[..] {
                    [lo, hi] if lo.is_finite() && hi.is_finite() && lo < hi => Values::Range { lo, hi },
                    [lo, hi] if lo.is_finite() && hi.is_finite() => {
                        return cx.err(
                            range.span(),
                            field("range"),
                            format!("empty range [{lo}, {hi}]: expected lo < hi"),
                        )
                    }
                    _ => {
                        return cx.err(
                            range.span(),
                            field("range"),
                            "expected [lo, hi], two finite numbers with lo < hi",
                        )
                    }
                },
                (None, Some(set)) => {
                    let v = set.get_ref();
                    if v.is_empty() {
                        return cx.err(set.span(), field("set"), "empty set: expected at least one value");
                    }
                    if v.iter().any(|x| !x.is_finite()) {
                        return cx.err(set.span(), field("set"), "expected finite values");
                    }
                    if (1..v.len()).any(|i| v[..i].contains(&v[i])) {
                        return cx.err(set.span(), field("set"), "a value appears twice");
                    }
                    Values::Set(v.clone())
                }
                _ => {
                    return cx.err(
                        p.span(),
                        field("range"),
                        "expected exactly one of `range = [lo, hi]` and `set = [...]`",
                    )
                }
            };
            parameters.push(Parameter { name, entry, theta, values });
        }

        let sampling = raw.sampling.ok_or_else(|| cx.error(0..0, "sampling.method", "missing table [sampling]"))?;
        let sp = sampling.get_ref();
        let seed = match &sp.seed {
            Some(s) if *s.get_ref() < 0 => return cx.err(s.span(), "sampling.seed", "expected a non-negative integer"),
            Some(s) => *s.get_ref() as u64,
            None => 0,
        };
        let method = match sp.method.get_ref().as_str() {
            "full_factorial" => Method::FullFactorial { levels: cx.count(&sp.levels, "sampling.levels", 1, Some(2))? },
            "one_at_a_time" => Method::OneAtATime { levels: cx.count(&sp.levels, "sampling.levels", 2, Some(3))? },
            "random" => Method::Random { n: cx.count(&sp.n, "sampling.n", 1, None)? },
            "lhs" => {
                let criterion = match sp.criterion.as_ref().map(|c| (c.get_ref().as_str(), c.span())) {
                    None | Some(("none", _)) => Criterion::None,
                    Some(("maximin", _)) => Criterion::Maximin,
                    Some(("correlation", _)) => Criterion::Correlation,
                    Some((other, span)) => {
                        return cx.err(
                            span,
                            "sampling.criterion",
                            format!("expected none, maximin or correlation, found {other:?}"),
                        )
                    }
                };
                Method::Lhs {
                    n: cx.count(&sp.n, "sampling.n", 1, None)?,
                    criterion,
                    candidates: cx.count(&sp.candidates, "sampling.candidates", 1, Some(20))?,
                }
            }
            "sobol" => {
                Method::Sobol { n: cx.count(&sp.n, "sampling.n", 1, None)?, scramble: sp.scramble.unwrap_or(true) }
            }
            other => {
                return cx.err(
                    sp.method.span(),
                    "sampling.method",
                    format!("expected full_factorial, one_at_a_time, random, lhs or sobol, found {other:?}"),
                )
            }
        };
        if let Method::Sobol { .. } = method {
            if parameters.len() > crate::sampler::sobol::MAX_DIMS {
                return cx.err(sp.method.span(), "sampling.method", "more parameters than Sobol' dimensions");
            }
        }

        let output = match raw.campaign.and_then(|c| c.output) {
            Some(o) => cx.resolve(&o),
            None => {
                let stem =
                    path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "campaign".into());
                cx.resolve(&format!("{stem}.out"))
            }
        };
        let settings = Settings { refine_tol, angle_tol, formats };
        // The hash of everything a variant's outputs depend on (not the file's comments).
        let spec = serde_json::json!({
            "geometry_sha256": sha_hex(&geometry_bytes),
            "deformation_sha256": sha_hex(def_text.as_bytes()),
            "parameters": parameters.iter().map(|p| serde_json::json!({
                "name": p.name, "entry": p.entry.to_string(),
                "values": match &p.values { Values::Range { lo, hi } => serde_json::json!({"range": [lo, hi]}),
                                            Values::Set(v) => serde_json::json!({"set": v}) },
            })).collect::<Vec<_>>(),
            "refine_tol": refine_tol, "angle_tol": angle_tol,
            "formats": settings.formats.iter().map(|f| format!("{f:?}")).collect::<Vec<_>>(),
            "method": format!("{method:?}"), "seed": seed,
            "cadmorph": env!("CARGO_PKG_VERSION"),
        });
        let hash = sha_hex(spec.to_string().as_bytes());
        Ok(DesignSpace {
            path: path.to_owned(),
            geometry,
            deformation_path,
            deformation,
            parameters,
            method,
            seed,
            settings,
            output,
            hash,
        })
    }

    /// The parameter names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.parameters.iter().map(|p| p.name.as_str()).collect()
    }
}
