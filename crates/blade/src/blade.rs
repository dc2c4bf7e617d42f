//! A blade from its sections and radial distributions, placed in 3D as BladeX
//! `Blade.apply_transformations` places it (paper §2.2.2, Figure 12).

use cadmorph_nurbs::math::{Matrix4, Point3, Vector3};

use crate::profile::Profile;
use crate::{Error, Result};

/// A blade design: one profile per radial section (root first) and the radial
/// distributions BladeX's `Blade` takes, all in the same length unit; skew in degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct Blade {
    /// The 2D profiles (unit chord or not; they are scaled to `chord`).
    pub sections: Vec<Profile>,
    /// Section radii, strictly increasing from root to tip.
    pub radii: Vec<f64>,
    /// Chord length per section.
    pub chord: Vec<f64>,
    /// Pitch (advance per revolution) per section.
    pub pitch: Vec<f64>,
    /// Rake per section.
    pub rake: Vec<f64>,
    /// Skew angle per section, degrees.
    pub skew: Vec<f64>,
    /// Optional maximum thickness per section (BladeX `thickness`).
    pub thickness: Option<Vec<f64>>,
    /// Optional maximum camber per section (BladeX `camber`; like BladeX, not applied to
    /// the tip section).
    pub camber: Option<Vec<f64>>,
}

/// Section points in 3D, root section first; each section is a list of points from the
/// leading to the trailing edge. The propeller axis is x; a section of radius `r` lies
/// on the cylinder `y² + z² = r²`.
#[derive(Debug, Clone, PartialEq)]
pub struct BladeCoordinates {
    /// Upper (suction) side per section.
    pub up: Vec<Vec<Point3<f64>>>,
    /// Lower (pressure) side per section.
    pub down: Vec<Vec<Point3<f64>>>,
}

impl BladeCoordinates {
    /// Applies the affine map `m` to every point.
    pub fn transform_by(&mut self, m: &Matrix4<f64>) {
        for p in self.up.iter_mut().chain(self.down.iter_mut()).flatten() {
            *p = m.transform_point(p);
        }
    }
}

/// Wraps the planar point `(x, y)` onto the cylinder of radius `r`: the arc length `y`
/// becomes the angle `y / r` (BladeX `_planar_to_cylindrical`: `(x, r sin(y/r), r cos(y/r))`).
/// The result lies on the cylinder exactly, and arc lengths along it equal the planar y.
pub fn wrap(x: f64, y: f64, r: f64) -> Point3<f64> {
    let theta = y / r;
    Point3::new(x, r * theta.sin(), r * theta.cos())
}

impl Blade {
    /// A blade design, checked.
    ///
    /// # Errors
    ///
    /// [`Error::Table`] naming the field and section: lengths that differ from the
    /// number of sections, fewer than 2 sections, radii not strictly increasing or not
    /// positive, a chord that is not positive, non-finite values.
    pub fn try_new(
        sections: Vec<Profile>,
        radii: Vec<f64>,
        chord: Vec<f64>,
        pitch: Vec<f64>,
        rake: Vec<f64>,
        skew: Vec<f64>,
    ) -> Result<Self> {
        let b = Self { sections, radii, chord, pitch, rake, skew, thickness: None, camber: None };
        b.check()?;
        Ok(b)
    }

