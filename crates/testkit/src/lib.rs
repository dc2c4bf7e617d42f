//! Test support for cadmorph: sample loader, OCCT reference data, `assert_near!`,
//! proptest strategies. Only ever a dev-dependency.
//!
//! ```
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/hull3.igs");
//! assert!(path.exists());
//! ```

use std::path::{Path, PathBuf};

pub mod occt;
pub mod refdata;
pub mod strategies;

/// Path of a file in the repository's `samples/` folder.
pub fn sample(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples").join(name)
}

/// Path of a defect reproducer in the repository's `tests/repro/` folder.
pub fn repro(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/repro").join(name)
}

/// Names of the files in `samples/` ending in `suffix`, sorted.
pub fn samples_with_suffix(suffix: &str) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(sample(""))
        .expect("samples/ is readable")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(suffix))
        .collect();
    names.sort();
    names
}

/// Asserts that two points or vectors are within `tol` of each other (Euclidean),
/// printing both and the distance otherwise.
///
/// ```
/// use nalgebra::Point3;
/// cadmorph_testkit::assert_near!(Point3::new(1.0, 2.0, 3.0), Point3::new(1.0, 2.0, 3.0 + 1e-13), 1e-12);
/// ```
#[macro_export]
macro_rules! assert_near {
    ($a:expr, $b:expr, $tol:expr $(, $($msg:tt)+)?) => {{
        let (a, b, tol) = (&$a, &$b, $tol);
        let d = (a - b).norm();
        if !(d <= tol) {
            panic!(
                "assert_near failed: |{:?} - {:?}| = {:e} > {:e}{}",
                a, b, d, tol, { let _m = String::new(); $( let _m = format!(": {}", format_args!($($msg)+)); )? _m }
            );
        }
    }};
}

/// `n × n` parameter pairs covering the surface domain, ends included, plus every
/// distinct interior knot value in each direction.
pub fn grid(s: &cadmorph_nurbs::NurbsSurface, n: usize) -> Vec<(f64, f64)> {
    use cadmorph_nurbs::Surface;
    let (ud, vd) = s.domain();
    let axis = |d: std::ops::RangeInclusive<f64>, knots: &cadmorph_nurbs::KnotVector| {
        let (a, b) = (*d.start(), *d.end());
        let mut t: Vec<f64> = (0..n).map(|i| a + (b - a) * i as f64 / (n - 1) as f64).collect();
        t.extend(knots.distinct().0.into_iter().filter(|&k| k > a && k < b));
        t
    };
    let us = axis(ud, s.u_knots());
    let vs = axis(vd, s.v_knots());
    us.iter().flat_map(|&u| vs.iter().map(move |&v| (u, v))).collect()
}

/// The OCCT oracle harness (`tests/occt/occt_ref.py`) run by the venv's Python.
///
/// Tests that use it are `#[ignore = "needs the OCCT venv (bash tests/occt/setup.sh)"]`
/// and run by `scripts/test`; a missing venv makes them fail with that instruction.
pub mod harness {
    use std::path::{Path, PathBuf};
    use std::process::Command;

