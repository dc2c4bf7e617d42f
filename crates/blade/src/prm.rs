//! BladeX parameter files (`.prm`, `bladex.params.ParamFile`): the radial distributions
//! of chord, pitch, rake, skew and camber, and per parameter the B-spline degree,
//! sample count, number of control points and control-point y-deformations.

use crate::{Error, Result};

/// The five radial parameters of a BladeX parameter file, in file order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LawParam {
    /// Chord length.
    Chord,
    /// Pitch.
    Pitch,
    /// Rake.
    Rake,
    /// Skew angle (degrees).
    Skew,
    /// Maximum camber.
    Camber,
}

impl LawParam {
    /// All five, in BladeX's order.
    pub const ALL: [LawParam; 5] = [LawParam::Chord, LawParam::Pitch, LawParam::Rake, LawParam::Skew, LawParam::Camber];

    /// The lower-case name (`"chord"`, ...).
    pub fn name(self) -> &'static str {
        match self {
            LawParam::Chord => "chord",
            LawParam::Pitch => "pitch",
            LawParam::Rake => "rake",
            LawParam::Skew => "skew",
            LawParam::Camber => "camber",
        }
    }

    /// The index in [`ALL`](Self::ALL).
    pub fn index(self) -> usize {
        self as usize
    }

    fn section(self) -> &'static str {
        match self {
            LawParam::Chord => "Chord B-Spline",
            LawParam::Pitch => "Pitch B-Spline",
            LawParam::Rake => "Rake B-Spline",
            LawParam::Skew => "Skew B-Spline",
            LawParam::Camber => "Camber B-Spline",
        }
    }

    /// From its name.
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == s)
    }
}

/// The B-spline settings of one parameter.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LawSettings {
    /// Degree of the B-spline (`spline degree`).
    pub degree: usize,
    /// Samples of the B-spline (`spline npoints`).
    pub npoints: usize,
    /// Number of control points (`number of control points`).
    pub nbasis: usize,
    /// Y-deformation of each control point (`control points Y-deformations`).
    pub deformations: Vec<f64>,
}

/// A BladeX parameter file.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ParamFile {
    /// Radial sections.
    pub radii: Vec<f64>,
    /// Radial distribution of each [`LawParam`], indexed by [`LawParam::index`].
    pub parameters: [Vec<f64>; 5],
    /// B-spline settings of each [`LawParam`].
    pub settings: [LawSettings; 5],
}

/// One `key = value` of an INI section: the value lines with their 1-based line numbers.
#[derive(Debug)]
struct Entry {
    section: String,
    key: String,
    key_line: usize,
    lines: Vec<(usize, String)>,
}

/// Parses INI text the way Python's `configparser.RawConfigParser` does for these files:
/// `[section]` headers, `#`/`;` comment lines, `key = value` or `key: value`, and
/// continuation lines indented deeper than their key (keys compared lower-case).
fn parse_ini(text: &str, file: &str) -> Result<Vec<Entry>> {
    let mut out: Vec<Entry> = Vec::new();
    let mut section: Option<String> = None;
    let mut key_indent = 0usize;
    let mut open = false;
    for (i, raw) in text.lines().enumerate() {
        let no = i + 1;
        let trimmed = raw.trim();
        let indent = raw.len() - raw.trim_start().len();
        if trimmed.starts_with('#') || trimmed.starts_with(';') {
            continue;
        }
        if trimmed.is_empty() {
            if open {
                if let Some(e) = out.last_mut() {
                    e.lines.push((no, String::new()));
                }
            }
            continue;
        }
        if open && indent > key_indent {
            if let Some(e) = out.last_mut() {
                e.lines.push((no, trimmed.to_owned()));
            }
            continue;
        }
        open = false;
        if trimmed.starts_with('[') {
            let Some(name) = trimmed.strip_prefix('[').and_then(|t| t.strip_suffix(']')) else {
                return Err(Error::Prm {
                    file: file.into(),
                    line: no,
                    reason: format!("bad section header {trimmed:?}"),
                });
            };
            section = Some(name.to_owned());
            continue;
        }
        let Some(sec) = section.clone() else {
            return Err(Error::Prm { file: file.into(), line: no, reason: "a value before any [section]".into() });
        };
        let pos = trimmed.find(['=', ':']).ok_or_else(|| Error::Prm {
            file: file.into(),
            line: no,
            reason: format!("expected `key = value`, found {trimmed:?}"),
        })?;
        let key = trimmed[..pos].trim().to_lowercase();
        let value = trimmed[pos + 1..].trim().to_owned();
        key_indent = indent;
        open = true;
        let mut lines = Vec::new();
        if !value.is_empty() {
            lines.push((no, value));
        }
        out.push(Entry { section: sec, key, key_line: no, lines });
    }
    for e in &mut out {
        while e.lines.last().is_some_and(|(_, l)| l.is_empty()) {
            e.lines.pop();
        }
    }
    Ok(out)
}