    /// Checks the design (see [`try_new`](Self::try_new)).
    ///
    /// # Errors
    ///
    /// As [`try_new`](Self::try_new).
    pub fn check(&self) -> Result<()> {
        let n = self.sections.len();
        if n < 2 {
            return Err(Error::table("sections", None, format!("{n} sections: at least 2 are needed")));
        }
        let mut fields: Vec<(&str, &[f64])> = vec![
            ("radii", &self.radii),
            ("chord", &self.chord),
            ("pitch", &self.pitch),
            ("rake", &self.rake),
            ("skew", &self.skew),
        ];
        if let Some(t) = &self.thickness {
            fields.push(("thickness", t));
        }
        if let Some(c) = &self.camber {
            fields.push(("camber", c));
        }
        for (name, v) in &fields {
            if v.len() != n {
                return Err(Error::table(name, None, format!("{} values for {n} sections", v.len())));
            }
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::table(name, Some(i), format!("{} is not a finite number", v[i])));
            }
        }
        for i in 0..n {
            if self.radii[i] <= 0.0 {
                return Err(Error::table("radii", Some(i), format!("radius {} must be positive", self.radii[i])));
            }
            if i > 0 && self.radii[i] <= self.radii[i - 1] {
                return Err(Error::table(
                    "radii",
                    Some(i),
                    format!("radius {} does not increase (previous {})", self.radii[i], self.radii[i - 1]),
                ));
            }
            if self.chord[i] <= 0.0 {
                return Err(Error::table("chord", Some(i), format!("chord {} must be positive", self.chord[i])));
            }
            if let Some(t) = &self.thickness {
                if t[i] <= 0.0 {
                    return Err(Error::table("thickness", Some(i), format!("thickness {} must be positive", t[i])));
                }
            }
            self.sections[i].leading_edge().map_err(|e| Error::table("sections", Some(i), e.to_string()))?;
        }
        Ok(())
    }

    /// Number of sections.
    pub fn len(&self) -> usize {
        self.sections.len()
    }

    /// Whether there is no section.
    pub fn is_empty(&self) -> bool {
        self.sections.is_empty()
    }

    /// Pitch angles `φ = atan(P / 2πr)` in radians (BladeX `pitch_angles`).
    pub fn pitch_angles(&self) -> Vec<f64> {
        self.pitch.iter().zip(&self.radii).map(|(p, r)| (p / (2.0 * std::f64::consts::PI * r)).atan()).collect()
    }

    /// Rake induced by skew, `r · θₛ · tan φ` (BladeX `induced_rake`).
    pub fn induced_rake(&self) -> Vec<f64> {
        self.pitch_angles()
            .iter()
            .zip(&self.radii)
            .zip(&self.skew)
            .map(|((phi, r), s)| r * s.to_radians() * phi.tan())
            .collect()
    }

    /// The sections as they are (no scaling or placement) wrapped on their cylinders
    /// (BladeX `_planar_to_cylindrical` alone).
    pub fn planar_to_cylindrical(&self) -> BladeCoordinates {
        wrap_sections(&self.sections, &self.radii)
    }

    /// The planar sections after BladeX's transformations, before wrapping: moved so
    /// the chord midpoint is at the origin, scaled to the chord, thickness and camber set
    /// when given, reflected (`reflect`), rotated by `π/2 − φ`, moved by `−r θₛ` in y (skew)
    /// and `−(rake + induced rake)` in x (BladeX `apply_transformations` steps 1–5).
    ///
    /// # Errors
    ///
    /// Those of the profile operations (a section without chord, a symmetric section
    /// given a camber).
    pub fn transformed_sections(&self, reflect: bool) -> Result<Vec<Profile>> {
        self.check()?;
        let phi = self.pitch_angles();
        let induced = self.induced_rake();
        let n = self.len();
        let mut out = Vec::with_capacity(n);
        for (i, s) in self.sections.iter().enumerate() {
            let mut s = s.clone();
            let at = |e: Error| Error::table("sections", Some(i), e.to_string());
            let r = s.reference_point().map_err(at)?;
            s.translate([-r[0], -r[1]]);
            s.scale(self.chord[i], true).map_err(at)?;
            if let Some(t) = &self.thickness {
                s.set_thickness_max(t[i]).map_err(at)?;
            }
            if let Some(c) = &self.camber {
                if i < n - 1 {
                    s.set_camber_line_max(c[i]).map_err(at)?;
                }
            }
            if reflect {
                s.reflect();
            }
            s.rotate(std::f64::consts::PI / 2.0 - phi[i]);
            s.translate([0.0, -self.radii[i] * self.skew[i].to_radians()]);
            s.translate([-(self.rake[i] + induced[i]), 0.0]);
            out.push(s);
        }
        Ok(out)
    }

    /// The blade's section points in 3D (BladeX `apply_transformations(reflect)`).
    ///
    /// # Errors
    ///
    /// As [`transformed_sections`](Self::transformed_sections).
    pub fn apply_transformations(&self, reflect: bool) -> Result<BladeCoordinates> {
        Ok(wrap_sections(&self.transformed_sections(reflect)?, &self.radii))
    }
}

fn wrap_sections(sections: &[Profile], radii: &[f64]) -> BladeCoordinates {
    let side = |x: &[f64], y: &[f64], r: f64| x.iter().zip(y).map(|(&x, &y)| wrap(x, y, r)).collect::<Vec<_>>();
    BladeCoordinates {
        up: sections.iter().zip(radii).map(|(s, &r)| side(&s.xup, &s.yup, r)).collect(),
        down: sections.iter().zip(radii).map(|(s, &r)| side(&s.xdown, &s.ydown, r)).collect(),
    }
}

/// The rotation by `angle` radians about the coordinate axis `axis` (0 = x, the
/// propeller axis; 1 = y; 2 = z), as BladeX `Blade.rotate` (its y matrix has the sign of
/// a rotation by −angle; this is the right-handed one).
pub fn rotation(axis: usize, angle: f64) -> Matrix4<f64> {
    let v = match axis {
        0 => Vector3::x_axis(),
        1 => Vector3::y_axis(),
        _ => Vector3::z_axis(),
    };
    nalgebra::Rotation3::from_axis_angle(&v, angle).to_homogeneous()
}

/// The mirror in the plane through `point` with normal `normal` (BladeX `Blade.mirror`).
pub fn mirror(point: Point3<f64>, normal: Vector3<f64>) -> Matrix4<f64> {
    let n = normal.normalize();
    let mut m = Matrix4::identity();
    let h = nalgebra::Matrix3::identity() - 2.0 * n * n.transpose();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&h);
    let t = 2.0 * n.dot(&point.coords) * n;
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&t);
    m
}

/// The uniform scaling by `factor` about the origin (BladeX `Blade.scale`).
pub fn scaling(factor: f64) -> Matrix4<f64> {
    Matrix4::new_scaling(factor)
}
