//! The offline/online split of the paper (§2.1.1, after eq. (2)): the deformation's
//! basis at the base geometry's control points is computed once per process (offline),
//! and each variant's control points are then one matrix product (online).
//!
//! Every deformation cadmorph has is linear in its parameters θ (FFD lattice
//! displacements, RBF and IDW control-point displacements;
//! [`cadmorph::morph::LinearInParameters`]). With `P` the base's
//! control points stacked, `θ₀` the deformation file's parameters and `J = ∂φ(P)/∂μ` the
//! columns of the campaign parameters only,
//!
//! ```text
//! P(μ) = φ_θ₀(P) + J (μ − θ₀[campaign entries])          exact, for every μ
//! ```
//!
//! `φ_θ₀(P)` and `J` are the offline part (for an FFD from [`Ffd::bind`], whose
//! Bernstein weights are the rows of `J` up to the box frame); `J` is also the exact
//! sensitivity of the control points ([`crate::sensitivity`]).

use cadmorph::morph::math::{Point3, Vector3};
use cadmorph::morph::{Deformation, Ffd, Idw, LinearInParameters, ParamWeights, Parameters, Rbf};

use crate::error::{Error, Result};
use crate::space::Parameter;

/// The deformation of a campaign, whatever its kind.
#[derive(Debug, Clone)]
pub enum Base {
    /// FFD (paper eq. (1)–(2)).
    Ffd(Ffd),
    /// RBF (paper eq. (3)–(5)).
    Rbf(Box<Rbf>),
    /// IDW (paper eq. (9)).
    Idw(Idw),
}

impl Base {
    /// The deformation of `params`.
    ///
    /// # Errors
    ///
    /// [`Error::Morph`] when the RBF system or the IDW setup cannot be built.
    pub fn new(params: &Parameters) -> Result<Base> {
        let err = |error| Error::Morph { context: "building the deformation".into(), error };
        Ok(match params {
            Parameters::Ffd(f) => Base::Ffd(f.clone()),
            Parameters::Rbf(r) => Base::Rbf(Box::new(Rbf::from_parameters(r).map_err(err)?)),
            Parameters::Idw(i) => Base::Idw(Idw::from_parameters(i).map_err(err)?),
        })
    }

    fn linear(&self) -> &dyn LinearInParameters {
        match self {
            Base::Ffd(f) => f,
            Base::Rbf(r) => r.as_ref(),
            Base::Idw(i) => i,
        }
    }

    /// The parameters θ of the file.
    pub fn theta(&self) -> Vec<f64> {
        self.linear().params()
    }

    /// The deformation with parameters `theta`.
    ///
    /// # Errors
    ///
    /// [`Error::Morph`] for a wrong count or a non-finite value.
    pub fn with_theta(&self, theta: &[f64]) -> Result<Base> {
        let mut b = self.clone();
        let err = |error| Error::Morph { context: "setting the campaign parameters".into(), error };
        match &mut b {
            Base::Ffd(f) => f.set_params(theta).map_err(err)?,
            Base::Rbf(r) => r.set_params(theta).map_err(err)?,
            Base::Idw(i) => i.set_params(theta).map_err(err)?,
        }
        Ok(b)
    }

    /// As a [`Deformation`].
    pub fn deformation(&self) -> &dyn Deformation {
        self.linear()
    }

    /// `∂φ(p)/∂θ` at every point (for an FFD from one [`Ffd::bind`]), and `φ(points)`.
    fn weights_and_moved(&self, points: &[Point3<f64>]) -> (Vec<ParamWeights>, Vec<Point3<f64>>) {
        match self {
            Base::Ffd(f) => {
                let bound = f.bind(points);
                let mut moved = vec![Point3::origin(); points.len()];
                bound.deform_with(f.mu(), &mut moved).expect("bound to these points, with the lattice's own shape");
                ((0..points.len()).map(|i| bound.param_weights(i)).collect(), moved)
            }
            other => {
                let d = other.linear();
                (
                    points.iter().map(|p| d.param_weights(p)).collect(),
                    points.iter().map(|p| d.deform_point(p)).collect(),
                )
            }
        }
    }
}

/// The offline part: the base's control points, where the file's deformation puts them,
/// and the columns of `J` for the campaign parameters.
#[derive(Debug, Clone)]
pub struct Basis {
    /// The base control points, all patches in order.
    pub points: Vec<Point3<f64>>,
    /// `φ_θ₀(points)`.
    pub moved: Vec<Point3<f64>>,
    /// `columns[q][i] = ∂φ(points[i])/∂μ_q`.
    pub columns: Vec<Vec<Vector3<f64>>>,
    /// θ₀ at the campaign entries.
    pub theta0: Vec<f64>,
}