fn find<'a>(entries: &'a [Entry], section: &str, key: &str, file: &str) -> Result<&'a Entry> {
    entries.iter().find(|e| e.section == section && e.key == key).ok_or_else(|| Error::Prm {
        file: file.into(),
        line: 0,
        reason: format!("missing `{key}` in [{section}]"),
    })
}

fn numbers(e: &Entry, what: &str, file: &str) -> Result<Vec<f64>> {
    let mut v = Vec::with_capacity(e.lines.len());
    for (no, l) in &e.lines {
        let mut it = l.split_whitespace();
        let (Some(first), None) = (it.next(), it.next()) else {
            return Err(Error::Prm {
                file: file.into(),
                line: *no,
                reason: if l.is_empty() {
                    format!("{what}: an empty line inside the list")
                } else {
                    format!("{what}: one value per line expected, found {l:?}")
                },
            });
        };
        v.push(first.parse::<f64>().map_err(|_| Error::Prm {
            file: file.into(),
            line: *no,
            reason: format!("{what}: {first:?} is not a number"),
        })?);
    }
    Ok(v)
}

fn integer(e: &Entry, what: &str, file: &str) -> Result<usize> {
    let (no, l) = e.lines.first().cloned().unwrap_or((e.key_line, String::new()));
    if e.lines.len() != 1 {
        return Err(Error::Prm { file: file.into(), line: no, reason: format!("{what}: one integer expected") });
    }
    l.trim().parse::<usize>().map_err(|_| Error::Prm {
        file: file.into(),
        line: no,
        reason: format!("{what}: {l:?} is not a non-negative integer"),
    })
}

