//! `cadmorph.open(path)` and the `Model` class: faces, edges, morph, seams, save.

use std::path::PathBuf;

use cadmorph::model::MorphOptions;
use cadmorph::seam::SeamRefineOptions;
use numpy::PyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Serialize;

use crate::arrays::points_to_array;
use crate::errors::model_err;
use crate::morphs::morph_of;

/// Entity references (`{"format", "id", "occurrence"}` in serde's form) as the names the
/// files use, `"DE 5"` (IGES) and `"#12"` (STEP), as `EntityRef`'s `Display` writes them.
fn entity_names(v: &mut serde_json::Value) {
    use serde_json::Value;
    match v {
        Value::Object(map) => {
            let is_ref = map.len() == 3
                && map.contains_key("format")
                && map.contains_key("id")
                && map.contains_key("occurrence");
            if is_ref {
                let id = map["id"].as_u64().unwrap_or(0);
                let occurrence = map["occurrence"].as_u64().unwrap_or(0);
                let mut name = match map["format"].as_str() {
                    Some("Iges") => format!("DE {id}"),
                    _ => format!("#{id}"),
                };
                if occurrence > 0 {
                    name.push_str(&format!(" (occurrence {})", occurrence + 1));
                }
                *v = Value::String(name);
            } else {
                map.values_mut().for_each(entity_names);
            }
        }
        Value::Array(items) => items.iter_mut().for_each(entity_names),
        _ => {}
    }
}

/// A value serialised by serde as the Python object `json.loads` makes of it, with entity
/// references as names (see [`entity_names`]).
fn to_python<'py, T: Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let mut v = serde_json::to_value(value).map_err(|e| PyValueError::new_err(e.to_string()))?;
    entity_names(&mut v);
    py.import("json")?.call_method1("loads", (v.to_string(),))
}

/// An IGES or STEP file as faces (exact NURBS patches in world coordinates) and the edges
/// they share, made by `cadmorph.open(path)`. Morphing rewrites only the entities that
/// move; `save` writes the edited document (every other entity byte for byte).
///
/// A model belongs to the thread that opened it.
#[pyclass(name = "Model", module = "cadmorph", unsendable)]
pub struct PyModel {
    model: cadmorph::Model,
    path: Option<PathBuf>,
}

/// Opens an IGES or STEP file (told apart by its contents) as a `Model`.
///
/// Raises `CadFileError` (a `ValueError`) with `path`, `line` and `entity` for a file that
/// does not read, `FileNotFoundError`/`OSError` when it cannot be opened.
#[pyfunction]
pub(crate) fn open(path: PathBuf) -> PyResult<PyModel> {
    let model = cadmorph::open(&path).map_err(|e| model_err(e, Some(&path)))?;
    Ok(PyModel { model, path: Some(path) })
}

/// A model from the bytes of an IGES or STEP file.
#[pyfunction]
pub(crate) fn from_bytes(data: &[u8]) -> PyResult<PyModel> {
    let model = cadmorph::from_bytes(data).map_err(|e| model_err(e, None))?;
    Ok(PyModel { model, path: None })
}

