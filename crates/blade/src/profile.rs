//! A 2D airfoil given by its upper and lower sides, with BladeX's measurements and
//! transformations (`bladex.profile.BaseProfile`).

use crate::spline1d::linspace;
use crate::wendland::reconstruct;
use crate::{Error, Result};

/// How thickness is measured (BladeX `generate_parameters(convention=...)`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Convention {
    /// Thickness measured perpendicular to the chord line (`|y_up − y_down|` at equal x).
    #[default]
    British,
    /// Thickness measured perpendicular to the mean camber line.
    American,
}

/// The measurements of a profile (BladeX `generate_parameters`): chord length and
/// chord fractions, maximum camber and camber fractions, maximum thickness and thickness
/// fractions, one fraction per upper-side point.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileParameters {
    /// Distance between leading and trailing edge.
    pub chord_length: f64,
    /// `(x_up − min x_up) / chord` per point.
    pub chord_percentage: Vec<f64>,
    /// `|max (y_up + y_down)/2|`.
    pub camber_max: f64,
    /// Camber per point divided by `camber_max` (zeros for a symmetric profile).
    pub camber_percentage: Vec<f64>,
    /// Largest thickness in the chosen convention.
    pub thickness_max: f64,
    /// Thickness per point divided by `thickness_max`.
    pub thickness_percentage: Vec<f64>,
    /// Chord fraction where the camber is largest.
    pub camber_max_position: f64,
    /// Chord fraction where the thickness is largest.
    pub thickness_max_position: f64,
}

/// An airfoil: upper side `(x_up, y_up)` and lower side `(x_down, y_down)`, both from
/// the leading edge to the trailing edge (BladeX `BaseProfile`).
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// x of the upper (suction) side, leading edge first.
    pub xup: Vec<f64>,
    /// y of the upper side.
    pub yup: Vec<f64>,
    /// x of the lower (pressure) side, leading edge first.
    pub xdown: Vec<f64>,
    /// y of the lower side.
    pub ydown: Vec<f64>,
}

