//! Test support for cadmorph: sample loader, OCCT reference data, `assert_near!`,
//! proptest strategies. Only ever a dev-dependency.
//!
//! ```
//! let path = cadmorph_testkit::sample("hull3.igs");
//! assert!(path.exists());
//! ```

use std::path::PathBuf;

pub mod occt;
pub mod strategies;

/// Path of a file in the repository's `samples/` folder.
pub fn sample(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples").join(name)
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
