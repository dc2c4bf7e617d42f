//! The deformations as Python classes: `Ffd`, `Rbf`, `Idw`, `Affine`, `Composed` and
//! `FromFunction`, all applying `cadmorph-morph`'s implementations to numpy arrays.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use cadmorph::morph::ffd::FACE_TOL;
use cadmorph::morph::math::{Matrix3, Point3, Vector3};
use cadmorph::morph::rbf::Kernel;
use cadmorph::morph::{
    checked_by_chunks, for_each_chunk, Affine, ChunkHook, Deformation, Ffd, Idw, IdwParameters, IdwVariant, Parameters,
    Rbf, RbfParameters,
};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::arrays::{
    as_points, as_points_mut, first_non_finite, non_finite_err, points_to_array, points_vec, points_view, three,
    to_array,
};
use crate::errors::morph_err;

/// A Python callable `f(points) -> points` on `(n, 3)` arrays, as a deformation. The first
/// exception it raises is kept (the [`Deformation`] trait cannot fail) and re-raised by
/// whatever called the morph; the points it was given come back as NaN meanwhile.
#[derive(Clone)]
pub(crate) struct PyFunction {
    func: Arc<Py<PyAny>>,
    error: Arc<Mutex<Option<PyErr>>>,
}

impl PyFunction {
    fn call(&self, points: &mut [Point3<f64>]) {
        if self.error.lock().map(|e| e.is_some()).unwrap_or(true) {
            points.fill(Point3::new(f64::NAN, f64::NAN, f64::NAN));
            return;
        }
        let result = Python::attach(|py| -> PyResult<()> {
            let arr = points_to_array(py, points)?;
            let out = self.func.bind(py).call1((arr,))?;
            let view = points_view(&out, "the function's result")?;
            let flat = view.as_slice().map_err(|e| PyValueError::new_err(e.to_string()))?;
            if flat.len() != points.len() * 3 {
                return Err(PyValueError::new_err(format!(
                    "the function returned {} points for {} given",
                    flat.len() / 3,
                    points.len()
                )));
            }
            points.copy_from_slice(as_points(flat));
            Ok(())
        });
        if let Err(e) = result {
            if let Ok(mut slot) = self.error.lock() {
                slot.get_or_insert(e);
            }
            points.fill(Point3::new(f64::NAN, f64::NAN, f64::NAN));
        }
    }

    /// The kept exception, if the function raised one (taken: the next call starts clean).
    pub(crate) fn take_error(&self) -> Option<PyErr> {
        self.error.lock().ok().and_then(|mut e| e.take())
    }
}

/// Every deformation the bindings know, as one type the model and the arrays can take.
#[derive(Clone)]
#[allow(clippy::large_enum_variant)] // one per call; boxing the Ffd would only add an indirection
pub(crate) enum Morph {
    Ffd(Ffd),
    Rbf(Arc<Rbf>),
    Idw(Arc<Idw>),
    Affine(Affine),
    Chain(Vec<Morph>),
    Function(PyFunction),
}

impl Morph {
    /// Whether applying it calls back into Python.
    fn calls_python(&self) -> bool {
        match self {
            Morph::Function(_) => true,
            Morph::Chain(v) => v.iter().any(Morph::calls_python),
            _ => false,
        }
    }

    /// The first exception a Python function in it raised, if any.
    pub(crate) fn take_error(&self) -> Option<PyErr> {
        match self {
            Morph::Function(f) => f.take_error(),
            Morph::Chain(v) => v.iter().find_map(Morph::take_error),
            _ => None,
        }
    }
}

impl Deformation for Morph {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        match self {
            Morph::Ffd(d) => d.deform_point(p),
            Morph::Rbf(d) => d.deform_point(p),
            Morph::Idw(d) => d.deform_point(p),
            Morph::Affine(d) => d.deform_point(p),
            Morph::Chain(v) => v.iter().fold(*p, |q, d| d.deform_point(&q)),
            Morph::Function(f) => {
                let mut one = [*p];
                f.call(&mut one);
                one[0]
            }
        }
    }

    fn deform(&self, points: &mut [Point3<f64>]) {
        match self {
            Morph::Ffd(d) => d.deform(points),
            Morph::Rbf(d) => d.deform(points),
            Morph::Idw(d) => d.deform(points),
            Morph::Affine(d) => d.deform(points),
            Morph::Chain(v) => v.iter().for_each(|d| d.deform(points)),
            // One call with the whole array, on the calling thread.
            Morph::Function(f) => f.call(points),
        }
    }

    fn deform_checked(&self, points: &mut [Point3<f64>]) -> Result<(), usize> {
        match self {
            // The FFD's check is fused into its kernel.
            Morph::Ffd(d) => d.deform_checked(points),
            _ => checked_by_chunks(self, points),
        }
    }

    fn deform_chunks(&self, points: &mut [Point3<f64>], before: &ChunkHook<'_>) {
        match self {
            Morph::Ffd(d) => d.deform_chunks(points, before),
            Morph::Rbf(d) => d.deform_chunks(points, before),
            Morph::Idw(d) => d.deform_chunks(points, before),
            Morph::Affine(d) => d.deform_chunks(points, before),
            // Each link's own batched deform, chunk by chunk.
            Morph::Chain(_) => for_each_chunk(points, before, |c| self.deform(c)),
            // On the calling thread, in one piece.
            Morph::Function(f) => {
                if before(0, points) {
                    f.call(points);
                }
            }
        }
    }

    fn jacobian(&self, p: &Point3<f64>) -> Option<Matrix3<f64>> {
        match self {
            Morph::Ffd(d) => d.jacobian(p),
            Morph::Rbf(d) => d.jacobian(p),
            Morph::Idw(d) => d.jacobian(p),
            Morph::Affine(d) => d.jacobian(p),
            Morph::Chain(v) => {
                let mut q = *p;
                let mut j = Matrix3::identity();
                for d in v {
                    j = d.jacobian(&q)? * j;
                    q = d.deform_point(&q);
                }
                Some(j)
            }
            Morph::Function(_) => None,
        }
    }
}

