//! NACA 4- and 5-digit profiles (BladeX `NacaProfile`; Abbott & von Doenhoff, *Theory of
//! Wing Sections*, §6.4 and §6.6; Moran 2003 p. 7).

use crate::profile::Profile;
use crate::spline1d::{linspace, InterpolatingSpline};
use crate::{Error, Result};

/// How the thickness is laid on the camber line.
///
/// BladeX calls these "cosine spacing" (`True`) and "linear spacing" (`False`), but in
/// both cases the x stations are equally spaced; the flag chooses whether the half
/// thickness is applied perpendicular to the camber line (true NACA construction,
/// upper and lower x differ) or vertically (x shared by both sides).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NacaSpacing {
    /// BladeX `cosine_spacing=True`: thickness normal to the camber line.
    #[default]
    Cosine,
    /// BladeX `cosine_spacing=False`: thickness added vertically.
    Linear,
}

/// The options of a NACA profile.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct NacaOptions {
    /// Points per side (BladeX default 240).
    pub n_points: usize,
    /// See [`NacaSpacing`].
    pub spacing: NacaSpacing,
    /// Closed trailing edge (`a₄ = −0.1036`, BladeX) or the original open one
    /// (`a₄ = −0.1015`, trailing-edge thickness 0.021 t).
    pub closed_trailing_edge: bool,
}

impl Default for NacaOptions {
    fn default() -> Self {
        Self { n_points: 240, spacing: NacaSpacing::Cosine, closed_trailing_edge: true }
    }
}

fn code_error(code: &str, reason: impl Into<String>) -> Error {
    Error::NacaCode { code: code.to_owned(), reason: reason.into() }
}