/// Python's `str(float)`: the shortest text that reads back to the same number, with
/// `.0` on integers and scientific notation below 1e-4 or from 1e16.
pub fn py_float(x: f64) -> String {
    if x.is_nan() {
        return "nan".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf".into() } else { "-inf".into() };
    }
    if x == 0.0 {
        return if x.is_sign_negative() { "-0.0".into() } else { "0.0".into() };
    }
    let e = format!("{x:e}");
    let (mant, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    if !(-4..16).contains(&exp) {
        return format!("{mant}e{}{:02}", if exp < 0 { '-' } else { '+' }, exp.abs());
    }
    let s = format!("{x}");
    if s.contains('.') {
        s
    } else {
        format!("{s}.0")
    }
}

impl ParamFile {
    /// Reads a parameter file's text (`file` names it in errors).
    ///
    /// # Errors
    ///
    /// [`Error::Prm`] with the line: a value line holding more than one number (BladeX's
    /// `_corrupt_3`, `_5`, `_6`), distributions of different lengths (the line of the
    /// first surplus value, `_corrupt`), an empty deformation list (`_corrupt_2`), a
    /// deformation count other than the number of control points (`_corrupt_4`), a
    /// missing key, a degree not below the number of control points.
    pub fn parse(text: &str, file: &str) -> Result<Self> {
        let entries = parse_ini(text, file)?;
        let sec = "Original parameters";
        let re = find(&entries, sec, "radial sections", file)?;
        let radii = numbers(re, "Radial sections", file)?;
        let mut parameters: [Vec<f64>; 5] = Default::default();
        for p in LawParam::ALL {
            let key = format!("radial distribution of {}", p.name());
            let e = find(&entries, sec, &key, file)?;
            let v = numbers(e, &format!("Radial distribution of {}", p.name()), file)?;
            if v.len() != radii.len() {
                let (longer, n) = if v.len() > radii.len() { (e, radii.len()) } else { (re, v.len()) };
                let line = longer.lines.get(n).map_or(longer.key_line, |l| l.0);
                return Err(Error::Prm {
                    file: file.into(),
                    line,
                    reason: format!(
                        "{} radial sections but {} values of {}: the arrays must have the same length",
                        radii.len(),
                        v.len(),
                        p.name()
                    ),
                });
            }
            parameters[p.index()] = v;
        }
        let mut settings: Vec<LawSettings> = Vec::new();
        for p in LawParam::ALL {
            let s = p.section();
            let degree = integer(find(&entries, s, "spline degree", file)?, "spline degree", file)?;
            let npoints = integer(find(&entries, s, "spline npoints", file)?, "spline npoints", file)?;
            let ne = find(&entries, s, "number of control points", file)?;
            let nbasis = integer(ne, "number of control points", file)?;
            let de = find(&entries, s, "control points y-deformations", file)?;
            if de.lines.is_empty() {
                return Err(Error::Prm {
                    file: file.into(),
                    line: de.key_line,
                    reason: format!("control points Y-deformations in [{s}] must be non-empty"),
                });
            }
            let deformations = numbers(de, &format!("[{s}] control points Y-deformations"), file)?;
            if deformations.len() != nbasis {
                return Err(Error::Prm {
                    file: file.into(),
                    line: ne.lines.first().map_or(ne.key_line, |l| l.0),
                    reason: format!("[{s}]: {nbasis} control points but {} Y-deformations", deformations.len()),
                });
            }
            settings.push(LawSettings { degree, npoints, nbasis, deformations });
        }
        let settings: [LawSettings; 5] =
            settings.try_into().map_err(|_| Error::Prm { file: file.into(), line: 0, reason: "five laws".into() })?;
        Ok(Self { radii, parameters, settings })
    }

    /// Reads a parameter file.
    ///
    /// # Errors
    ///
    /// [`Error::Io`], then as [`parse`](Self::parse).
    pub fn read(path: &std::path::Path) -> Result<Self> {
        let text =
            std::fs::read_to_string(path).map_err(|e| Error::Io { path: path.display().to_string(), source: e })?;
        Self::parse(&text, &path.display().to_string())
    }

    /// The file text in BladeX's layout (`ParamFile.write_parameters`), which reads back
    /// to the same values.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        s.push_str("\n[Original parameters]\n");
        s.push_str("# This section describes the radial distributions of the parameters:\n");
        s.push_str("# \"chord lengths\", \"pitch\", \"rake\", \"skew angles\", and \"camber\"\n");
        s.push_str("# at given radial sections.\n");
        s.push_str("\nRadial sections = ");
        let mut offset = 1;
        for r in &self.radii {
            s.push_str(&" ".repeat(offset));
            s.push_str(&py_float(*r));
            s.push('\n');
            offset = 19;
        }
        let gaps: [isize; 5] = [0, 0, 1, 1, -1];
        for (p, gap) in LawParam::ALL.into_iter().zip(gaps) {
            let mut offset = (1 + gap) as usize;
            s.push_str(&format!("\nRadial distribution of {} = ", p.name()));
            for v in &self.parameters[p.index()] {
                s.push_str(&" ".repeat(offset));
                s.push_str(&py_float(*v));
                s.push('\n');
                offset = 32;
            }
        }
        for p in LawParam::ALL {
            let st = &self.settings[p.index()];
            s.push_str(&format!("\n\n[{}]\n", p.section()));
            s.push_str(&format!(
                "# This section describes the B-Spline construction of the RADII -- {} curve.\n",
                p.name().to_uppercase()
            ));
            s.push_str("\n# degree of the B-Spline curve\n");
            s.push_str(&format!("spline degree: {}\n", st.degree));
            s.push_str("\n# number of points to be evaluated with the B-Spline interpolation\n");
            s.push_str(&format!("spline npoints: {}\n", st.npoints));
            s.push_str("\n# number of the control points\n");
            s.push_str(&format!("number of control points: {}\n", st.nbasis));
            s.push_str("\n# Y-deformations of the control points.\n");
            s.push_str("control points Y-deformations = ");
            let mut offset = 1;
            for d in &st.deformations {
                s.push_str(&" ".repeat(offset));
                s.push_str(&py_float(*d));
                s.push('\n');
                offset = 33;
            }
        }
        s
    }

    /// The TOML form of the same content: `radii`, `parameters` (five arrays in the
    /// order chord, pitch, rake, skew, camber) and `settings` (five tables with `degree`,
    /// `npoints`, `nbasis`, `deformations`).
    ///
    /// # Errors
    ///
    /// [`Error::Toml`] (not expected).
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::Toml(e.to_string()))
    }

    /// Reads the TOML form (see [`to_toml`](Self::to_toml)), with the checks of
    /// [`parse`](Self::parse): equal lengths, one deformation per control point.
    ///
    /// # Errors
    ///
    /// [`Error::Toml`] with TOML's line and column; [`Error::Prm`] (line 0) for
    /// inconsistent arrays.
    pub fn from_toml(text: &str, file: &str) -> Result<Self> {
        let p: ParamFile = toml::from_str(text).map_err(|e| Error::Toml(format!("{file}: {e}")))?;
        for q in LawParam::ALL {
            let n = p.parameters[q.index()].len();
            if n != p.radii.len() {
                return Err(Error::Prm {
                    file: file.into(),
                    line: 0,
                    reason: format!("{} radii but {n} values of {}", p.radii.len(), q.name()),
                });
            }
            let s = &p.settings[q.index()];
            if s.deformations.len() != s.nbasis {
                return Err(Error::Prm {
                    file: file.into(),
                    line: 0,
                    reason: format!(
                        "{}: {} control points but {} deformations",
                        q.name(),
                        s.nbasis,
                        s.deformations.len()
                    ),
                });
            }
        }
        Ok(p)
    }

    /// Reads a `.prm` file, or its TOML form when the name ends in `.toml`.
    ///
    /// # Errors
    ///
    /// As [`read`](Self::read) and [`from_toml`](Self::from_toml).
    pub fn read_any(path: &std::path::Path) -> Result<Self> {
        if path.extension().is_some_and(|e| e == "toml") {
            let text =
                std::fs::read_to_string(path).map_err(|e| Error::Io { path: path.display().to_string(), source: e })?;
            Self::from_toml(&text, &path.display().to_string())
        } else {
            Self::read(path)
        }
    }

    /// Writes the file through a temporary file renamed into place.
    ///
    /// # Errors
    ///
    /// [`Error::Io`].
    pub fn write(&self, path: &std::path::Path) -> Result<()> {
        crate::output::write_atomic(path, self.to_text().as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::py_float;

    #[test]
    fn python_float_text() {
        assert_eq!(py_float(1.0), "1.0");
        assert_eq!(py_float(0.3), "0.3");
        assert_eq!(py_float(-7.4), "-7.4");
        assert_eq!(py_float(1e-5), "1e-05");
        assert_eq!(py_float(0.0001), "0.0001");
        assert_eq!(py_float(1.5e16), "1.5e+16");
    }
}