/// The deformation held by any of the bindings' classes, or a `TypeError` naming `name`.
pub(crate) fn morph_of(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Morph> {
    if let Ok(d) = obj.cast::<PyFfd>() {
        return Ok(Morph::Ffd(d.borrow().inner.clone()));
    }
    if let Ok(d) = obj.cast::<PyRbf>() {
        return Ok(Morph::Rbf(d.borrow().inner.clone()));
    }
    if let Ok(d) = obj.cast::<PyIdw>() {
        return Ok(Morph::Idw(d.borrow().inner.clone()));
    }
    if let Ok(d) = obj.cast::<PyAffine>() {
        return Ok(Morph::Affine(d.borrow().inner));
    }
    if let Ok(d) = obj.cast::<PyComposed>() {
        return Ok(d.borrow().inner.clone());
    }
    if let Ok(d) = obj.cast::<PyFromFunction>() {
        return Ok(d.borrow().inner.clone());
    }
    let ty = obj.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into());
    Err(PyTypeError::new_err(format!(
        "{name} must be a cadmorph deformation (Ffd, Rbf, Idw, Affine, Composed, FromFunction), got {ty}"
    )))
}

/// `morph` applied to `points`: into a new array, or into `out` (which may be `points`
/// itself, for an in-place morph). The GIL is released while native morphs run.
pub(crate) fn apply<'py>(
    morph: &Morph,
    points: &Bound<'py, PyAny>,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let py = points.py();
    let python = morph.calls_python();
    match out {
        None => {
            let view = points_view(points, "points")?;
            let src = view.as_slice().map_err(|e| PyValueError::new_err(format!("points: {e}")))?;
            let run = || copy_check_deform(morph, src, python);
            let result = if python { run() } else { py.detach(run) };
            let flat = result.map_err(|at| non_finite_err("points", at, src[at.0 * 3 + at.1]))?;
            if let Some(e) = morph.take_error() {
                return Err(e);
            }
            Ok(to_array(py, flat)?.into_any())
        }
        Some(out) => {
            let same = out.is(points);
            let out_arr = points_view(out, "out").map(drop).and_then(|_| {
                out.cast::<PyArray2<f64>>().map_err(|_| PyTypeError::new_err("out must be a float64 array"))
            })?;
            if !same {
                let view = points_view(points, "points")?;
                if view.shape() != out_arr.shape() {
                    return Err(PyValueError::new_err(format!(
                        "out must have the shape of points, {:?}, got {:?}",
                        view.shape(),
                        out_arr.shape()
                    )));
                }
                let src = view.as_slice().map_err(|e| PyValueError::new_err(format!("points: {e}")))?;
                if let Some(at) = first_non_finite(src) {
                    return Err(non_finite_err("points", at, src[at.0 * 3 + at.1]));
                }
                let mut rw = out_arr.try_readwrite().map_err(|e| PyValueError::new_err(format!("out: {e}")))?;
                let dst = rw.as_slice_mut().map_err(|e| PyValueError::new_err(format!("out: {e}")))?;
                dst.copy_from_slice(src);
                let mut run = || morph.deform(as_points_mut(dst));
                if python {
                    run()
                } else {
                    py.detach(run)
                }
            } else {
                let mut rw = out_arr.try_readwrite().map_err(|e| PyValueError::new_err(format!("points: {e}")))?;
                let dst = rw.as_slice_mut().map_err(|e| PyValueError::new_err(format!("points: {e}")))?;
                // Checked chunk by chunk just before each chunk is deformed (one pass over
                // memory, as fast as the Rust call): a non-finite value is reported, and the
                // finite points have moved meanwhile (see the docs of `deform`).
                let mut run = || check_deform_in_place(morph, dst, python);
                let result = if python { run() } else { py.detach(run) };
                if let Err(at) = result {
                    let v = dst[at.0 * 3 + at.1];
                    return Err(non_finite_err("points", at, v));
                }
            }
            if let Some(e) = morph.take_error() {
                return Err(e);
            }
            Ok(out.clone())
        }
    }
}

/// `morph` applied to `flat` in place with the check for non-finite values of
/// [`Deformation::deform_checked`] (fused into the FFD's kernel; chunk by chunk just before
/// each is deformed for the others; on this thread when the morph calls Python, after
/// checking everything). `Err` is the first non-finite value, whose point is left as it was.
fn check_deform_in_place(morph: &Morph, flat: &mut [f64], sequential: bool) -> Result<(), (usize, usize)> {
    if sequential {
        if let Some(at) = first_non_finite(flat) {
            return Err(at);
        }
        morph.deform(as_points_mut(flat));
        return Ok(());
    }
    morph.deform_checked(as_points_mut(flat)).map_err(|i| {
        // The point is left as it was: name its first non-finite coordinate.
        let k = (0..3).find(|&k| !flat[3 * i + k].is_finite()).unwrap_or(0);
        (i, k)
    })
}