/// The NACA profile `code` (`"0012"`, `"2412"`, `"23012"`, reflex `"23112"`) on the unit
/// chord, as BladeX `NacaProfile(digits=code, n_points, cosine_spacing)` builds it: `x`
/// equally spaced on `[0, 1]`, half thickness
/// `y_t = 5t (0.2969 √x − 0.1260 x − 0.3516 x² + 0.2843 x³ + a₄ x⁴)`; for five digits
/// the `m` and `k₁` of the camber line are read from Abbott's table by FITPACK cubic
/// interpolation (`splrep`/`splev`), the reflex tables for `S = 1` (BladeX then uses the
/// simple camber formula with those constants, and so does this). In the linear mode a
/// five-digit camber is not scaled by the design lift `L` (BladeX does the same).
///
/// # Errors
///
/// [`Error::NacaCode`] for anything but 4 or 5 decimal digits, a reflex digit other than
/// 0 or 1, zero thickness, a 4-digit camber without a position, fewer than 2 points.
pub fn naca(code: &str, options: NacaOptions) -> Result<Profile> {
    let digits: Vec<f64> = code
        .chars()
        .map(|c| c.to_digit(10).map(f64::from))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| code_error(code, "only 4- or 5-digit NACA codes made of decimal digits are supported"))?;
    if options.n_points < 2 {
        return Err(code_error(code, format!("n_points = {} (at least 2)", options.n_points)));
    }
    // About a dozen arrays of n_points each are built here and by the profile's curve:
    // a size from a table is checked against the memory budget before any is allocated.
    cadmorph_morph::budget::check("NACA n_points", &[options.n_points, 16], 8)
        .map_err(|e| code_error(code, e.to_string()))?;
    let (a0, a1, a2, a3) = (0.2969, -0.1260, -0.3516, 0.2843);
    let a4 = if options.closed_trailing_edge { -0.1036 } else { -0.1015 };
    let x = linspace(0.0, 1.0, options.n_points);
    let half = |t: f64| -> Vec<f64> {
        x.iter()
            .map(|&x| 5.0 * t * (a0 * x.sqrt() + a1 * x + a2 * x.powi(2) + a3 * x.powi(3) + a4 * x.powi(4)))
            .collect()
    };
    let cosine = options.spacing == NacaSpacing::Cosine;
    // (camber, slope) per x, and the factor applied to the camber in the cosine mode.
    let (camber, slope, t, lift_factor): (Vec<f64>, Vec<f64>, f64, f64) = match digits.len() {
        4 => {
            let m = digits[0] / 100.0;
            let p = digits[1] / 10.0;
            let t = (digits[2] * 10.0 + digits[3]) / 100.0;
            if p == 0.0 {
                if m != 0.0 {
                    return Err(code_error(code, "a 4-digit camber needs a non-zero camber position (second digit)"));
                }
                (vec![0.0; x.len()], vec![0.0; x.len()], t, 1.0)
            } else {
                let c = x
                    .iter()
                    .map(|&x| {
                        if x <= p {
                            m / p.powi(2) * x * (2.0 * p - x)
                        } else {
                            m / (1.0 - p).powi(2) * (1.0 - 2.0 * p + x) * (1.0 - x)
                        }
                    })
                    .collect();
                let s = x
                    .iter()
                    .map(|&x| {
                        if x <= p {
                            m / p.powi(2) * (2.0 * p - 2.0 * x)
                        } else {
                            m / (1.0 - p).powi(2) * (2.0 * p - 2.0 * x)
                        }
                    })
                    .collect();
                (c, s, t, 1.0)
            }
        }
        5 => {
            let cld = digits[0] * 0.15;
            let p = 5.0 * digits[1] / 100.0;
            let s = digits[2];
            let t = (digits[3] * 10.0 + digits[4]) / 100.0;
            // Abbott's table values (0.318 is a tabulated camber position, not 1/π).
            #[allow(clippy::approx_constant)]
            let (pt, mt, kt): (&[f64], &[f64], &[f64]) = if s == 1.0 {
                (&[0.1, 0.15, 0.2, 0.25], &[0.13, 0.2170, 0.318, 0.441], &[51.99, 15.793, 6.520, 3.191])
            } else if s == 0.0 {
                (
                    &[0.05, 0.1, 0.15, 0.2, 0.25],
                    &[0.0580, 0.1260, 0.2025, 0.2900, 0.3910],
                    &[361.4, 51.64, 15.957, 6.643, 3.230],
                )
            } else {
                return Err(code_error(code, format!("third digit S = {s}: 0 (standard) or 1 (reflex) expected")));
            };
            if p == 0.0 {
                (vec![0.0; x.len()], vec![0.0; x.len()], t, 1.0)
            } else {
                let m = InterpolatingSpline::splrep(pt, mt, 3)?.eval(p);
                let k1 = InterpolatingSpline::splrep(mt, kt, 3)?.eval(m);
                let c = x
                    .iter()
                    .map(|&x| {
                        if x <= m {
                            k1 / 6.0 * (x.powi(3) - 3.0 * m * x.powi(2) + m.powi(2) * (3.0 - m) * x)
                        } else {
                            k1 / 6.0 * m.powi(3) * (1.0 - x)
                        }
                    })
                    .collect();
                let sl = x
                    .iter()
                    .map(|&x| {
                        if x <= m {
                            1.0 / 6.0 * k1 * (3.0 * x.powi(2) - 6.0 * m * x + m.powi(2) * (3.0 - m))
                        } else {
                            -1.0 / 6.0 * k1 * m.powi(3)
                        }
                    })
                    .collect();
                (c, sl, t, cld / 0.3)
            }
        }
        _ => {
            return Err(code_error(code, format!("{} digits: only 4- and 5-digit series are supported", digits.len())))
        }
    };
    if t == 0.0 {
        return Err(code_error(code, "zero thickness (last two digits 00)"));
    }
    let yt = half(t);
    let symmetric = camber.iter().all(|c| *c == 0.0) && slope.iter().all(|s| *s == 0.0);
    if symmetric {
        let down = yt.iter().map(|y| -y).collect();
        return Ok(Profile::from_parts(x.clone(), yt, x, down));
    }
    if cosine {
        let mut p = Profile::from_parts(Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for i in 0..x.len() {
            let th = slope[i].atan();
            let (s, c) = (th.sin(), th.cos());
            let zc = lift_factor * camber[i];
            p.xup.push(x[i] - yt[i] * s);
            p.yup.push(zc + yt[i] * c);
            p.xdown.push(x[i] + yt[i] * s);
            p.ydown.push(zc - yt[i] * c);
        }
        Ok(p)
    } else {
        let up = camber.iter().zip(&yt).map(|(c, y)| c + y).collect();
        let down = camber.iter().zip(&yt).map(|(c, y)| c - y).collect();
        Ok(Profile::from_parts(x.clone(), up, x, down))
    }
}
