//! Helpers shared by the integration tests: sample paths, a NumPy `.npy` reader, PyGeM's
//! test grid.
#![allow(dead_code)]

use cadmorph_morph::math::Point3;
use std::path::PathBuf;

/// What PyGeM's own tests accept is 6 decimals; the issue asks for 1e-10 absolute.
pub const PYGEM_MATCH: f64 = 1e-10;

/// `samples/pygem/<name>` of the workspace.
pub fn sample(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples/pygem").join(name)
}

pub fn read_text(name: &str) -> String {
    std::fs::read_to_string(sample(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// A little-endian f64 C-order `.npy` array: `(shape, data)`.
pub fn read_npy(name: &str) -> (Vec<usize>, Vec<f64>) {
    let bytes = std::fs::read(sample(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(&bytes[..6], b"\x93NUMPY", "{name}: not an .npy file");
    let (header_len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 => (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12),
        v => panic!("{name}: npy version {v}"),
    };
    let header = std::str::from_utf8(&bytes[start..start + header_len]).unwrap();
    assert!(header.contains("'descr': '<f8'"), "{name}: {header}");
    assert!(header.contains("'fortran_order': False"), "{name}: {header}");
    let shape_txt = header.split("'shape': (").nth(1).unwrap().split(')').next().unwrap();
    let shape: Vec<usize> =
        shape_txt.split(',').filter(|s| !s.trim().is_empty()).map(|s| s.trim().parse().unwrap()).collect();
    let data: Vec<f64> =
        bytes[start + header_len..].chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect();
    assert_eq!(data.len(), shape.iter().product::<usize>(), "{name}");
    (shape, data)
}

/// An (n, 3) `.npy` array as points.
pub fn read_points(name: &str) -> Vec<Point3<f64>> {
    let (shape, data) = read_npy(name);
    assert_eq!(shape[1], 3);
    data.chunks_exact(3).map(|c| Point3::new(c[0], c[1], c[2])).collect()
}

/// PyGeM's test grid: `z, y, x = np.meshgrid(zv, yv, xv)` of `linspace(0, 1, 20)`, raveled:
/// x runs fastest, then z, then y.
pub fn cube_grid() -> Vec<Point3<f64>> {
    let n = 20;
    // numpy.linspace: start + i·step, with the last value set to stop exactly.
    let step = 1.0 / (n - 1) as f64;
    let v = |i: usize| if i == n - 1 { 1.0 } else { i as f64 * step };
    let mut out = Vec::with_capacity(n * n * n);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                out.push(Point3::new(v(k), v(i), v(j)));
            }
        }
    }
    out
}

pub fn max_abs_diff(a: &[Point3<f64>], b: &[Point3<f64>]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(p, q)| (p - q).amax()).fold(0.0, f64::max)
}

/// A full-precision value from `pygem_reference_points.txt` (PyGeM run on the same files).
pub fn pygem_reference(name: &str) -> Point3<f64> {
    let text = read_text("pygem_reference_points.txt");
    let line = text
        .lines()
        .find(|l| l.split_whitespace().next() == Some(name))
        .unwrap_or_else(|| panic!("no reference {name}"));
    let v: Vec<f64> = line.split_whitespace().skip(1).map(|t| t.parse().unwrap()).collect();
    Point3::new(v[0], v[1], v[2])
}