/// A new buffer holding `morph(src)`: copied, checked and deformed chunk by chunk in
/// parallel (each chunk is still in cache for the morph, see
/// [`Deformation::deform_chunks`]), or all at once on this thread when the morph calls
/// Python. `Err` is the first non-finite input value.
fn copy_check_deform(morph: &Morph, src: &[f64], sequential: bool) -> Result<Vec<f64>, (usize, usize)> {
    let mut dst = vec![0.0; src.len()];
    if sequential {
        if let Some(at) = first_non_finite(src) {
            return Err(at);
        }
        dst.copy_from_slice(src);
        morph.deform(as_points_mut(&mut dst));
        return Ok(dst);
    }
    let first = AtomicUsize::new(usize::MAX);
    morph.deform_chunks(as_points_mut(&mut dst), &|start, chunk| {
        let s = &src[start * 3..start * 3 + chunk.len() * 3];
        match first_non_finite(s) {
            Some((i, k)) => {
                first.fetch_min((start + i) * 3 + k, Ordering::Relaxed);
                false
            }
            None => {
                bytemuck::cast_slice_mut::<Point3<f64>, f64>(chunk).copy_from_slice(s);
                true
            }
        }
    });
    match first.into_inner() {
        usize::MAX => Ok(dst),
        i => Err((i / 3, i % 3)),
    }
}

/// Read a parameter file: TOML when the name ends in `.toml`, else PyGeM's `.prm`.
fn read_params(path: &Path) -> PyResult<Parameters> {
    let bytes = std::fs::read(path).map_err(|e| {
        let err: PyErr = std::io::Error::new(e.kind(), format!("{}: {e}", path.display())).into();
        err
    })?;
    let toml = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    Parameters::from_bytes(&bytes, toml).map_err(|e| morph_err(e, Some(path)))
}

/// Write parameters: TOML when the name ends in `.toml`, else PyGeM's `.prm`.
fn write_params(params: &Parameters, path: &Path) -> PyResult<()> {
    let toml = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    let text = if toml { params.to_toml() } else { params.to_prm().map_err(|e| morph_err(e, Some(path)))? };
    std::fs::write(path, text).map_err(|e| std::io::Error::new(e.kind(), format!("{}: {e}", path.display())).into())
}

/// A Python object of the class that holds `params` (building RBF and IDW).
fn params_to_object(py: Python<'_>, params: Parameters, path: Option<&Path>) -> PyResult<Py<PyAny>> {
    Ok(match params {
        Parameters::Ffd(f) => Py::new(py, PyFfd { inner: f, face_tol: FACE_TOL })?.into_any(),
        Parameters::Rbf(r) => {
            let rbf = py.detach(|| Rbf::from_parameters(&r)).map_err(|e| morph_err(e, path))?;
            Py::new(py, PyRbf { inner: Arc::new(rbf) })?.into_any()
        }
        Parameters::Idw(i) => {
            let idw = Idw::from_parameters(&i).map_err(|e| morph_err(e, path))?;
            Py::new(py, PyIdw { inner: Arc::new(idw) })?.into_any()
        }
    })
}

/// Reads a parameter file (PyGeM `.prm`, or TOML when the name ends in `.toml`) and
/// returns the deformation it describes: an `Ffd`, `Rbf` (solved) or `Idw`.
///
/// Raises `ParameterError` (a `ValueError`) with `path` and `line` for a file that does
/// not read, `OSError` when the file cannot be opened.
#[pyfunction]
pub(crate) fn read_parameters(py: Python<'_>, path: PathBuf) -> PyResult<Py<PyAny>> {
    let params = read_params(&path)?;
    params_to_object(py, params, Some(&path))
}

/// Parses parameter text: PyGeM `.prm` (default) or TOML (`toml=True`); see
/// `read_parameters`.
#[pyfunction]
#[pyo3(signature = (text, toml = false))]
pub(crate) fn parameters_from_str(py: Python<'_>, text: &str, toml: bool) -> PyResult<Py<PyAny>> {
    let params = Parameters::from_bytes(text.as_bytes(), toml).map_err(|e| morph_err(e, None))?;
    params_to_object(py, params, None)
}

/// Composes deformations: `compose(a, b, c)` applies `a`, then `b`, then `c`.
#[pyfunction]
#[pyo3(signature = (*deformations))]
pub(crate) fn compose(deformations: &Bound<'_, PyTuple>) -> PyResult<PyComposed> {
    if deformations.is_empty() {
        return Err(PyValueError::new_err("compose needs at least one deformation"));
    }
    let mut stages = Vec::with_capacity(deformations.len());
    for (i, d) in deformations.iter().enumerate() {
        match morph_of(&d, &format!("deformations[{i}]"))? {
            Morph::Chain(v) => stages.extend(v),
            m => stages.push(m),
        }
    }
    Ok(PyComposed { inner: Morph::Chain(stages) })
}

fn then(first: Morph, next: &Bound<'_, PyAny>) -> PyResult<PyComposed> {
    let mut stages = match first {
        Morph::Chain(v) => v,
        m => vec![m],
    };
    match morph_of(next, "next")? {
        Morph::Chain(v) => stages.extend(v),
        m => stages.push(m),
    }
    Ok(PyComposed { inner: Morph::Chain(stages) })
}

