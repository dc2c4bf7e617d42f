//! One-dimensional radial-basis interpolation with the Wendland C² kernel, as
//! `bladex.ndinterpolator.reconstruct_f(..., basis='beckert_wendland_c2_basis')`.

use nalgebra::{DMatrix, DVector};

use crate::linalg::solve_dense;
use crate::Result;

/// The Beckert–Wendland C² kernel `φ(r) = (1 − r/R)⁴₊ (4 r/R + 1)` (BladeX
/// `RBF.beckert_wendland_c2_basis`; paper §2.1 eq. (3)–(5) with this φ).
pub fn wendland_c2(r: f64, radius: f64) -> f64 {
    let a = r / radius;
    let first = if 1.0 - a > 0.0 { (1.0 - a).powi(4) } else { 0.0 };
    first * (4.0 * a + 1.0)
}

/// The interpolant through `(x, y)` evaluated at `at`: weights from
/// `Φ(x, x) w = y`, values `Φ(at, x) w` (BladeX `reconstruct_f`).
///
/// # Errors
///
/// [`crate::Error::Singular`] when the kernel matrix is singular (repeated `x`).
pub fn reconstruct(x: &[f64], y: &[f64], at: &[f64], radius: f64) -> Result<Vec<f64>> {
    let n = x.len();
    let phi = DMatrix::from_fn(n, n, |i, j| wendland_c2((x[i] - x[j]).abs(), radius));
    let w = solve_dense(phi, &DVector::from_column_slice(y), "Wendland RBF weights")?;
    Ok(at
        .iter()
        .map(|&t| {
            let mut s = 0.0;
            for j in 0..n {
                s += w[j] * wendland_c2((t - x[j]).abs(), radius);
            }
            s
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_its_centres() {
        let x = [0.3, 0.4, 0.5, 0.7, 1.0];
        let y = [1.0, -2.0, 0.5, 3.0, 0.0];
        let r = reconstruct(&x, &y, &x, 2.0).unwrap();
        for (a, b) in r.iter().zip(y) {
            assert!((a - b).abs() < 1e-12);
        }
        assert_eq!(wendland_c2(2.5, 2.0), 0.0);
    }
}
