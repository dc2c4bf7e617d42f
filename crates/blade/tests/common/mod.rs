//! Test helpers: a small `.npy` reader and the BladeX test-data folder.
#![allow(dead_code)]

use std::path::PathBuf;

/// `samples/blade/bladex/NAME` (copied from BladeX's `tests/test_datasets`).
pub fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples/blade/bladex").join(name)
}

/// A little-endian float64 `.npy` array: its shape and values in C order.
pub fn npy(name: &str) -> (Vec<usize>, Vec<f64>) {
    let bytes = std::fs::read(data(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(&bytes[..6], b"\x93NUMPY", "{name}: not an npy file");
    let (hlen, start) = if bytes[6] == 1 {
        (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10)
    } else {
        (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12)
    };
    let header = std::str::from_utf8(&bytes[start..start + hlen]).unwrap();
    assert!(header.contains("'descr': '<f8'"), "{name}: {header}");
    let fortran = header.contains("'fortran_order': True");
    let s = header.split("'shape': (").nth(1).unwrap();
    let s = &s[..s.find(')').unwrap()];
    let shape: Vec<usize> = s.split(',').map(str::trim).filter(|t| !t.is_empty()).map(|t| t.parse().unwrap()).collect();
    let body = &bytes[start + hlen..];
    let vals: Vec<f64> = body.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect();
    assert_eq!(vals.len(), shape.iter().product::<usize>(), "{name}");
    if fortran && shape.len() == 2 {
        // Column-major: element (i, j) at j * rows + i; return it in C order.
        let (r, c) = (shape[0], shape[1]);
        let t = (0..r * c).map(|k| vals[(k % c) * r + k / c]).collect();
        return (shape, t);
    }
    assert!(!fortran || shape.len() < 2, "{name}: Fortran order of rank {}", shape.len());
    (shape, vals)
}

/// Largest absolute difference, with the lengths checked.
pub fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}