fn vec3(py: Python<'_>, v: Vector3<f64>) -> Bound<'_, numpy::PyArray1<f64>> {
    vec![v.x, v.y, v.z].into_pyarray(py)
}

/// Free-form deformation on an L×M×N Bernstein lattice, as PyGeM's `FFD`.
///
/// `Ffd(n_control_points=(2, 2, 2), box_origin=(0, 0, 0), box_length=(1, 1, 1),
/// rot_angle=(0, 0, 0), face_tol=1e-12)`. The displacements `mu_x`, `mu_y`, `mu_z` are
/// (L, M, N) arrays in units of the box length (PyGeM's `array_mu_x` ...); assign a whole
/// array to change them (reading gives a copy). Points outside the closed box do not
/// move. Points on a face move like their neighbours inside: unit-box coordinates within
/// `face_tol` of the box count as on it (PyGeM tests strictly, which is `face_tol=0`).
#[pyclass(name = "Ffd", module = "cadmorph")]
#[derive(Clone)]
pub struct PyFfd {
    pub(crate) inner: Ffd,
    /// The face tolerance `inner` was built with (the Ffd keeps it private).
    pub(crate) face_tol: f64,
}

fn mu_array<'py>(py: Python<'py>, ffd: &Ffd, c: usize) -> Bound<'py, PyArray3<f64>> {
    let [l, m, n] = ffd.n_control_points();
    let v = match c {
        0 => ffd.mu().x.clone(),
        1 => ffd.mu().y.clone(),
        _ => ffd.mu().z.clone(),
    };
    Array3::from_shape_vec((l, m, n), v).expect("L·M·N values").into_pyarray(py)
}

fn set_mu_component(ffd: &mut Ffd, c: usize, value: &Bound<'_, PyAny>, name: &str) -> PyResult<()> {
    let arr: PyReadonlyArray3<'_, f64> = value
        .extract()
        .map_err(|_| PyTypeError::new_err(format!("{name} must be a float64 numpy array of shape (L, M, N)")))?;
    let shape = ffd.n_control_points();
    if arr.shape() != shape {
        return Err(PyValueError::new_err(format!("{name} must have shape {shape:?}, got {:?}", arr.shape())));
    }
    let values: Vec<f64> = arr.as_array().iter().copied().collect();
    if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!("{name} must be finite, found {bad}")));
    }
    let mu = ffd.mu_mut();
    match c {
        0 => mu.x = values,
        1 => mu.y = values,
        _ => mu.z = values,
    }
    Ok(())
}

#[pymethods]
impl PyFfd {
    #[new]
    #[pyo3(signature = (n_control_points = (2, 2, 2), box_origin = None, box_length = None, rot_angle = None, face_tol = FACE_TOL))]
    fn new(
        n_control_points: (usize, usize, usize),
        box_origin: Option<&Bound<'_, PyAny>>,
        box_length: Option<&Bound<'_, PyAny>>,
        rot_angle: Option<&Bound<'_, PyAny>>,
        face_tol: f64,
    ) -> PyResult<Self> {
        let o = box_origin.map(|o| three(o, "box_origin")).transpose()?.unwrap_or([0.0; 3]);
        let l = box_length.map(|o| three(o, "box_length")).transpose()?.unwrap_or([1.0; 3]);
        let r = rot_angle.map(|o| three(o, "rot_angle")).transpose()?.unwrap_or([0.0; 3]);
        if !(face_tol.is_finite() && face_tol >= 0.0) {
            return Err(PyValueError::new_err(format!("face_tol must be finite and >= 0, got {face_tol}")));
        }
        let (a, b, c) = n_control_points;
        let ffd = Ffd::try_new([a, b, c], Point3::from(o), Vector3::from(l), Vector3::from(r))
            .map_err(|e| morph_err(e, None))?
            .with_face_tol(face_tol);
        Ok(PyFfd { inner: ffd, face_tol })
    }

    /// Lattice size (L, M, N).
    #[getter]
    fn n_control_points(&self) -> (usize, usize, usize) {
        let [l, m, n] = self.inner.n_control_points();
        (l, m, n)
    }

