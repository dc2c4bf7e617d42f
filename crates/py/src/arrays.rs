//! numpy arrays of points in and out: checked once, then read in place.
//!
//! An `(n, 3)` C-contiguous `float64` array is read through its own buffer (no copy); the
//! result is one new array whose buffer is the `Vec` the morph wrote (moved into numpy, not
//! copied). Anything else is refused with an exception naming the argument: `TypeError` for
//! a non-array or another dtype, `ValueError` for another shape, a non-contiguous array or
//! a non-finite value.

use cadmorph::morph::math::Point3;
use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray2, PyArrayDescrMethods, PyArrayMethods, PyReadonlyArray2, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// `obj` as a read-only view of an `(n, 3)` float64 C-contiguous array, or the exception
/// naming `name`. Finiteness is not checked here (see [`first_non_finite`]).
pub(crate) fn points_view<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<PyReadonlyArray2<'py, f64>> {
    let untyped = obj.cast::<PyUntypedArray>().map_err(|_| {
        let ty = obj.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into());
        PyTypeError::new_err(format!(
            "{name} must be a numpy.ndarray of shape (n, 3) and dtype float64, got {ty} (use numpy.asarray({name}, dtype=float))"
        ))
    })?;
    let dtype = untyped.dtype();
    if !dtype.is_equiv_to(&numpy::dtype::<f64>(obj.py())) {
        let shown = dtype.str().map(|s| s.to_string()).unwrap_or_else(|_| "?".into());
        return Err(PyTypeError::new_err(format!(
            "{name} must have dtype float64, got {shown} (use {name}.astype(numpy.float64))"
        )));
    }
    let shape = untyped.shape();
    if shape.len() != 2 || shape[1] != 3 {
        let shown: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
        let shown = if shown.len() == 1 { format!("({},)", shown[0]) } else { format!("({})", shown.join(", ")) };
        return Err(PyValueError::new_err(format!("{name} must have shape (n, 3), got {shown}")));
    }
    if !untyped.is_c_contiguous() {
        return Err(PyValueError::new_err(format!(
            "{name} must be C-contiguous (a transposed or strided view is not; use numpy.ascontiguousarray({name}))"
        )));
    }
    let typed =
        obj.cast::<PyArray2<f64>>().map_err(|_| PyTypeError::new_err(format!("{name}: not a float64 array")))?;
    typed.try_readonly().map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
}

/// The flat coordinates as points (a reinterpretation of the same memory).
pub(crate) fn as_points(flat: &[f64]) -> &[Point3<f64>] {
    bytemuck::cast_slice(flat)
}

/// The flat coordinates as points, mutable.
pub(crate) fn as_points_mut(flat: &mut [f64]) -> &mut [Point3<f64>] {
    bytemuck::cast_slice_mut(flat)
}

/// The first `(row, column)` whose value is NaN or infinite (`flat` holds whole points):
/// [`first_non_finite`](cadmorph::morph::first_non_finite)'s branch-free pass, then the
/// column of the point it names.
pub(crate) fn first_non_finite(flat: &[f64]) -> Option<(usize, usize)> {
    let i = cadmorph::morph::first_non_finite(as_points(flat))?;
    Some((i, (0..3).find(|&k| !flat[3 * i + k].is_finite()).unwrap_or(0)))
}

/// The `ValueError` for a non-finite input value.
pub(crate) fn non_finite_err(name: &str, at: (usize, usize), value: f64) -> PyErr {
    PyValueError::new_err(format!("{name}[{}, {}] is {value}: every coordinate must be finite", at.0, at.1))
}

/// A small `(n, 3)` array (control points, parameters) copied into points, checked like
/// [`points_view`] and for finiteness.
pub(crate) fn points_vec(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<Point3<f64>>> {
    let view = points_view(obj, name)?;
    let flat = view.as_slice().map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    if let Some(at) = first_non_finite(flat) {
        return Err(non_finite_err(name, at, flat[at.0 * 3 + at.1]));
    }
    Ok(as_points(flat).to_vec())
}

/// Points as a new `(n, 3)` array whose buffer is `flat` itself.
pub(crate) fn to_array(py: Python<'_>, flat: Vec<f64>) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let n = flat.len() / 3;
    let arr = Array2::from_shape_vec((n, 3), flat).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(arr.into_pyarray(py))
}

/// Points as a new `(n, 3)` array.
pub(crate) fn points_to_array<'py>(py: Python<'py>, pts: &[Point3<f64>]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    to_array(py, bytemuck::cast_slice::<Point3<f64>, f64>(pts).to_vec())
}

/// Three floats (a sequence or array of length 3), or a `ValueError`/`TypeError` naming `name`.
pub(crate) fn three(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 3]> {
    let v: Vec<f64> =
        obj.extract().map_err(|_| PyTypeError::new_err(format!("{name} must be a sequence of three numbers")))?;
    let a: [f64; 3] = v
        .as_slice()
        .try_into()
        .map_err(|_| PyValueError::new_err(format!("{name} must hold exactly three values, got {}", v.len())))?;
    if let Some(bad) = a.iter().find(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!("{name} must be finite, got {bad}")));
    }
    Ok(a)
}
