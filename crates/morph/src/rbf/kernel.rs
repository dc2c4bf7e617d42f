//! Radial basis functions φ(r): PyGeM's six (`pygem/rbf_factory.py`, same formulas, names
//! and parameters) and the compactly supported Wendland family.

/// A radial basis function `φ(r)`, `r = ‖x − c‖`.
///
/// PyGeM's kernels keep PyGeM's names (see [`Kernel::name`]) and formulas, with its scaling
/// parameter `radius` (PyGeM's `r`, written `R` below, `ρ = r / R`):
///
/// | variant | PyGeM name | φ(r) |
/// |---|---|---|
/// | `Gaussian` | `gaussian_spline` | `exp(−r²/R²)` |
/// | `MultiQuadratic` | `multi_quadratic_biharmonic_spline` | `√(r² + R²)` |
/// | `InverseMultiQuadratic` | `inv_multi_quadratic_biharmonic_spline` | `1/√(r² + R²)` |
/// | `ThinPlate` | `thin_plate_spline` | `ρᵏ ln ρ` (0 at ρ = 0), k = 2 by default |
/// | `BeckertWendlandC2` | `beckert_wendland_c2_basis` | `(1 − ρ)₊⁴ (4ρ + 1)` |
/// | `Polyharmonic` | `polyharmonic_spline` | `ρᵏ` for odd k; `ρᵏ ln ρ` for even k (PyGeM writes `ρᵏ⁻¹ ln(ρ^ρ)` for ρ < 1, the same function) |
///
/// The Wendland functions φ₃,ₖ (Wendland 1995) are positive definite in ℝ³ and vanish
/// beyond the support radius `s` (`ρ = r / s`); with them the interpolation matrix is sparse
/// and [`crate::Rbf`] solves it with a sparse Cholesky factorisation or conjugate gradients:
///
/// | variant | name | φ(r) |
/// |---|---|---|
/// | `WendlandC0` | `wendland_c0` | `(1 − ρ)₊²` |
/// | `WendlandC2` | `wendland_c2` | `(1 − ρ)₊⁴ (4ρ + 1)` |
/// | `WendlandC4` | `wendland_c4` | `(1 − ρ)₊⁶ (35ρ² + 18ρ + 3) / 3` |
///
/// (`beckert_wendland_c2_basis` is the same function as `wendland_c2`; PyGeM solves it densely.)
///
/// # Examples
///
/// ```
/// use cadmorph_morph::rbf::Kernel;
/// let k = Kernel::from_name("thin_plate_spline", 0.5, None).unwrap();
/// assert_eq!(k, Kernel::ThinPlate { radius: 0.5, k: 2 });
/// assert!((k.eval(1.0) - 4.0 * 2f64.ln()).abs() < 1e-15);
/// assert_eq!(Kernel::WendlandC2 { support: 1.0 }.eval(1.5), 0.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kernel {
    /// `gaussian_spline`: `exp(−r²/R²)`.
    Gaussian {
        /// Scaling radius R.
        radius: f64,
    },
    /// `multi_quadratic_biharmonic_spline`: `√(r² + R²)`.
    MultiQuadratic {
        /// Scaling radius R.
        radius: f64,
    },
    /// `inv_multi_quadratic_biharmonic_spline`: `1/√(r² + R²)`.
    InverseMultiQuadratic {
        /// Scaling radius R.
        radius: f64,
    },
    /// `thin_plate_spline`: `(r/R)ᵏ ln(r/R)`.
    ThinPlate {
        /// Scaling radius R.
        radius: f64,
        /// Power k (PyGeM's extra parameter `k`, default 2).
        k: u32,
    },
    /// `beckert_wendland_c2_basis`: `(1 − r/R)₊⁴ (4r/R + 1)`.
    BeckertWendlandC2 {
        /// Support radius R.
        radius: f64,
    },
    /// `polyharmonic_spline`: `(r/R)ᵏ`, k odd; `(r/R)ᵏ ln(r/R)`, k even.
    Polyharmonic {
        /// Scaling radius R.
        radius: f64,
        /// Power k (PyGeM's extra parameter `k`, default 2).
        k: u32,
    },
    /// Wendland φ₃,₀: `(1 − r/s)₊²`.
    WendlandC0 {
        /// Support radius s.
        support: f64,
    },
    /// Wendland φ₃,₁: `(1 − r/s)₊⁴ (4r/s + 1)`.
    WendlandC2 {
        /// Support radius s.
        support: f64,
    },
    /// Wendland φ₃,₂: `(1 − r/s)₊⁶ (35(r/s)² + 18r/s + 3) / 3`.
    WendlandC4 {
        /// Support radius s.
        support: f64,
    },
}

