//! Rust errors as Python exceptions, with the position (file, line, entity) as attributes.
//!
//! Every exception cadmorph raises for bad input is a `ValueError` (or `OSError` for the file
//! system), so `except ValueError` catches them; the subclasses carry what Python code
//! needs to point at the problem:
//!
//! - [`ParameterError`] (`cadmorph.ParameterError`): a parameter file or parameter value
//!   (`.prm`, TOML) — attributes `path` (or `None`) and `line` (1-based, or `None`);
//! - [`CadFileError`] (`cadmorph.CadFileError`): an IGES/STEP file that does not read, or
//!   a morph/save of a model that fails — attributes `path`, `line`, `entity` (`"DE 5"`,
//!   `"#12"`, or `None`).

use std::path::Path;

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    cadmorph,
    ParameterError,
    PyValueError,
    "A parameter file (PyGeM .prm or TOML) or a parameter value is invalid. Attributes: `path` (str or None) and `line` (1-based int or None)."
);

pyo3::create_exception!(
    cadmorph,
    CadFileError,
    PyValueError,
    "An IGES/STEP file does not read, or a model cannot be morphed or saved. Attributes: `path` (str or None), `line` (1-based int or None) and `entity` (\"DE 5\", \"#12\" or None)."
);

/// The first number after `key` in `msg`.
fn number_after(msg: &str, key: &str) -> Option<u64> {
    let mut rest = msg;
    while let Some(i) = rest.find(key) {
        let tail = &rest[i + key.len()..];
        let digits: String = tail.chars().take_while(|c| c.is_ascii_digit()).collect();
        if let Ok(n) = digits.parse() {
            return Some(n);
        }
        rest = tail;
    }
    None
}

/// The 1-based line a message names (`line 12`), if any.
pub(crate) fn line_of(msg: &str) -> Option<u64> {
    number_after(msg, "line ").filter(|&l| l > 0)
}

/// The entity a message names: IGES `DE 5`, STEP `#12`.
pub(crate) fn entity_of(msg: &str) -> Option<String> {
    if let Some(de) = number_after(msg, "DE ") {
        return Some(format!("DE {de}"));
    }
    number_after(msg, "#").map(|id| format!("#{id}"))
}

fn with_attrs(py: Python<'_>, err: PyErr, attrs: &[(&str, Py<PyAny>)]) -> PyErr {
    let value = err.value(py);
    for (k, v) in attrs {
        // Setting an attribute on a fresh exception instance cannot fail; ignore if it does.
        let _ = value.setattr(*k, v);
    }
    err
}

fn opt_str(py: Python<'_>, s: Option<String>) -> Py<PyAny> {
    match s {
        Some(s) => s.into_pyobject(py).map(|b| b.into_any().unbind()).unwrap_or_else(|_| py.None()),
        None => py.None(),
    }
}

fn opt_int(py: Python<'_>, n: Option<u64>) -> Py<PyAny> {
    match n {
        Some(n) => n.into_pyobject(py).map(|b| b.into_any().unbind()).unwrap_or_else(|_| py.None()),
        None => py.None(),
    }
}

/// A morph-crate error (parameters, solves) as [`ParameterError`].
pub(crate) fn morph_err(e: cadmorph::morph::Error, path: Option<&Path>) -> PyErr {
    let msg = e.to_string();
    let line = line_of(&msg);
    let full = match path {
        Some(p) => format!("{}: {msg}", p.display()),
        None => msg,
    };
    Python::attach(|py| {
        with_attrs(
            py,
            ParameterError::new_err(full),
            &[("path", opt_str(py, path.map(|p| p.display().to_string()))), ("line", opt_int(py, line))],
        )
    })
}

/// A model-layer error: I/O as `OSError` (the right subclass, `FileNotFoundError` for a
/// missing file), everything else as [`CadFileError`] with the whole cause chain in the
/// message and the position as attributes.
pub(crate) fn model_err(e: cadmorph::Error, path: Option<&Path>) -> PyErr {
    use cadmorph::Error as E;
    match &e {
        E::Io { path, source } | E::Write { path, source } => {
            let err = std::io::Error::new(source.kind(), format!("{}: {source}", path.display()));
            let py_err: PyErr = err.into();
            Python::attach(|py| {
                if py_err.is_instance_of::<PyOSError>(py) {
                    with_attrs(py, py_err, &[("filename", opt_str(py, Some(path.display().to_string())))])
                } else {
                    py_err
                }
            })
        }
        _ => {
            let msg = cadmorph::brep::chain(&e);
            let file = match &e {
                E::Read { path, .. } | E::NotAFile { path, .. } | E::UnknownExtension { path } => Some(path.clone()),
                _ => path.map(Path::to_path_buf),
            };
            let line = line_of(&msg);
            let entity = entity_of(&msg);
            Python::attach(|py| {
                with_attrs(
                    py,
                    CadFileError::new_err(msg),
                    &[
                        ("path", opt_str(py, file.map(|p| p.display().to_string()))),
                        ("line", opt_int(py, line)),
                        ("entity", opt_str(py, entity)),
                    ],
                )
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_are_found_in_messages() {
        assert_eq!(line_of("line 12: expected a number"), Some(12));
        assert_eq!(line_of("section P, line 40, column 3, entity DE 7"), Some(40));
        assert_eq!(line_of("no position"), None);
        assert_eq!(entity_of("section P, line 40, column 3, entity DE 7: bad"), Some("DE 7".into()));
        assert_eq!(entity_of("line 3, column 1, instance #120: invalid geometry"), Some("#120".into()));
        assert_eq!(entity_of("the morph folds space at control point 3 of face #45"), Some("#45".into()));
        assert_eq!(entity_of("nothing here"), None);
    }
}