fn max_of(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

fn argmax(v: &[f64]) -> usize {
    let mut best = 0;
    for (i, x) in v.iter().enumerate() {
        if *x > v[best] {
            best = i;
        }
    }
    best
}

impl Profile {
    /// A profile from its four arrays without checks (the generators use it).
    pub(crate) fn from_parts(xup: Vec<f64>, yup: Vec<f64>, xdown: Vec<f64>, ydown: Vec<f64>) -> Self {
        Self { xup, yup, xdown, ydown }
    }

    /// Number of points per side (the upper side's).
    pub fn len(&self) -> usize {
        self.xup.len()
    }

    /// Whether the profile has no points.
    pub fn is_empty(&self) -> bool {
        self.xup.is_empty()
    }

    fn check_shapes(&self) -> Result<()> {
        if self.xup.len() != self.yup.len() {
            return Err(Error::profile("yup", format!("{} values for {} xup", self.yup.len(), self.xup.len())));
        }
        if self.xdown.len() != self.ydown.len() {
            return Err(Error::profile("ydown", format!("{} values for {} xdown", self.ydown.len(), self.xdown.len())));
        }
        if self.xup.len() < 2 || self.xdown.len() < 2 {
            return Err(Error::profile("xup", "each side needs at least 2 points"));
        }
        if let Some((name, i)) =
            [("xup", &self.xup), ("yup", &self.yup), ("xdown", &self.xdown), ("ydown", &self.ydown)]
                .iter()
                .find_map(|(n, v)| v.iter().position(|x| !x.is_finite()).map(|i| (*n, i)))
        {
            return Err(Error::profile(format!("{name}[{i}]"), "not a finite number"));
        }
        Ok(())
    }

    /// The leading edge `(x_up[0], y_up[0])` (BladeX `_update_edges`).
    ///
    /// # Errors
    ///
    /// [`Error::Profile`] when the two sides do not start (or end) at the same x within 1e-4.
    pub fn leading_edge(&self) -> Result<[f64; 2]> {
        self.check_shapes()?;
        if (self.xup[0] - self.xdown[0]).abs() > 1e-4 {
            return Err(Error::profile("xdown[0]", format!("{} is not xup[0] = {}", self.xdown[0], self.xup[0])));
        }
        let (nu, nd) = (self.xup.len() - 1, self.xdown.len() - 1);
        if (self.xup[nu] - self.xdown[nd]).abs() > 1e-4 {
            return Err(Error::profile(
                format!("xdown[{nd}]"),
                format!("{} is not xup[{nu}] = {}", self.xdown[nd], self.xup[nu]),
            ));
        }
        Ok([self.xup[0], self.yup[0]])
    }

    /// The trailing edge: `x_up[-1]` and the mean of the two last y (BladeX
    /// `_update_edges`: an open trailing edge is represented by its midpoint).
    ///
    /// # Errors
    ///
    /// As [`leading_edge`](Self::leading_edge).
    pub fn trailing_edge(&self) -> Result<[f64; 2]> {
        self.leading_edge()?;
        let (yu, yd) = (self.yup[self.yup.len() - 1], self.ydown[self.ydown.len() - 1]);
        let y = if yu == yd { yu } else { 0.5 * (yu + yd) };
        Ok([self.xup[self.xup.len() - 1], y])
    }

    /// The chord midpoint (BladeX `reference_point`).
    ///
    /// # Errors
    ///
    /// As [`leading_edge`](Self::leading_edge).
    pub fn reference_point(&self) -> Result<[f64; 2]> {
        let (le, te) = (self.leading_edge()?, self.trailing_edge()?);
        Ok([0.5 * (le[0] + te[0]), 0.5 * (le[1] + te[1])])
    }

    /// The gap between the two trailing-edge points.
    pub fn trailing_edge_gap(&self) -> f64 {
        let (nu, nd) = (self.xup.len() - 1, self.xdown.len() - 1);
        (self.xup[nu] - self.xdown[nd]).hypot(self.yup[nu] - self.ydown[nd])
    }

    fn same_x(&self) -> bool {
        self.xup == self.xdown
    }

    /// Chord, camber and thickness measurements (BladeX `generate_parameters`). The
    /// American thickness is measured along the normal of the camber line through each
    /// camber point, to where it crosses the upper and lower polylines (BladeX solves the
    /// same intersection with an RBF fit of the lower side and Newton's method, so its
    /// American figures differ from these by that fit's error).
    ///
    /// # Errors
    ///
    /// As [`leading_edge`](Self::leading_edge); [`Error::Profile`] for a zero chord.
    pub fn parameters(&self, convention: Convention) -> Result<ProfileParameters> {
        let (le, te) = (self.leading_edge()?, self.trailing_edge()?);
        let chord_length = (le[0] - te[0]).hypot(le[1] - te[1]);
        if chord_length <= 0.0 {
            return Err(Error::profile("chord", "zero chord length"));
        }
        if self.yup.len() != self.ydown.len() {
            return Err(Error::profile("ydown", "parameters need as many lower as upper points"));
        }
        let xmin = self.xup.iter().copied().fold(f64::INFINITY, f64::min);
        let chord_percentage: Vec<f64> = self.xup.iter().map(|x| (x - xmin) / chord_length).collect();
        let camber: Vec<f64> = self.yup.iter().zip(&self.ydown).map(|(u, d)| (u + d) / 2.0).collect();
        let camber_max = max_of(&camber).abs();
        let camber_percentage: Vec<f64> =
            if camber_max == 0.0 { vec![0.0; camber.len()] } else { camber.iter().map(|c| c / camber_max).collect() };
        let thickness: Vec<f64> = if convention == Convention::British || camber_max == 0.0 {
            self.yup.iter().zip(&self.ydown).map(|(u, d)| (u - d).abs()).collect()
        } else {
            self.american_thickness(&camber)
        };
        let thickness_max = max_of(&thickness);
        let thickness_percentage: Vec<f64> = if thickness_max == 0.0 {
            vec![0.0; thickness.len()]
        } else {
            thickness.iter().map(|t| t / thickness_max).collect()
        };
        Ok(ProfileParameters {
            chord_length,
            camber_max_position: chord_percentage[argmax(&camber)],
            thickness_max_position: chord_percentage[argmax(&thickness)],
            chord_percentage,
            camber_max,
            camber_percentage,
            thickness_max,
            thickness_percentage,
        })
    }

    /// Thickness along the camber-line normal at each camber point `(x_up[i], camber[i])`.
    fn american_thickness(&self, camber: &[f64]) -> Vec<f64> {
        let n = camber.len();
        let x = &self.xup;
        (0..n)
            .map(|i| {
                let (a, b) = if i == 0 { (0, 1.min(n - 1)) } else { (i - 1, i) };
                let dx = x[b] - x[a];
                let slope = if dx != 0.0 { (camber[b] - camber[a]) / dx } else { 0.0 };
                let th = slope.atan();
                let normal = [-th.sin(), th.cos()];
                let c = [x[i], camber[i]];
                let up = line_polyline(c, normal, &self.xup, &self.yup, true);
                let down = line_polyline(c, normal, &self.xdown, &self.ydown, false);
                match (up, down) {
                    (Some(su), Some(sd)) => su - sd,
                    _ => (self.yup[i] - self.ydown[i]).abs(),
                }
            })
            .collect()
    }

    /// Coordinates re-sampled at `num` equally spaced x per side by Wendland C² RBF
    /// interpolation of radius `radius`: `(x_up, x_down, y_up, y_down)` (BladeX
    /// `interpolate_coordinates`).
    ///
    /// # Errors
    ///
    /// [`Error::Profile`] for `num == 0` or a non-positive radius; a singular kernel matrix.
    pub fn interpolate_coordinates(&self, num: usize, radius: f64) -> Result<[Vec<f64>; 4]> {
        if num == 0 || radius.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(Error::profile("num/radius", "must be positive"));
        }
        self.check_shapes()?;
        let xu = linspace(self.xup[0], self.xup[self.xup.len() - 1], num);
        let yu = reconstruct(&self.xup, &self.yup, &xu, radius)?;
        let xd = linspace(self.xdown[0], self.xdown[self.xdown.len() - 1], num);
        let yd = reconstruct(&self.xdown, &self.ydown, &xd, radius)?;
        Ok([xu, xd, yu, yd])
    }

    /// The chord line `(x, y)` (BladeX `compute_chord_line`); `n` equally spaced points,
    /// or the upper x when `n` is `None` and both sides share their x.
    ///
    /// # Errors
    ///
    /// As [`leading_edge`](Self::leading_edge).
    pub fn chord_line(&self, n: Option<usize>) -> Result<(Vec<f64>, Vec<f64>)> {
        let (le, te) = (self.leading_edge()?, self.trailing_edge()?);
        let aratio = (te[1] - le[1]) / (te[0] - le[0]);
        let n = if !self.same_x() && n.is_none() { Some(500) } else { n };
        let xs = match n {
            Some(n) if n > 0 => linspace(le[0], te[0], n),
            _ => self.xup.clone(),
        };
        let ys = xs.iter().map(|x| aratio * (x - le[0]) + le[1]).collect();
        Ok((xs, ys))
    }

    /// The mean camber line (BladeX `compute_camber_line`): midpoints of the sides at
    /// equal x, re-sampled at `n` points by RBF when `n` is given or the sides' x differ.
    ///
    /// # Errors
    ///
    /// As [`interpolate_coordinates`](Self::interpolate_coordinates).
    pub fn camber_line(&self, n: Option<usize>) -> Result<(Vec<f64>, Vec<f64>)> {
        self.check_shapes()?;
        let n = if !self.same_x() && n.is_none() { Some(500) } else { n };
        match n {
            Some(n) if n > 0 => {
                let [_, xd, yu, yd] = self.interpolate_coordinates(n, 1.0)?;
                Ok((xd, yu.iter().zip(&yd).map(|(u, d)| 0.5 * (u + d)).collect()))
            }
            _ => Ok((self.xup.clone(), self.yup.iter().zip(&self.ydown).map(|(u, d)| 0.5 * (d + u)).collect())),
        }
    }

    /// The largest `|y_up − y_down|` at equal x (BladeX `max_thickness`, British).
    ///
    /// # Errors
    ///
    /// As [`interpolate_coordinates`](Self::interpolate_coordinates).
    pub fn max_thickness(&self, n: Option<usize>) -> Result<f64> {
        self.check_shapes()?;
        let n = if !self.same_x() && n.is_none() { Some(500) } else { n };
        match n {
            Some(n) if n > 0 => {
                let [_, _, yu, yd] = self.interpolate_coordinates(n, 1.0)?;
                Ok(yu.iter().zip(&yd).map(|(u, d)| (u - d).abs()).fold(f64::NEG_INFINITY, f64::max))
            }
            _ => Ok(self.yup.iter().zip(&self.ydown).map(|(u, d)| (u - d).abs()).fold(f64::NEG_INFINITY, f64::max)),
        }
    }

    /// The signed largest distance between chord line and camber line, negative when the
    /// camber line is below the chord there (BladeX `max_camber`, default `n = 500`).
    ///
    /// # Errors
    ///
    /// As [`camber_line`](Self::camber_line).
    pub fn max_camber(&self, n: Option<usize>) -> Result<f64> {
        let (cx, cy) = self.chord_line(n)?;
        let (mx, my) = self.camber_line(n)?;
        let m = cx.len().min(mx.len());
        let d: Vec<f64> = (0..m).map(|i| (cx[i] - mx[i]).hypot(cy[i] - my[i])).collect();
        let k = argmax(&d);
        Ok(if my[k] < cy[k] { -d[k] } else { d[k] })
    }

    /// Scales the camber line by `1 + percent/100` keeping the half thickness (BladeX
    /// `deform_camber_line`; re-samples at `n` (or 500) points when the sides' x differ).
    ///
    /// # Errors
    ///
    /// As [`camber_line`](Self::camber_line).
    pub fn deform_camber_line(&mut self, percent_change: f64, n: Option<usize>) -> Result<()> {
        let (_, mut cy) = self.camber_line(n)?;
        let factor = percent_change / 100.0 + 1.0;
        for c in &mut cy {
            *c *= factor;
        }
        let n = if !self.same_x() && n.is_none() { Some(500) } else { n };
        if let Some(n) = n.filter(|n| *n > 0) {
            let [xu, xd, yu, yd] = self.interpolate_coordinates(n, 1.0)?;
            *self = Self::from_parts(xu, yu, xd, yd);
        }
        let half: Vec<f64> = self.yup.iter().zip(&self.ydown).map(|(u, d)| 0.5 * (u - d).abs()).collect();
        self.yup = cy.iter().zip(&half).map(|(c, h)| c + h).collect();
        self.ydown = cy.iter().zip(&half).map(|(c, h)| c - h).collect();
        Ok(())
    }

    /// Rescales the camber to the maximum `camber_max` (BladeX `set_camber_line_max`).
    ///
    /// # Errors
    ///
    /// [`Error::Profile`] for a profile without camber; as [`deform_camber_line`](Self::deform_camber_line).
    pub fn set_camber_line_max(&mut self, camber_max: f64) -> Result<()> {
        let old = self.max_camber(Some(500))?;
        if old == 0.0 {
            return Err(Error::profile("camber", "a symmetric profile has no camber to rescale"));
        }
        self.deform_camber_line(100.0 * (camber_max - old) / old, None)
    }

    /// Scales y so that the maximum thickness becomes `thickness_max` (BladeX
    /// `set_thickness_max`).
    ///
    /// # Errors
    ///
    /// As [`max_thickness`](Self::max_thickness).
    pub fn set_thickness_max(&mut self, thickness_max: f64) -> Result<()> {
        let old = self.max_thickness(None)?;
        let ratio = if old != 0.0 { thickness_max / old } else { 0.0 };
        for y in self.yup.iter_mut().chain(self.ydown.iter_mut()) {
            *y *= ratio;
        }
        Ok(())
    }

    /// Moves every point by `(dx, dy)` (BladeX `translate`).
    pub fn translate(&mut self, d: [f64; 2]) {
        for x in self.xup.iter_mut().chain(self.xdown.iter_mut()) {
            *x += d[0];
        }
        for y in self.yup.iter_mut().chain(self.ydown.iter_mut()) {
            *y += d[1];
        }
    }

    /// Rotates counter-clockwise by `angle` radians about the origin (BladeX `rotate`).
    pub fn rotate(&mut self, angle: f64) {
        let (s, c) = (angle.sin(), angle.cos());
        for (x, y) in
            self.xup.iter_mut().zip(self.yup.iter_mut()).chain(self.xdown.iter_mut().zip(self.ydown.iter_mut()))
        {
            let (x0, y0) = (*x, *y);
            *x = c * x0 + (-s) * y0;
            *y = s * x0 + c * y0;
        }
    }

    /// Mirrors about both axes, `(x, y) → (−x, −y)` (BladeX `reflect`).
    pub fn reflect(&mut self) {
        for v in
            self.xup.iter_mut().chain(self.xdown.iter_mut()).chain(self.yup.iter_mut()).chain(self.ydown.iter_mut())
        {
            *v *= -1.0;
        }
    }

    /// Scales by `factor` about the reference point (`about_reference`) or the origin
    /// (BladeX `scale`).
    ///
    /// # Errors
    ///
    /// As [`reference_point`](Self::reference_point).
    pub fn scale(&mut self, factor: f64, about_reference: bool) -> Result<()> {
        let r = if about_reference { self.reference_point()? } else { [0.0, 0.0] };
        if about_reference {
            self.translate([-r[0], -r[1]]);
        }
        for v in
            self.xup.iter_mut().chain(self.xdown.iter_mut()).chain(self.yup.iter_mut()).chain(self.ydown.iter_mut())
        {
            *v *= factor;
        }
        if about_reference {
            self.translate(r);
        }
        Ok(())
    }
}

/// Where the line `c + s·n` first crosses the polyline `(xs, ys)`: the crossing with
/// the smallest `s > 0` (`positive`) or the largest `s < 0`.
fn line_polyline(c: [f64; 2], n: [f64; 2], xs: &[f64], ys: &[f64], positive: bool) -> Option<f64> {
    let mut best: Option<f64> = None;
    for k in 0..xs.len().saturating_sub(1) {
        let (a, b) = ([xs[k], ys[k]], [xs[k + 1], ys[k + 1]]);
        let e = [b[0] - a[0], b[1] - a[1]];
        let den = n[0] * (-e[1]) - n[1] * (-e[0]);
        if den.abs() < 1e-300 {
            continue;
        }
        let r = [a[0] - c[0], a[1] - c[1]];
        let s = (r[0] * (-e[1]) - r[1] * (-e[0])) / den;
        let t = (n[0] * r[1] - n[1] * r[0]) / den;
        if !(-1e-12..=1.0 + 1e-12).contains(&t) {
            continue;
        }
        let ok = if positive { s >= 0.0 } else { s <= 0.0 };
        if ok && best.is_none_or(|b| s.abs() < b.abs()) {
            best = Some(s);
        }
    }
    best
}