/// Default power of `thin_plate_spline` and `polyharmonic_spline` (PyGeM's default `k=2`).
pub const DEFAULT_K: u32 = 2;

impl Kernel {
    /// Every kernel name [`Kernel::from_name`] accepts: PyGeM's six, then cadmorph's Wendland family.
    pub const NAMES: [&'static str; 9] = [
        "gaussian_spline",
        "multi_quadratic_biharmonic_spline",
        "inv_multi_quadratic_biharmonic_spline",
        "thin_plate_spline",
        "beckert_wendland_c2_basis",
        "polyharmonic_spline",
        "wendland_c0",
        "wendland_c2",
        "wendland_c4",
    ];

    /// The kernel called `name` with scaling (or support) radius `radius` and, for
    /// `thin_plate_spline` and `polyharmonic_spline`, power `k` (default [`DEFAULT_K`]).
    /// `None` for an unknown name, or a `k` given to a kernel that takes none.
    pub fn from_name(name: &str, radius: f64, k: Option<u32>) -> Option<Kernel> {
        let kk = k.unwrap_or(DEFAULT_K);
        let kernel = match name {
            "gaussian_spline" => Kernel::Gaussian { radius },
            "multi_quadratic_biharmonic_spline" => Kernel::MultiQuadratic { radius },
            "inv_multi_quadratic_biharmonic_spline" => Kernel::InverseMultiQuadratic { radius },
            "thin_plate_spline" => return Some(Kernel::ThinPlate { radius, k: kk }),
            "beckert_wendland_c2_basis" => Kernel::BeckertWendlandC2 { radius },
            "polyharmonic_spline" => return Some(Kernel::Polyharmonic { radius, k: kk }),
            "wendland_c0" => Kernel::WendlandC0 { support: radius },
            "wendland_c2" => Kernel::WendlandC2 { support: radius },
            "wendland_c4" => Kernel::WendlandC4 { support: radius },
            _ => return None,
        };
        if k.is_some() {
            return None;
        }
        Some(kernel)
    }