#[pymethods]
impl PyModel {
    /// "iges" or "step".
    #[getter]
    fn format(&self) -> &'static str {
        match self.model.format() {
            cadmorph::Format::Iges => "iges",
            cadmorph::Format::Step => "step",
        }
    }

    /// The file's length unit (`"millimetre"`, `"metre"`, ...).
    #[getter]
    fn unit(&self) -> String {
        self.model.unit().to_string()
    }

    /// The model size (diagonal of the bounding box of all control points), model units.
    #[getter]
    fn size(&self) -> f64 {
        self.model.size()
    }

    /// The path it was opened from, or None.
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.path.clone()
    }

    /// The faces, one dict each: `face` and `surface` (entity names, `"DE 5"`, `"#12"`),
    /// `kind`, `u_degree`, `v_degree`, `n_u`, `n_v`, `rational`, `analytic`, `trimmed`,
    /// `reversed`.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.model.info().patches)
    }

    /// Faces that could not be converted (left untouched by a morph): dicts with `entity`
    /// and `reason`.
    #[getter]
    fn skipped<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.model.info().skipped)
    }

    /// The shared edges, one dict each: `kind` ("iso" for coinciding patch sides, "trim"
    /// for edges from the file's topology or trimming curves), `faces` (the two face
    /// indices) and, for iso edges, `sides` (`"u_min"` ...), for trim edges `entities`.
    #[getter]
    fn edges<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let list = pyo3::types::PyList::empty(py);
        let side = |s: cadmorph::nurbs::Side| match s {
            cadmorph::nurbs::Side::UMin => "u_min",
            cadmorph::nurbs::Side::UMax => "u_max",
            cadmorph::nurbs::Side::VMin => "v_min",
            cadmorph::nurbs::Side::VMax => "v_max",
        };
        for e in self.model.edges() {
            let d = PyDict::new(py);
            d.set_item("kind", "iso")?;
            d.set_item("faces", (e.a.patch, e.b.patch))?;
            d.set_item("sides", (side(e.a.side), side(e.b.side)))?;
            list.append(d)?;
        }
        for e in self.model.trim_edges() {
            let d = PyDict::new(py);
            d.set_item("kind", "trim")?;
            d.set_item("faces", (e.a, e.b))?;
            d.set_item("entities", e.label.iter().map(|r| r.to_string()).collect::<Vec<_>>())?;
            list.append(d)?;
        }
        Ok(list.into_any())
    }

    /// The control points of face `index` in world coordinates, an (n_u·n_v, 3) array
    /// (u-major: row `i·n_v + j` is pole (i, j)).
    fn control_points<'py>(&self, py: Python<'py>, index: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let faces = self.model.patches();
        let face = faces
            .get(index)
            .ok_or_else(|| PyValueError::new_err(format!("index: the model has {} faces, got {index}", faces.len())))?;
        points_to_array(py, face.surface.control_points())
    }

    /// The weights of face `index`, an (n_u·n_v,) array (all 1 for a non-rational face).
    fn weights<'py>(&self, py: Python<'py>, index: usize) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
        let faces = self.model.patches();
        let face = faces
            .get(index)
            .ok_or_else(|| PyValueError::new_err(format!("index: the model has {} faces, got {index}", faces.len())))?;
        let s = &face.surface;
        let n = s.control_points().len();
        let w: Vec<f64> = match s.weights() {
            Some(w) => w.to_vec(),
            None => vec![1.0; n],
        };
        Ok(numpy::IntoPyArray::into_pyarray(w, py))
    }

    /// Measures every shared edge with `samples` points each and returns one dict per edge:
    /// `a`, `b` (face index and side), `edge` (entities), `length`, `gap_closest`,
    /// `gap_matched`, `g1_angle_deg`, `g1_angle_unoriented_deg`, `c1_mismatch` (each a dict
    /// of `max`, `mean`, `at`, `t`) and `sharp`. `seam_report()` gives the totals too.
    #[pyo3(signature = (samples = 200))]
    fn seams<'py>(&self, py: Python<'py>, samples: usize) -> PyResult<Bound<'py, PyAny>> {
        let r = self.model.seams(samples.max(2));
        to_python(py, &r.edges)
    }

    /// The whole seam report: `edges` (as `seams()`) and the maxima `max_gap_closest`,
    /// `max_gap_matched`, `max_g1_angle_deg`, `max_g1_angle_unoriented_deg`,
    /// `max_c1_mismatch`, `sharp_edges`.
    #[pyo3(signature = (samples = 200))]
    fn seam_report<'py>(&self, py: Python<'py>, samples: usize) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &self.model.seams(samples.max(2)))
    }

    /// Morphs every face with `deformation` (any cadmorph deformation).
    ///
    /// `refine_tol` (model units): insert knots first where the morph needs them, until the
    /// seams stay within this gap and `angle_tol` degrees after the morph (at most
    /// `max_control_points` in all, default `SeamRefineOptions::default_budget`: 20x the input's, at least 50 000); a refinement that does not
    /// converge raises `CadFileError` and leaves the model as it was. `uniform_knots`:
    /// PyGeM-style refinement instead (that many knots per direction on every patch).
    /// `repair`: make knots compatible across seams first and both sides of every shared
    /// edge identical after. Returns the outcome as a dict (`control_points_before`,
    /// `control_points_after`, `faces_rewritten`, `curves_rewritten`, `parts_copied`,
    /// `refinement`, `seams_before`, `seams_after`).
    #[pyo3(signature = (deformation, refine_tol = None, angle_tol = 0.01, max_control_points = None, uniform_knots = None, repair = false))]
    fn morph<'py>(
        &mut self,
        py: Python<'py>,
        deformation: &Bound<'py, PyAny>,
        refine_tol: Option<f64>,
        angle_tol: f64,
        max_control_points: Option<usize>,
        uniform_knots: Option<usize>,
        repair: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let d = morph_of(deformation, "deformation")?;
        if refine_tol.is_some() && uniform_knots.is_some() {
            return Err(PyValueError::new_err("refine_tol and uniform_knots: give one or the other"));
        }
        if !(angle_tol.is_finite() && angle_tol > 0.0) {
            return Err(PyValueError::new_err(format!("angle_tol must be positive and finite, got {angle_tol}")));
        }
        let before: usize = self.model.patches().iter().map(|p| p.surface.control_points().len()).sum();
        let refine = match refine_tol {
            Some(t) => {
                if !(t.is_finite() && t > 0.0) {
                    return Err(PyValueError::new_err(format!("refine_tol must be positive and finite, got {t}")));
                }
                let mut r = SeamRefineOptions::new(t, angle_tol);
                r.max_control_points = max_control_points.unwrap_or(SeamRefineOptions::default_budget(before));
                Some(r)
            }
            None => None,
        };
        let opts = MorphOptions { refine, uniform_knots, repair };
        // A failed or unconverged morph must leave the model as it was: work on a copy of
        // the document and keep it only when everything succeeded.
        let mut work = cadmorph::from_bytes(&self.model.to_bytes()).map_err(|e| model_err(e, self.path.as_deref()))?;
        let outcome = work.morph(&d, &opts);
        if let Some(e) = d.take_error() {
            return Err(e);
        }
        let outcome = outcome.map_err(|e| model_err(e, self.path.as_deref()))?;
        if let (Some(r), Some(o)) = (&outcome.refinement, &opts.refine) {
            if !r.converged {
                return Err(crate::errors::model_err(
                    cadmorph::Error::Unsupported("seam refinement did not converge (model left unchanged)"),
                    self.path.as_deref(),
                )
                .and_note(py, format!(
                    "after {} rounds the largest gap is {:.3e} (asked {:.3e}) and the largest angle {:.4} deg (asked {}), with {} control points (limit {})",
                    r.rounds, r.max_gap, o.tol, r.max_angle_deg, o.angle_tol_deg, r.control_points_after, o.max_control_points
                )));
            }
        }
        self.model = work;
        to_python(py, &outcome)
    }

    /// Reads the document as it would be written back and measures it: a dict with
    /// `seams` (the seam report of the file read back) and `max_deviation` (largest
    /// control-point difference between memory and file).
    fn verify<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v = self.model.verify().map_err(|e| model_err(e, self.path.as_deref()))?;
        to_python(py, &v)
    }

    /// Writes the model to `path` (through a temporary file and a rename), in the format
    /// its extension names (`.igs`/`.iges`, `.stp`/`.step`): the edited document for the
    /// model's own format, a converted one for the other.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        cadmorph::save_as(&self.model, &path).map_err(|e| model_err(e, Some(&path)))
    }

    /// The document as bytes (the input, byte for byte, where nothing was edited).
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, pyo3::types::PyBytes> {
        pyo3::types::PyBytes::new(py, &self.model.to_bytes())
    }

    fn __len__(&self) -> usize {
        self.model.patches().len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(format={:?}, faces={}, edges={}, unit={:?}{})",
            self.format(),
            self.model.patches().len(),
            self.model.edges().len() + self.model.trim_edges().len(),
            self.unit(),
            self.path.as_ref().map(|p| format!(", path={:?}", p.display().to_string())).unwrap_or_default()
        )
    }
}

/// Adds a note to an exception's message (PEP 678 `add_note` is 3.11+; the message is
/// extended instead so that every Python version shows it).
trait AndNote {
    fn and_note(self, py: Python<'_>, note: String) -> PyErr;
}

impl AndNote for PyErr {
    fn and_note(self, py: Python<'_>, note: String) -> PyErr {
        let value = self.value(py);
        let msg = value.str().map(|s| s.to_string()).unwrap_or_default();
        let new = crate::errors::CadFileError::new_err(format!("{msg}: {note}"));
        for attr in ["path", "line", "entity"] {
            if let Ok(v) = value.getattr(attr) {
                let _ = new.value(py).setattr(attr, v);
            }
        }
        new
    }
}