    /// Box origin (the lattice node (0, 0, 0) and the centre of rotation).
    #[getter]
    fn box_origin<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        vec3(py, self.inner.box_origin().coords)
    }

    #[setter]
    fn set_box_origin(&mut self, v: &Bound<'_, PyAny>) -> PyResult<()> {
        let o = three(v, "box_origin")?;
        let (l, r) = (self.inner.box_length(), self.inner.rot_angle());
        self.inner.set_box(Point3::from(o), l, r).map_err(|e| morph_err(e, None))
    }

    /// Box lengths along the rotated box axes.
    #[getter]
    fn box_length<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        vec3(py, self.inner.box_length())
    }

    #[setter]
    fn set_box_length(&mut self, v: &Bound<'_, PyAny>) -> PyResult<()> {
        let l = three(v, "box_length")?;
        let (o, r) = (self.inner.box_origin(), self.inner.rot_angle());
        self.inner.set_box(o, Vector3::from(l), r).map_err(|e| morph_err(e, None))
    }

    /// Rotation angles about x, y, z in degrees (R = Rx·Ry·Rz, as PyGeM).
    #[getter]
    fn rot_angle<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        vec3(py, self.inner.rot_angle())
    }

    #[setter]
    fn set_rot_angle(&mut self, v: &Bound<'_, PyAny>) -> PyResult<()> {
        let r = three(v, "rot_angle")?;
        let (o, l) = (self.inner.box_origin(), self.inner.box_length());
        self.inner.set_box(o, l, Vector3::from(r)).map_err(|e| morph_err(e, None))
    }

    /// Displacements along the box x axis, an (L, M, N) array (a copy; assign to change).
    #[getter]
    fn mu_x<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        mu_array(py, &self.inner, 0)
    }

    #[setter]
    fn set_mu_x(&mut self, v: &Bound<'_, PyAny>) -> PyResult<()> {
        set_mu_component(&mut self.inner, 0, v, "mu_x")
    }

    /// Displacements along the box y axis, an (L, M, N) array.
    #[getter]
    fn mu_y<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        mu_array(py, &self.inner, 1)
    }

    #[setter]
    fn set_mu_y(&mut self, v: &Bound<'_, PyAny>) -> PyResult<()> {
        set_mu_component(&mut self.inner, 1, v, "mu_y")
    }

    /// Displacements along the box z axis, an (L, M, N) array.
    #[getter]
    fn mu_z<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f64>> {
        mu_array(py, &self.inner, 2)
    }

    #[setter]
    fn set_mu_z(&mut self, v: &Bound<'_, PyAny>) -> PyResult<()> {
        set_mu_component(&mut self.inner, 2, v, "mu_z")
    }

    /// Unit-box tolerance within which points outside the box count as on its faces.
    #[getter]
    fn face_tol(&self) -> f64 {
        self.face_tol
    }

    /// The lattice control points, (L·M·N, 3), C order of (i, j, k): deformed (P + μ) or not.
    #[pyo3(signature = (deformed = true))]
    fn control_points<'py>(&self, py: Python<'py>, deformed: bool) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_to_array(py, &self.inner.control_points(deformed))
    }

    /// The deformed copy of `points` ((n, 3) float64, C-contiguous); with `out`, the result
    /// is written there (`out=points` morphs in place) and `out` is returned.
    ///
    /// A NaN or infinite coordinate raises `ValueError` naming it. The new array or another
    /// `out` is then not returned; in place (`out=points`) the check is part of the morph
    /// (no second pass over memory): the non-finite points stay as they were, and the FFD
    /// has moved every finite point when the error is raised (the other morphs, checked
    /// in chunks of 2048 points, leave the chunks holding a bad value unmoved).
    #[pyo3(signature = (points, out = None))]
    fn deform<'py>(&self, points: &Bound<'py, PyAny>, out: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
        apply(&Morph::Ffd(self.inner.clone()), points, out)
    }

    /// `ffd(points)` is `ffd.deform(points)`.
    #[pyo3(signature = (points, out = None))]
    fn __call__<'py>(
        &self,
        points: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.deform(points, out)
    }

    /// The Jacobian ∂φ/∂x at one point, a (3, 3) array.
    fn jacobian<'py>(&self, py: Python<'py>, point: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        jacobian_of(py, &Morph::Ffd(self.inner.clone()), point)
    }

    /// This deformation followed by `next`.
    fn then(&self, next: &Bound<'_, PyAny>) -> PyResult<PyComposed> {
        then(Morph::Ffd(self.inner.clone()), next)
    }

    /// The PyGeM `.prm` text (byte-identical to PyGeM's `write_parameters`).
    fn to_prm(&self) -> String {
        self.inner.to_prm()
    }

    /// The TOML form.
    fn to_toml(&self) -> String {
        Parameters::Ffd(self.inner.clone()).to_toml()
    }

    /// Writes the parameters: TOML when `path` ends in `.toml`, else PyGeM's `.prm`.
    fn write_parameters(&self, path: PathBuf) -> PyResult<()> {
        write_params(&Parameters::Ffd(self.inner.clone()), &path)
    }

    /// Reads an FFD `.prm` text.
    #[staticmethod]
    fn from_prm(text: &str) -> PyResult<Self> {
        Ffd::from_prm(text).map(|inner| PyFfd { inner, face_tol: FACE_TOL }).map_err(|e| morph_err(e, None))
    }

    fn __repr__(&self) -> String {
        let [l, m, n] = self.inner.n_control_points();
        let o = self.inner.box_origin();
        let b = self.inner.box_length();
        let r = self.inner.rot_angle();
        format!(
            "Ffd(n_control_points=({l}, {m}, {n}), box_origin=({}, {}, {}), box_length=({}, {}, {}), rot_angle=({}, {}, {}))",
            o.x, o.y, o.z, b.x, b.y, b.z, r.x, r.y, r.z
        )
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<PyFfd>().map(|o| o.borrow().inner == self.inner).unwrap_or(false)
    }
}

fn jacobian_of<'py>(py: Python<'py>, m: &Morph, point: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let p = Point3::from(three(point, "point")?);
    match m.jacobian(&p) {
        Some(j) => {
            let rows: Vec<Vec<f64>> = (0..3).map(|r| (0..3).map(|c| j[(r, c)]).collect()).collect();
            Ok(PyArray2::from_vec2(py, &rows).map_err(|e| PyValueError::new_err(e.to_string()))?.into_any())
        }
        None => Ok(py.None().into_bound(py)),
    }
}

fn kernel_of(name: &str, radius: f64, k: Option<u32>) -> PyResult<Kernel> {
    let kernel = Kernel::from_name(name, radius, k).ok_or_else(|| {
        if Kernel::from_name(name, radius, None).is_some() {
            PyValueError::new_err(format!("k: the kernel {name:?} takes no power k"))
        } else {
            PyValueError::new_err(format!("kernel: unknown {name:?} (known: {})", Kernel::NAMES.join(", ")))
        }
    })?;
    Ok(kernel)
}

fn displacements(orig: &[Point3<f64>], def: &[Point3<f64>]) -> PyResult<Vec<Vector3<f64>>> {
    if orig.len() != def.len() {
        return Err(PyValueError::new_err(format!(
            "deformed_control_points must have as many rows as original_control_points ({}), got {}",
            orig.len(),
            def.len()
        )));
    }
    Ok(orig.iter().zip(def).map(|(a, b)| b - a).collect())
}

/// Radial basis function interpolation of control-point displacements (PyGeM's `RBF`).
///
/// `Rbf(original_control_points, deformed_control_points, kernel="thin_plate_spline",
/// radius=0.5, k=None)`: both (n, 3) float64 arrays; `kernel` is any of PyGeM's six
/// names or `wendland_c0`, `wendland_c2`, `wendland_c4` (compact support `radius`); `k`
/// is the power of `thin_plate_spline` and `polyharmonic_spline` (default 2). The system
/// is solved once, here (GIL released); a singular or ill-conditioned one raises
/// `ParameterError` with its condition estimate.
#[pyclass(name = "Rbf", module = "cadmorph")]
pub struct PyRbf {
    pub(crate) inner: Arc<Rbf>,
}