    /// The repository root.
    pub fn root() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
    }

    /// The venv's Python.
    ///
    /// # Panics
    ///
    /// If the venv is missing, with the command that makes it.
    pub fn python() -> PathBuf {
        let py = root().join("tests/occt/.venv/bin/python");
        assert!(py.exists(), "the OCCT venv is missing: run `bash tests/occt/setup.sh` (or `bash scripts/test`)");
        py
    }

    /// Runs `occt_ref.py ARGS...` and parses its JSON output; returns the exit code too.
    ///
    /// # Panics
    ///
    /// If the harness cannot be started or prints no JSON.
    pub fn run(args: &[&str]) -> (i32, serde_json::Value) {
        let out = Command::new(python())
            .arg(root().join("tests/occt/occt_ref.py"))
            .args(args)
            .output()
            .expect("occt_ref.py starts");
        let code = out.status.code().unwrap_or(-1);
        let json = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
            panic!(
                "occt_ref.py {args:?} exited {code} without JSON ({e}); stderr:\n{}",
                String::from_utf8_lossy(&out.stderr)
            )
        });
        (code, json)
    }

    /// `occt_ref.py validate FILE [--eval REQUEST]`: OCCT's read status, validity and
    /// (with a request) its evaluation of each face.
    pub fn validate(file: &Path, eval_request: Option<&Path>) -> (i32, serde_json::Value) {
        let f = file.to_string_lossy().into_owned();
        let mut args = vec!["validate", f.as_str()];
        let r;
        if let Some(req) = eval_request {
            r = req.to_string_lossy().into_owned();
            args.extend(["--eval", r.as_str()]);
        }
        run(&args)
    }

    /// What OCCT measures of a solid (`tests/occt/planing_hull.py volume`).
    #[derive(Debug, Clone, PartialEq)]
    pub struct SolidProperties {
        /// `BRepCheck_Analyzer` finds the shape valid.
        pub valid: bool,
        /// `BRepGProp::VolumeProperties` over every solid (sewn from the faces when the
        /// file has none), Eps 1e-12.
        pub volume: f64,
        /// The first solid's centre of mass.
        pub centre: [f64; 3],
        /// `BRepGProp::SurfaceProperties` of every face, Eps 1e-12.
        pub area: f64,
        /// Solids found or sewn.
        pub solids: usize,
    }

    /// OCCT's validity, volume, centre of mass and face area of the shape in `file`
    /// (faces without a solid sewn at 1e-6 model units).
    ///
    /// # Panics
    ///
    /// If the script cannot start or does not read the file.
    pub fn solid_properties(file: &Path) -> SolidProperties {
        solid_properties_sewn(file, 1e-6)
    }

    /// [`solid_properties`] sewing faces that come without a solid at `sew_tol` model
    /// units (for files whose seams are within a looser tolerance).
    ///
    /// # Panics
    ///
    /// As [`solid_properties`].
    pub fn solid_properties_sewn(file: &Path, sew_tol: f64) -> SolidProperties {
        let out = Command::new(python())
            .arg(root().join("tests/occt/planing_hull.py"))
            .arg("volume")
            .arg(file)
            .arg("--sew-tol")
            .arg(sew_tol.to_string())
            .output()
            .expect("planing_hull.py starts");
        let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
            panic!("planing_hull.py volume {}: no JSON ({e}): {}", file.display(), String::from_utf8_lossy(&out.stderr))
        });
        let f = |v: &serde_json::Value| v.as_f64().unwrap_or_else(|| panic!("{}: not a number in {j}", file.display()));
        let c = &j["solids"][0]["centre"];
        SolidProperties {
            valid: j["valid"] == true,
            volume: f(&j["volume"]),
            centre: if c.is_null() { [f64::NAN; 3] } else { [0, 1, 2].map(|k| f(&c[k])) },
            area: f(&j["area"]),
            solids: j["solids"].as_array().map_or(0, Vec::len),
        }
    }
}

/// The surface of the side-by-side NURBS benchmark (`benches/occt/README.md`): degree
/// 3 × 3, 10 × 10 poles `P[i][j] = (i, j, sin i · cos j)`, clamped uniform knots on [0, 1]².
pub fn occt_bench_surface() -> cadmorph_nurbs::NurbsSurface {
    use cadmorph_nurbs::{math::Point3, KnotVector, NurbsSurface};
    let pts = (0..10)
        .flat_map(|i| (0..10).map(move |j| Point3::new(i as f64, j as f64, (i as f64).sin() * (j as f64).cos())))
        .collect();
    let k = || KnotVector::clamped_uniform(3, 10);
    NurbsSurface::new((3, 3), (k(), k()), (10, 10), pts, None)
}

/// A scratch folder under the system's temporary folder, `cadmorph-<name>-<pid>`, made
/// empty when created and removed when dropped, also when the test fails and unwinds,
/// so tests leave nothing in `$TMPDIR`.
pub struct Scratch(PathBuf);

impl Scratch {
    /// A fresh, empty folder.
    ///
    /// # Panics
    ///
    /// When the folder cannot be made.
    pub fn new(name: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("cadmorph-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("a scratch folder");
        Scratch(d)
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.0
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