    /// The kernel's name (PyGeM's for PyGeM's kernels).
    pub fn name(&self) -> &'static str {
        match self {
            Kernel::Gaussian { .. } => "gaussian_spline",
            Kernel::MultiQuadratic { .. } => "multi_quadratic_biharmonic_spline",
            Kernel::InverseMultiQuadratic { .. } => "inv_multi_quadratic_biharmonic_spline",
            Kernel::ThinPlate { .. } => "thin_plate_spline",
            Kernel::BeckertWendlandC2 { .. } => "beckert_wendland_c2_basis",
            Kernel::Polyharmonic { .. } => "polyharmonic_spline",
            Kernel::WendlandC0 { .. } => "wendland_c0",
            Kernel::WendlandC2 { .. } => "wendland_c2",
            Kernel::WendlandC4 { .. } => "wendland_c4",
        }
    }

    /// The scaling radius (support radius for compact kernels).
    pub fn radius(&self) -> f64 {
        match *self {
            Kernel::Gaussian { radius }
            | Kernel::MultiQuadratic { radius }
            | Kernel::InverseMultiQuadratic { radius }
            | Kernel::ThinPlate { radius, .. }
            | Kernel::BeckertWendlandC2 { radius }
            | Kernel::Polyharmonic { radius, .. } => radius,
            Kernel::WendlandC0 { support } | Kernel::WendlandC2 { support } | Kernel::WendlandC4 { support } => support,
        }
    }

    /// The power k of `thin_plate_spline` and `polyharmonic_spline`.
    pub fn k(&self) -> Option<u32> {
        match *self {
            Kernel::ThinPlate { k, .. } | Kernel::Polyharmonic { k, .. } => Some(k),
            _ => None,
        }
    }

    /// The support radius of a compactly supported kernel (φ(r) = 0 for r ≥ support).
    pub fn support(&self) -> Option<f64> {
        match *self {
            Kernel::BeckertWendlandC2 { radius } => Some(radius),
            Kernel::WendlandC0 { support } | Kernel::WendlandC2 { support } | Kernel::WendlandC4 { support } => {
                Some(support)
            }
            _ => None,
        }
    }

    /// φ(r).
    #[inline(always)]
    pub fn eval(&self, r: f64) -> f64 {
        match *self {
            Kernel::Gaussian { radius } => (-(r * r) / (radius * radius)).exp(),
            Kernel::MultiQuadratic { radius } => (r * r + radius * radius).sqrt(),
            Kernel::InverseMultiQuadratic { radius } => 1.0 / (r * r + radius * radius).sqrt(),
            Kernel::ThinPlate { radius, k } => {
                let a = r / radius;
                if a > 0.0 {
                    powi(a, k) * a.ln()
                } else {
                    powi(a, k)
                }
            }
            Kernel::Polyharmonic { radius, k } => {
                let a = r / radius;
                if k % 2 == 1 {
                    powi(a, k)
                } else if a > 0.0 {
                    powi(a, k) * a.ln()
                } else {
                    0.0
                }
            }
            Kernel::BeckertWendlandC2 { radius: s } | Kernel::WendlandC2 { support: s } => {
                let a = r / s;
                let t = 1.0 - a;
                if t > 0.0 {
                    let t2 = t * t;
                    t2 * t2 * (4.0 * a + 1.0)
                } else {
                    0.0
                }
            }
            Kernel::WendlandC0 { support } => {
                let t = 1.0 - r / support;
                if t > 0.0 {
                    t * t
                } else {
                    0.0
                }
            }
            Kernel::WendlandC4 { support } => {
                let a = r / support;
                let t = 1.0 - a;
                if t > 0.0 {
                    let t3 = t * t * t;
                    t3 * t3 * (35.0 * a * a + 18.0 * a + 3.0) / 3.0
                } else {
                    0.0
                }
            }
        }
    }

    /// dφ/dr at `r > 0`; at `r = 0` the one-sided limit.
    pub fn deriv(&self, r: f64) -> f64 {
        match *self {
            Kernel::Gaussian { radius } => -2.0 * r / (radius * radius) * (-(r * r) / (radius * radius)).exp(),
            Kernel::MultiQuadratic { radius } => r / (r * r + radius * radius).sqrt(),
            Kernel::InverseMultiQuadratic { radius } => -r / (r * r + radius * radius).powf(1.5),
            Kernel::ThinPlate { radius, k } => log_power_deriv(r / radius, k) / radius,
            Kernel::Polyharmonic { radius, k } => {
                let a = r / radius;
                if k % 2 == 1 {
                    k as f64 * powi(a, k - 1) / radius
                } else {
                    log_power_deriv(a, k) / radius
                }
            }
            Kernel::BeckertWendlandC2 { radius: s } | Kernel::WendlandC2 { support: s } => {
                let a = r / s;
                let t = 1.0 - a;
                if t > 0.0 {
                    -20.0 * a * t * t * t / s
                } else {
                    0.0
                }
            }
            Kernel::WendlandC0 { support } => {
                let t = 1.0 - r / support;
                if t > 0.0 {
                    -2.0 * t / support
                } else {
                    0.0
                }
            }
            Kernel::WendlandC4 { support } => {
                let a = r / support;
                let t = 1.0 - a;
                if t > 0.0 {
                    // d/da [(1−a)⁶(35a² + 18a + 3)/3] = −(56/3) a (1 + 5a)(1 − a)⁵
                    let t5 = t * t * t * t * t;
                    -56.0 / 3.0 * a * (1.0 + 5.0 * a) * t5 / support
                } else {
                    0.0
                }
            }
        }
    }

    /// The same kernel with scaling (or support) radius `radius` (the power k kept): the
    /// multilevel interpolation halves the support from level to level.
    ///
    /// ```
    /// use cadmorph_morph::rbf::Kernel;
    /// let k = Kernel::WendlandC2 { support: 0.6 }.with_radius(0.3);
    /// assert_eq!(k, Kernel::WendlandC2 { support: 0.3 });
    /// ```
    pub fn with_radius(&self, radius: f64) -> Kernel {
        match *self {
            Kernel::Gaussian { .. } => Kernel::Gaussian { radius },
            Kernel::MultiQuadratic { .. } => Kernel::MultiQuadratic { radius },
            Kernel::InverseMultiQuadratic { .. } => Kernel::InverseMultiQuadratic { radius },
            Kernel::ThinPlate { k, .. } => Kernel::ThinPlate { radius, k },
            Kernel::BeckertWendlandC2 { .. } => Kernel::BeckertWendlandC2 { radius },
            Kernel::Polyharmonic { k, .. } => Kernel::Polyharmonic { radius, k },
            Kernel::WendlandC0 { .. } => Kernel::WendlandC0 { support: radius },
            Kernel::WendlandC2 { .. } => Kernel::WendlandC2 { support: radius },
            Kernel::WendlandC4 { .. } => Kernel::WendlandC4 { support: radius },
        }
    }

    /// Whether `x ↦ φ(‖x − c‖)` is differentiable at the centre `x = c`, i.e. φ'(0) = 0.
    pub fn smooth_at_centre(&self) -> bool {
        match *self {
            Kernel::Polyharmonic { k, .. } => k >= 2,
            Kernel::ThinPlate { k, .. } => k >= 2,
            Kernel::WendlandC0 { .. } => false,
            _ => true,
        }
    }

    /// Checks the radius (positive, finite) and the power (k ≥ 1).
    pub(crate) fn validate(&self) -> crate::Result<()> {
        let r = self.radius();
        if !(r.is_finite() && r > 0.0) {
            return Err(crate::Error::InvalidParameter {
                line: None,
                name: "radius",
                value: r,
                reason: "must be positive and finite",
            });
        }
        if let Some(k) = self.k() {
            if k == 0 {
                return Err(crate::Error::InvalidParameter {
                    line: None,
                    name: "k",
                    value: 0.0,
                    reason: "must be at least 1",
                });
            }
        }
        Ok(())
    }
}