#[pymethods]
impl PyRbf {
    #[new]
    #[pyo3(signature = (original_control_points, deformed_control_points, kernel = "thin_plate_spline", radius = 0.5, k = None))]
    fn new(
        py: Python<'_>,
        original_control_points: &Bound<'_, PyAny>,
        deformed_control_points: &Bound<'_, PyAny>,
        kernel: &str,
        radius: f64,
        k: Option<u32>,
    ) -> PyResult<Self> {
        let orig = points_vec(original_control_points, "original_control_points")?;
        let def = points_vec(deformed_control_points, "deformed_control_points")?;
        let d = displacements(&orig, &def)?;
        let kernel = kernel_of(kernel, radius, k)?;
        let rbf = py.detach(|| Rbf::try_new(&orig, &d, kernel)).map_err(|e| morph_err(e, None))?;
        Ok(PyRbf { inner: Arc::new(rbf) })
    }

    /// The kernel's name.
    #[getter]
    fn kernel(&self) -> &'static str {
        self.inner.kernel().name()
    }

    /// The kernel's scaling (or support) radius.
    #[getter]
    fn radius(&self) -> f64 {
        self.inner.kernel().radius()
    }

    /// The power k of `thin_plate_spline` and `polyharmonic_spline`, else None.
    #[getter]
    fn k(&self) -> Option<u32> {
        self.inner.kernel().k()
    }

    /// The control points before the deformation, (n, 3).
    #[getter]
    fn original_control_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_to_array(py, self.inner.centres())
    }

    /// The control points after the deformation, (n, 3).
    #[getter]
    fn deformed_control_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let p: Vec<Point3<f64>> =
            self.inner.centres().iter().zip(self.inner.displacements()).map(|(c, d)| c + d).collect();
        points_to_array(py, &p)
    }

    /// The 1-norm condition estimate of the solved system.
    #[getter]
    fn condition(&self) -> f64 {
        self.inner.condition()
    }

    /// The weights in PyGeM's layout (`RBF.weights`): (n + 4, 3), the kernel weights then
    /// the constant and linear terms.
    fn pygem_weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let w = self.inner.pygem_weights();
        to_array(py, w.iter().flat_map(|r| r.iter().copied()).collect())
    }

    /// The deformed copy of `points`; see `Ffd.deform`.
    #[pyo3(signature = (points, out = None))]
    fn deform<'py>(&self, points: &Bound<'py, PyAny>, out: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
        apply(&Morph::Rbf(self.inner.clone()), points, out)
    }

    /// `rbf(points)` is `rbf.deform(points)`.
    #[pyo3(signature = (points, out = None))]
    fn __call__<'py>(
        &self,
        points: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.deform(points, out)
    }

    /// The Jacobian at one point, (3, 3), or None where the kernel has a corner.
    fn jacobian<'py>(&self, py: Python<'py>, point: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        jacobian_of(py, &Morph::Rbf(self.inner.clone()), point)
    }

    /// This deformation followed by `next`.
    fn then(&self, next: &Bound<'_, PyAny>) -> PyResult<PyComposed> {
        then(Morph::Rbf(self.inner.clone()), next)
    }

    /// The PyGeM `.prm` text.
    fn to_prm(&self) -> String {
        self.inner.parameters().to_prm()
    }

    /// The TOML form.
    fn to_toml(&self) -> String {
        Parameters::Rbf(self.inner.parameters()).to_toml()
    }

    /// Writes the parameters: TOML when `path` ends in `.toml`, else PyGeM's `.prm`.
    fn write_parameters(&self, path: PathBuf) -> PyResult<()> {
        write_params(&Parameters::Rbf(self.inner.parameters()), &path)
    }

    /// Reads an RBF `.prm` text and solves it.
    #[staticmethod]
    fn from_prm(py: Python<'_>, text: &str) -> PyResult<Self> {
        let p = RbfParameters::from_prm(text).map_err(|e| morph_err(e, None))?;
        let rbf = py.detach(|| Rbf::from_parameters(&p)).map_err(|e| morph_err(e, None))?;
        Ok(PyRbf { inner: Arc::new(rbf) })
    }

    fn __repr__(&self) -> String {
        format!(
            "Rbf(kernel={:?}, radius={}, n_control_points={})",
            self.kernel(),
            self.radius(),
            self.inner.centres().len()
        )
    }
}

/// Inverse distance weighting of control-point displacements.
///
/// `Idw(original_control_points, deformed_control_points, power=2, variant="paper",
/// cutoff=None)`. `variant="paper"` is the paper's eq. (7)–(8) (Euclidean distance, weight
/// d⁻ᵖ, optional cutoff radius); `variant="pygem"` is what PyGeM's `IDW` computes (distance
/// in the Minkowski p-norm, weight 1/d; integer power, no cutoff), which reading a PyGeM
/// `.prm` file selects.
#[pyclass(name = "Idw", module = "cadmorph")]
pub struct PyIdw {
    pub(crate) inner: Arc<Idw>,
}

