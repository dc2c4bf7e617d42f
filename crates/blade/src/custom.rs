//! Custom profiles: from side coordinates, from a CSV file, or from camber and thickness
//! distributions (BladeX `CustomProfile`).

use crate::profile::{Convention, Profile};
use crate::{Error, Result};

impl Profile {
    /// A profile from its side coordinates, checked as BladeX `CustomProfile` checks
    /// them: equal lengths per side, `y_up ≥ y_down` at the inner points, and both sides
    /// meeting at the leading and trailing edge within 1e-6 (a closed trailing edge).
    ///
    /// # Errors
    ///
    /// [`Error::Profile`] naming the array (and index) that breaks a rule.
    pub fn try_new(xup: Vec<f64>, yup: Vec<f64>, xdown: Vec<f64>, ydown: Vec<f64>) -> Result<Self> {
        let p = Self::from_parts(xup, yup, xdown, ydown);
        p.check_custom(true)?;
        Ok(p)
    }

    /// Like [`try_new`](Self::try_new) but accepting an open trailing edge (the two last
    /// points may differ in y).
    ///
    /// # Errors
    ///
    /// As [`try_new`](Self::try_new).
    pub fn try_new_open(xup: Vec<f64>, yup: Vec<f64>, xdown: Vec<f64>, ydown: Vec<f64>) -> Result<Self> {
        let p = Self::from_parts(xup, yup, xdown, ydown);
        p.check_custom(false)?;
        Ok(p)
    }

    fn check_custom(&self, closed: bool) -> Result<()> {
        self.leading_edge()?;
        let (nu, nd) = (self.xup.len(), self.xdown.len());
        if nu == nd {
            for i in 1..nu - 1 {
                if self.yup[i] < self.ydown[i] {
                    return Err(Error::profile(
                        format!("yup[{i}]"),
                        format!("{} is below ydown[{i}] = {}", self.yup[i], self.ydown[i]),
                    ));
                }
            }
        }
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 + 1e-5 * b.abs();
        if !close(self.xdown[0], self.xup[0]) {
            return Err(Error::profile("xdown[0]", "must equal xup[0] (leading edge)"));
        }
        if !close(self.xdown[nd - 1], self.xup[nu - 1]) {
            return Err(Error::profile(format!("xdown[{}]", nd - 1), "must equal the last xup (trailing edge)"));
        }
        if !close(self.ydown[0], self.yup[0]) {
            return Err(Error::profile("ydown[0]", "must equal yup[0] (leading edge)"));
        }
        if closed && !close(self.ydown[nd - 1], self.yup[nu - 1]) {
            return Err(Error::profile(format!("ydown[{}]", nd - 1), "must equal the last yup (closed trailing edge)"));
        }
        Ok(())
    }

    /// A profile from a CSV text in the layout of BladeX's `boeing_707.csv`: four
    /// columns stacked one after the other, each introduced by a header line (`X_UP`,
    /// `Y_UP`, `X_DOWN`, `Y_DOWN`, a trailing `:` allowed) and followed by one number
    /// per line; or four comma-separated columns per line after one header line.
    ///
    /// # Errors
    ///
    /// [`Error::Profile`] naming the line that is neither a header nor a number, or the
    /// column that is missing; then the checks of [`try_new`](Self::try_new).
    pub fn from_csv(text: &str) -> Result<Self> {
        let lines: Vec<(usize, &str)> =
            text.lines().enumerate().map(|(i, l)| (i + 1, l.trim())).filter(|(_, l)| !l.is_empty()).collect();
        let wide = lines.iter().skip(1).all(|(_, l)| l.split(',').count() == 4);
        let mut cols: Vec<(String, Vec<f64>)> = Vec::new();
        if wide && lines.len() > 1 {
            let names: Vec<String> =
                lines[0].1.split(',').map(|s| s.trim().trim_end_matches(':').to_uppercase()).collect();
            if names.len() != 4 {
                return Err(Error::profile(
                    format!("line {}", lines[0].0),
                    format!("a header of 4 comma-separated column names, found {}", names.len()),
                ));
            }
            cols = names.into_iter().map(|n| (n, Vec::new())).collect();
            for (no, l) in &lines[1..] {
                for (k, cell) in l.split(',').enumerate() {
                    let v: f64 = cell.trim().parse().map_err(|_| {
                        Error::profile(format!("line {no}, column {}", k + 1), format!("{cell:?} is not a number"))
                    })?;
                    cols[k].1.push(v);
                }
            }
        } else {
            for (no, l) in &lines {
                match l.parse::<f64>() {
                    Ok(v) => match cols.last_mut() {
                        Some(c) => c.1.push(v),
                        None => return Err(Error::profile(format!("line {no}"), "a number before any column header")),
                    },
                    Err(_) => {
                        if l.chars().any(|c| c.is_ascii_digit()) {
                            return Err(Error::profile(format!("line {no}"), format!("{l:?} is not a number")));
                        }
                        cols.push((l.trim_end_matches(':').trim().to_uppercase(), Vec::new()));
                    }
                }
            }
        }
        let mut take = |name: &str| -> Result<Vec<f64>> {
            let k = cols
                .iter()
                .position(|(n, _)| n.replace([' ', '-'], "_") == name)
                .ok_or_else(|| Error::profile(name, "column missing"))?;
            Ok(std::mem::take(&mut cols[k].1))
        };
        let (xu, yu, xd, yd) = (take("X_UP")?, take("Y_UP")?, take("X_DOWN")?, take("Y_DOWN")?);
        Self::try_new(xu, yu, xd, yd)
    }