/// `aⁿ` by repeated squaring (exact for the small integer powers used here).
#[inline(always)]
fn powi(a: f64, n: u32) -> f64 {
    a.powi(n as i32)
}

/// d/da (aᵏ ln a) = aᵏ⁻¹ (k ln a + 1), with the limit at a = 0.
fn log_power_deriv(a: f64, k: u32) -> f64 {
    if a > 0.0 {
        powi(a, k - 1) * (k as f64 * a.ln() + 1.0)
    } else if k >= 2 {
        0.0
    } else {
        f64::NEG_INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(r: f64) -> Vec<Kernel> {
        vec![
            Kernel::Gaussian { radius: r },
            Kernel::MultiQuadratic { radius: r },
            Kernel::InverseMultiQuadratic { radius: r },
            Kernel::ThinPlate { radius: r, k: 2 },
            Kernel::ThinPlate { radius: r, k: 3 },
            Kernel::BeckertWendlandC2 { radius: r },
            Kernel::Polyharmonic { radius: r, k: 1 },
            Kernel::Polyharmonic { radius: r, k: 3 },
            Kernel::Polyharmonic { radius: r, k: 4 },
            Kernel::WendlandC0 { support: r },
            Kernel::WendlandC2 { support: r },
            Kernel::WendlandC4 { support: r },
        ]
    }

    #[test]
    fn derivative_matches_central_difference() {
        let h = 1e-6;
        for k in all(0.8) {
            for r in [0.05, 0.3, 0.6, 0.79, 1.3] {
                let fd = (k.eval(r + h) - k.eval(r - h)) / (2.0 * h);
                assert!((k.deriv(r) - fd).abs() < 1e-7 * (1.0 + fd.abs()), "{k:?} at {r}: {} vs {fd}", k.deriv(r));
            }
        }
    }

    #[test]
    fn names_round_trip() {
        for k in all(0.5) {
            let back = Kernel::from_name(k.name(), k.radius(), k.k()).unwrap();
            assert_eq!(back, k);
        }
        assert_eq!(Kernel::from_name("gaussian_spline", 1.0, Some(3)), None);
        assert_eq!(Kernel::from_name("gaussian_splines", 1.0, None), None);
    }

    #[test]
    fn pygem_formulas() {
        // Values written out from pygem/rbf_factory.py's formulas at r = 0.3, R = 0.5.
        let (r, big_r) = (0.3f64, 0.5f64);
        let a = r / big_r;
        assert_eq!(Kernel::Gaussian { radius: big_r }.eval(r), (-(r * r) / (big_r * big_r)).exp());
        assert_eq!(Kernel::ThinPlate { radius: big_r, k: 2 }.eval(r), a.powi(2) * a.ln());
        let pyg = a.powi(3) * (a.powf(a)).ln(); // PyGeM's ρᵏ⁻¹ ln(ρ^ρ), k = 4
        assert!((Kernel::Polyharmonic { radius: big_r, k: 4 }.eval(r) - pyg).abs() < 1e-16);
        // (powi may round differently from t²·t² once optimised: one ulp.)
        let bw = (1.0 - a).powi(4) * (4.0 * a + 1.0);
        assert!((Kernel::BeckertWendlandC2 { radius: big_r }.eval(r) - bw).abs() <= f64::EPSILON * bw);
        assert_eq!(Kernel::ThinPlate { radius: 1.0, k: 2 }.eval(0.0), 0.0);
        assert_eq!(Kernel::Polyharmonic { radius: 1.0, k: 2 }.eval(0.0), 0.0);
    }
}