#[pymethods]
impl PyIdw {
    #[new]
    #[pyo3(signature = (original_control_points, deformed_control_points, power = 2.0, variant = "paper", cutoff = None))]
    fn new(
        original_control_points: &Bound<'_, PyAny>,
        deformed_control_points: &Bound<'_, PyAny>,
        power: f64,
        variant: &str,
        cutoff: Option<f64>,
    ) -> PyResult<Self> {
        let orig = points_vec(original_control_points, "original_control_points")?;
        let def = points_vec(deformed_control_points, "deformed_control_points")?;
        let d = displacements(&orig, &def)?;
        let variant = match variant {
            "paper" => IdwVariant::Paper { power, cutoff },
            "pygem" => {
                if cutoff.is_some() {
                    return Err(PyValueError::new_err("cutoff: the pygem variant takes no cutoff"));
                }
                if !(power.fract() == 0.0 && (1.0..=64.0).contains(&power)) {
                    return Err(PyValueError::new_err(format!(
                        "power: the pygem variant needs an integer power in 1..=64, got {power}"
                    )));
                }
                IdwVariant::PyGem { power: power as u32 }
            }
            other => {
                return Err(PyValueError::new_err(format!("variant must be \"paper\" or \"pygem\", got {other:?}")))
            }
        };
        let idw = Idw::try_new(&orig, &d, variant).map_err(|e| morph_err(e, None))?;
        Ok(PyIdw { inner: Arc::new(idw) })
    }

    /// "paper" or "pygem".
    #[getter]
    fn variant(&self) -> &'static str {
        match self.inner.variant() {
            IdwVariant::Paper { .. } => "paper",
            IdwVariant::PyGem { .. } => "pygem",
        }
    }

    /// The power p.
    #[getter]
    fn power(&self) -> f64 {
        match self.inner.variant() {
            IdwVariant::Paper { power, .. } => power,
            IdwVariant::PyGem { power } => power as f64,
        }
    }

    /// The cutoff radius (paper variant), or None.
    #[getter]
    fn cutoff(&self) -> Option<f64> {
        match self.inner.variant() {
            IdwVariant::Paper { cutoff, .. } => cutoff,
            IdwVariant::PyGem { .. } => None,
        }
    }

    /// The control points before the deformation, (n, 3).
    #[getter]
    fn original_control_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_to_array(py, self.inner.centres())
    }

    /// The control points after the deformation, (n, 3).
    #[getter]
    fn deformed_control_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let p: Vec<Point3<f64>> =
            self.inner.centres().iter().zip(self.inner.displacements()).map(|(c, d)| c + d).collect();
        points_to_array(py, &p)
    }

    /// The deformed copy of `points`; see `Ffd.deform`.
    #[pyo3(signature = (points, out = None))]
    fn deform<'py>(&self, points: &Bound<'py, PyAny>, out: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
        apply(&Morph::Idw(self.inner.clone()), points, out)
    }

    /// `idw(points)` is `idw.deform(points)`.
    #[pyo3(signature = (points, out = None))]
    fn __call__<'py>(
        &self,
        points: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.deform(points, out)
    }

    /// The Jacobian at one point, (3, 3), or None where it does not exist.
    fn jacobian<'py>(&self, py: Python<'py>, point: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        jacobian_of(py, &Morph::Idw(self.inner.clone()), point)
    }

    /// This deformation followed by `next`.
    fn then(&self, next: &Bound<'_, PyAny>) -> PyResult<PyComposed> {
        then(Morph::Idw(self.inner.clone()), next)
    }

    /// The PyGeM `.prm` text (pygem variant only; the paper's has no `.prm` form).
    fn to_prm(&self) -> PyResult<String> {
        self.inner.parameters().to_prm().map_err(|e| morph_err(e, None))
    }

    /// The TOML form.
    fn to_toml(&self) -> String {
        Parameters::Idw(self.inner.parameters()).to_toml()
    }

    /// Writes the parameters: TOML when `path` ends in `.toml`, else PyGeM's `.prm`.
    fn write_parameters(&self, path: PathBuf) -> PyResult<()> {
        write_params(&Parameters::Idw(self.inner.parameters()), &path)
    }

    /// Reads an IDW `.prm` text (the pygem variant).
    #[staticmethod]
    fn from_prm(text: &str) -> PyResult<Self> {
        let p = IdwParameters::from_prm(text).map_err(|e| morph_err(e, None))?;
        let idw = Idw::from_parameters(&p).map_err(|e| morph_err(e, None))?;
        Ok(PyIdw { inner: Arc::new(idw) })
    }

    fn __repr__(&self) -> String {
        format!(
            "Idw(variant={:?}, power={}, n_control_points={})",
            self.variant(),
            self.power(),
            self.inner.centres().len()
        )
    }
}

/// An affine map `x ↦ A x + t`.
///
/// `Affine(matrix=None, translation=None)` (identity and zero by default); also
/// `Affine.translation(t)`, `Affine.scaling(s)`, `Affine.rotation(angles_deg)` (R = Rx·Ry·Rz).
#[pyclass(name = "Affine", module = "cadmorph")]
pub struct PyAffine {
    pub(crate) inner: Affine,
}