    /// A profile from camber and thickness distributions given as fractions (BladeX
    /// `CustomProfile(chord_perc=..., camber_perc=..., thickness_perc=..., camber_max=...,
    /// thickness_max=..., chord_len=...)`): at each chord fraction `c`, camber
    /// `f = camber_perc·camber_max` and half thickness `h = thickness_perc·thickness_max/2`;
    /// British: `(x, f ± h)` with `x = c·chord`; American: `(x ∓ h sin θ, f ± h cos θ)`
    /// with θ the camber-line slope angle by backward differences (`θ₀ = 0`).
    ///
    /// # Errors
    ///
    /// [`Error::Profile`] for arrays of different lengths or negative maxima.
    pub fn from_camber_thickness(
        chord_perc: &[f64],
        camber_perc: &[f64],
        thickness_perc: &[f64],
        camber_max: f64,
        thickness_max: f64,
        chord_len: f64,
        convention: Convention,
    ) -> Result<Self> {
        let n = chord_perc.len();
        if camber_perc.len() != n {
            return Err(Error::profile("camber_perc", format!("{} values for {n} chord_perc", camber_perc.len())));
        }
        if thickness_perc.len() != n {
            return Err(Error::profile(
                "thickness_perc",
                format!("{} values for {n} chord_perc", thickness_perc.len()),
            ));
        }
        if n < 2 {
            return Err(Error::profile("chord_perc", "at least 2 stations"));
        }
        if camber_max < 0.0 {
            return Err(Error::profile("camber_max", "must not be negative"));
        }
        if thickness_max < 0.0 {
            return Err(Error::profile("thickness_max", "must not be negative"));
        }
        if chord_len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(Error::profile("chord_len", "must be positive"));
        }
        let x: Vec<f64> = chord_perc.iter().map(|c| c * chord_len).collect();
        let f: Vec<f64> = camber_perc.iter().map(|c| c * camber_max).collect();
        let h: Vec<f64> = thickness_perc.iter().map(|t| thickness_max / 2.0 * t).collect();
        match convention {
            Convention::British => Ok(Self::from_parts(
                x.clone(),
                f.iter().zip(&h).map(|(f, h)| f + h).collect(),
                x,
                f.iter().zip(&h).map(|(f, h)| f - h).collect(),
            )),
            Convention::American => {
                let mut p = Self::from_parts(Vec::new(), Vec::new(), Vec::new(), Vec::new());
                for i in 0..n {
                    let m = if i == 0 {
                        0.0
                    } else {
                        (camber_perc[i] - camber_perc[i - 1]) * camber_max
                            / (chord_perc[i] - chord_perc[i - 1])
                            / chord_len
                    };
                    let th = m.atan();
                    p.xup.push(x[i] - h[i] * th.sin());
                    p.xdown.push(x[i] + h[i] * th.sin());
                    p.yup.push(f[i] + h[i] * th.cos());
                    p.ydown.push(f[i] - h[i] * th.cos());
                }
                Ok(p)
            }
        }
    }
}
