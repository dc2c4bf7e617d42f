//! Sensitivities of the control points with respect to the campaign parameters (issue
//! 16, Deliver 5): exact, because every morph is linear in its parameters, so
//! `∂P/∂μ = J` is the same for every variant and is the offline basis itself
//! ([`Basis::columns`]).

use cadmorph::morph::math::DMatrix;

use crate::online::{Base, Basis};
use crate::space::DesignSpace;

/// The dense Jacobian `∂P/∂μ` of the stacked control points (`3·i + c` for coordinate
/// `c` of point `i`) with respect to the campaign parameters (columns, in order).
pub fn jacobian(basis: &Basis) -> DMatrix<f64> {
    let n = basis.points.len();
    DMatrix::from_fn(3 * n, basis.columns.len(), |r, q| basis.columns[q][r / 3][r % 3])
}

/// The same Jacobian by central differences of the deformation itself, step `h` on
/// every parameter around `mu` (a check of [`jacobian`]; exact up to rounding for a
/// linear map).
///
/// # Errors
///
/// [`crate::Error::Morph`] when a deformation cannot be built.
pub fn finite_differences(
    space: &DesignSpace,
    base: &Base,
    basis: &Basis,
    mu: &[f64],
    h: f64,
) -> crate::Result<DMatrix<f64>> {
    let n = basis.points.len();
    let theta0 = base.theta();
    let mut j = DMatrix::zeros(3 * n, mu.len());
    for q in 0..mu.len() {
        let mut plus = mu.to_vec();
        let mut minus = mu.to_vec();
        plus[q] += h;
        minus[q] -= h;
        let dp = base.with_theta(&crate::run::theta_of(space, &theta0, &plus))?;
        let dm = base.with_theta(&crate::run::theta_of(space, &theta0, &minus))?;
        for (i, p) in basis.points.iter().enumerate() {
            let d = (dp.deformation().deform_point(p) - dm.deformation().deform_point(p)) / (2.0 * h);
            for c in 0..3 {
                j[(3 * i + c, q)] = d[c];
            }
        }
    }
    Ok(j)
}

/// Per parameter, the largest control-point displacement per unit of it
/// (`maxᵢ ‖∂Pᵢ/∂μ_q‖`, model units per parameter unit).
pub fn max_displacement_per_unit(basis: &Basis) -> Vec<f64> {
    basis.columns.iter().map(|col| col.iter().map(|v| v.norm()).fold(0.0, f64::max)).collect()
}
