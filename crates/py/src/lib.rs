//! Python bindings of cadmorph (PyO3): the extension module `cadmorph._native`, which the
//! pure-Python package `cadmorph` (in `python/cadmorph/`) re-exports.
//!
//! Everything the module does is a call into the Rust crates (`cadmorph-morph` for the
//! deformations and parameter files, `cadmorph-model` through the facade for CAD files);
//! this crate only converts arguments and results:
//!
//! - points are `(n, 3)` C-contiguous `float64` numpy arrays, read in place (no copy) and
//!   returned as one new array whose buffer is the morph's own output; with `out=` the
//!   result is written into a given array (`out=points` morphs in place). The GIL is
//!   released while a native morph runs, and rayon's pool does the work (its size follows
//!   `RAYON_NUM_THREADS`, or `cadmorph.set_num_threads(n)` before the first morph);
//! - a bad argument raises `TypeError` (not an array, wrong dtype) or `ValueError` (shape,
//!   contiguity, NaN or infinity) naming the argument; errors from files raise
//!   `ParameterError` / `CadFileError` (both `ValueError`s) carrying `path`, `line` and
//!   `entity`, and `OSError` for the file system. A panic in Rust becomes a Python
//!   `PanicException`, never an abort.
//!
//! Build with maturin (`pip install .` at the repository root, whose `pyproject.toml`
//! points here); `cargo test -p cadmorph-py` builds the same code as an rlib linked to
//! the interpreter for the Rust tests.

mod arrays;
mod errors;
mod model;
mod morphs;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Sets the number of rayon worker threads (call it before the first morph; the pool is
/// built once per process). The calling thread becomes worker 0, as the `cadmorph` CLI
/// does, so that short parallel loops start on it instead of waking sleeping workers.
/// Returns False when the pool already exists (its size is then kept).
#[pyfunction]
#[pyo3(signature = (n = None))]
fn set_num_threads(n: Option<usize>) -> PyResult<bool> {
    if n == Some(0) {
        return Err(PyValueError::new_err("n must be at least 1 (or None for one per CPU)"));
    }
    let mut b = rayon::ThreadPoolBuilder::new().use_current_thread();
    if let Some(n) = n {
        b = b.num_threads(n);
    }
    Ok(b.build_global().is_ok())
}

/// The number of threads rayon's pool uses (building it with the defaults if needed).
#[pyfunction]
fn num_threads() -> usize {
    rayon::current_num_threads()
}

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("ParameterError", py.get_type::<errors::ParameterError>())?;
    m.add("CadFileError", py.get_type::<errors::CadFileError>())?;
    m.add_class::<morphs::PyFfd>()?;
    m.add_class::<morphs::PyRbf>()?;
    m.add_class::<morphs::PyIdw>()?;
    m.add_class::<morphs::PyAffine>()?;
    m.add_class::<morphs::PyComposed>()?;
    m.add_class::<morphs::PyFromFunction>()?;
    m.add_class::<model::PyModel>()?;
    m.add_function(wrap_pyfunction!(morphs::read_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(morphs::parameters_from_str, m)?)?;
    m.add_function(wrap_pyfunction!(morphs::compose, m)?)?;
    m.add_function(wrap_pyfunction!(morphs::ffd_with_mu, m)?)?;
    m.add_function(wrap_pyfunction!(model::open, m)?)?;
    m.add_function(wrap_pyfunction!(model::from_bytes, m)?)?;
    m.add_function(wrap_pyfunction!(set_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(num_threads, m)?)?;
    Ok(())
}