#[pymethods]
impl PyAffine {
    #[new]
    #[pyo3(signature = (matrix = None, translation = None))]
    fn new(matrix: Option<&Bound<'_, PyAny>>, translation: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let a = match matrix {
            Some(m) => {
                let rows: Vec<Vec<f64>> =
                    m.extract().map_err(|_| PyTypeError::new_err("matrix must be a 3x3 array of numbers"))?;
                if rows.len() != 3 || rows.iter().any(|r| r.len() != 3) {
                    return Err(PyValueError::new_err("matrix must have shape (3, 3)"));
                }
                if rows.iter().flatten().any(|v| !v.is_finite()) {
                    return Err(PyValueError::new_err("matrix must be finite"));
                }
                Matrix3::from_fn(|r, c| rows[r][c])
            }
            None => Matrix3::identity(),
        };
        let t = translation.map(|t| three(t, "translation")).transpose()?.unwrap_or([0.0; 3]);
        Ok(PyAffine { inner: Affine::new(a, Vector3::from(t)) })
    }

    /// A translation by `t`.
    #[staticmethod]
    fn translation(t: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(PyAffine { inner: Affine::translation(Vector3::from(three(t, "t")?)) })
    }

    /// A scaling by `s` along x, y, z about the origin.
    #[staticmethod]
    fn scaling(s: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(PyAffine { inner: Affine::scaling(Vector3::from(three(s, "s")?)) })
    }

    /// A rotation about the origin by angles in degrees about x, y, z (R = Rx·Ry·Rz).
    #[staticmethod]
    fn rotation(angles_deg: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(PyAffine { inner: Affine::rotation_degrees(Vector3::from(three(angles_deg, "angles_deg")?)) })
    }

    /// The linear part A, (3, 3).
    #[getter]
    fn matrix<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        jacobian_of(py, &Morph::Affine(self.inner), &vec![0.0f64, 0.0, 0.0].into_pyobject(py)?.into_any())
    }

    /// The translation t.
    #[getter]
    fn translation_vector<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        vec3(py, self.inner.deform_point(&Point3::origin()).coords)
    }

    /// The deformed copy of `points`; see `Ffd.deform`.
    #[pyo3(signature = (points, out = None))]
    fn deform<'py>(&self, points: &Bound<'py, PyAny>, out: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
        apply(&Morph::Affine(self.inner), points, out)
    }

    /// `a(points)` is `a.deform(points)`.
    #[pyo3(signature = (points, out = None))]
    fn __call__<'py>(
        &self,
        points: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.deform(points, out)
    }

    /// This map followed by `next`.
    fn then(&self, next: &Bound<'_, PyAny>) -> PyResult<PyComposed> {
        then(Morph::Affine(self.inner), next)
    }

    /// The inverse map, or None when A is singular.
    fn inverse(&self) -> Option<Self> {
        self.inner.try_inverse().map(|inner| PyAffine { inner })
    }
}

/// Deformations applied one after the other (made by `compose(a, b, ...)` or `a.then(b)`).
#[pyclass(name = "Composed", module = "cadmorph")]
pub struct PyComposed {
    pub(crate) inner: Morph,
}

#[pymethods]
impl PyComposed {
    /// How many deformations are chained.
    fn __len__(&self) -> usize {
        match &self.inner {
            Morph::Chain(v) => v.len(),
            _ => 1,
        }
    }

    /// The deformed copy of `points`; see `Ffd.deform`.
    #[pyo3(signature = (points, out = None))]
    fn deform<'py>(&self, points: &Bound<'py, PyAny>, out: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
        apply(&self.inner, points, out)
    }

    /// `c(points)` is `c.deform(points)`.
    #[pyo3(signature = (points, out = None))]
    fn __call__<'py>(
        &self,
        points: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.deform(points, out)
    }

    /// The Jacobian at one point by the chain rule, or None when a stage has none.
    fn jacobian<'py>(&self, py: Python<'py>, point: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        jacobian_of(py, &self.inner, point)
    }

    /// This chain followed by `next`.
    fn then(&self, next: &Bound<'_, PyAny>) -> PyResult<PyComposed> {
        then(self.inner.clone(), next)
    }
}

/// A deformation given by a Python function `f(points) -> points` on (n, 3) float64 arrays
/// (PyGeM's `CustomDeformation`, vectorised). It runs with the GIL held, on one thread; an
/// exception it raises is re-raised by the call that applied it.
#[pyclass(name = "FromFunction", module = "cadmorph")]
pub struct PyFromFunction {
    pub(crate) inner: Morph,
}

#[pymethods]
impl PyFromFunction {
    #[new]
    fn new(func: Py<PyAny>, py: Python<'_>) -> PyResult<Self> {
        if !func.bind(py).is_callable() {
            return Err(PyTypeError::new_err("func must be callable: f(points) -> points"));
        }
        Ok(PyFromFunction {
            inner: Morph::Function(PyFunction { func: Arc::new(func), error: Arc::new(Mutex::new(None)) }),
        })
    }

    /// The deformed copy of `points`; see `Ffd.deform`.
    #[pyo3(signature = (points, out = None))]
    fn deform<'py>(&self, points: &Bound<'py, PyAny>, out: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
        apply(&self.inner, points, out)
    }

    /// `f(points)` is `f.deform(points)`.
    #[pyo3(signature = (points, out = None))]
    fn __call__<'py>(
        &self,
        points: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.deform(points, out)
    }

    /// This deformation followed by `next`.
    fn then(&self, next: &Bound<'_, PyAny>) -> PyResult<PyComposed> {
        then(self.inner.clone(), next)
    }
}

/// An `Ffd` from its box and three (L, M, N) displacement arrays in one call (what the
/// PyGeM layer builds from its attributes for each call).
#[pyfunction]
pub(crate) fn ffd_with_mu(
    n_control_points: (usize, usize, usize),
    box_origin: &Bound<'_, PyAny>,
    box_length: &Bound<'_, PyAny>,
    rot_angle: &Bound<'_, PyAny>,
    mu_x: &Bound<'_, PyAny>,
    mu_y: &Bound<'_, PyAny>,
    mu_z: &Bound<'_, PyAny>,
    face_tol: f64,
) -> PyResult<PyFfd> {
    let mut f = PyFfd::new(n_control_points, Some(box_origin), Some(box_length), Some(rot_angle), face_tol)?;
    set_mu_component(&mut f.inner, 0, mu_x, "array_mu_x")?;
    set_mu_component(&mut f.inner, 1, mu_y, "array_mu_y")?;
    set_mu_component(&mut f.inner, 2, mu_z, "array_mu_z")?;
    Ok(f)
}