impl Basis {
    /// Builds the basis of `base` at `points` for `params` (offline).
    pub fn new(base: &Base, params: &[Parameter], points: Vec<Point3<f64>>) -> Basis {
        let theta = base.theta();
        let (weights, moved) = base.weights_and_moved(&points);
        let columns = params
            .iter()
            .map(|p| {
                weights
                    .iter()
                    .map(|w| {
                        let (c, j) = (p.theta / w.n_nodes, p.theta % w.n_nodes);
                        let wj: f64 = w.weights.iter().filter(|(node, _)| *node == j).map(|(_, x)| x).sum();
                        w.frame.column(c) * wj
                    })
                    .collect()
            })
            .collect();
        Basis { theta0: params.iter().map(|p| theta[p.theta]).collect(), points, moved, columns }
    }

    /// The control points of the variant with campaign values `mu` (online: `φ_θ₀(P) +
    /// J (μ − θ₀)`).
    pub fn control_points(&self, mu: &[f64]) -> Vec<Point3<f64>> {
        let delta: Vec<f64> = mu.iter().zip(&self.theta0).map(|(m, t)| m - t).collect();
        let mut out = self.moved.clone();
        for (col, &dq) in self.columns.iter().zip(&delta) {
            if dq != 0.0 {
                for (p, c) in out.iter_mut().zip(col) {
                    *p += c * dq;
                }
            }
        }
        out
    }
}

/// A variant's deformation as the model's morph sees it: the base's control points go
/// where the online product put them; any other point (curve control points, the
/// points seam checks sample) through the variant's full deformation, which also gives
/// the Jacobian for the fold check.
pub struct Online<'a> {
    table: std::collections::HashMap<[u64; 3], Point3<f64>>,
    full: &'a dyn Deformation,
}

fn key(p: &Point3<f64>) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

impl<'a> Online<'a> {
    /// The base points `points` going to `moved`, everything else through `full`.
    pub fn new(points: &[Point3<f64>], moved: &[Point3<f64>], full: &'a dyn Deformation) -> Self {
        Online { table: points.iter().zip(moved).map(|(p, q)| (key(p), *q)).collect(), full }
    }
}

impl Deformation for Online<'_> {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        match self.table.get(&key(p)) {
            Some(q) => *q,
            None => self.full.deform_point(p),
        }
    }
    fn jacobian(&self, p: &Point3<f64>) -> Option<cadmorph::morph::math::Matrix3<f64>> {
        self.full.jacobian(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::entry::Entry;
    use crate::space::Values;

    #[test]
    fn online_product_equals_the_deformation() {
        let mut ffd = Ffd::try_new(
            [4, 3, 3],
            Point3::new(-1.0, -1.0, -1.0),
            Vector3::new(2.0, 2.0, 2.0),
            Vector3::new(5.0, 0.0, 10.0),
        )
        .unwrap();
        ffd.mu_mut().set(1, 1, 1, [0.02, 0.0, 0.01]);
        let base = Base::Ffd(ffd);
        let params: Vec<Parameter> = [(1, [1, 1, 1]), (2, [2, 1, 1]), (0, [1, 1, 1])]
            .iter()
            .enumerate()
            .map(|(n, &(component, node))| {
                let entry = Entry::Lattice { component, node };
                let theta = entry.theta_index(&Parameters::Ffd(Ffd::unit([4, 3, 3]))).unwrap();
                Parameter { name: format!("p{n}"), entry, theta, values: Values::Range { lo: -0.1, hi: 0.1 } }
            })
            .collect();
        let points: Vec<Point3<f64>> = (0..200)
            .map(|i| Point3::new((i as f64 * 0.37).sin(), (i as f64 * 0.11).cos(), (i as f64 * 0.07).sin() * 1.2))
            .collect();
        let basis = Basis::new(&base, &params, points.clone());
        let mu = [0.05, -0.03, 0.07];
        let mut theta = base.theta();
        for (p, m) in params.iter().zip(mu) {
            theta[p.theta] = m;
        }
        let direct = base.with_theta(&theta).unwrap();
        for (p, q) in points.iter().zip(basis.control_points(&mu)) {
            assert!((direct.deformation().deform_point(p) - q).norm() < 1e-14);
        }
    }
}
