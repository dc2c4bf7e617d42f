//! Orthographic views: a direction to look along, an up direction, and a framing box
//! fitted into the picture.
//!
//! The same [`Camera`] for two pictures (a model before and after its morph, framed on
//! the box of both) maps every point to the same pixel in both, so the pictures can be
//! compared pixel by pixel and a box of the model (the FFD lattice) projected onto them.

use cadmorph_nurbs::math::Vector3;
use serde::Serialize;

/// A named view direction of the static pictures.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct View {
    /// Name, for file names and captions (`side`, `plan`, `front`, `iso`).
    pub name: &'static str,
    /// Direction from the eye to the model.
    pub look: [f64; 3],
    /// What is up in the picture (need not be square to `look`; must not be parallel).
    pub up: [f64; 3],
}

/// The four static views: from +y (side: the outside of a half hull modelled on y ≥ 0),
/// from −z (plan: the bottom), from +x (front) and an oblique one.
pub const VIEWS: [View; 4] = [
    View { name: "side", look: [0.0, -1.0, 0.0], up: [0.0, 0.0, 1.0] },
    View { name: "plan", look: [0.0, 0.0, 1.0], up: [0.0, 1.0, 0.0] },
    View { name: "front", look: [-1.0, 0.0, 0.0], up: [0.0, 0.0, 1.0] },
    View { name: "iso", look: [-1.0, -1.2, -0.6], up: [0.0, 0.0, 1.0] },
];

/// An orthographic camera fitted to a box, for a picture of `width × height` pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    right: Vector3<f64>,
    up: Vector3<f64>,
    back: Vector3<f64>,
    /// Screen centre in view coordinates.
    centre: (f64, f64),
    /// Pixels per model unit.
    scale: f64,
    /// Picture size.
    pub width: u32,
    /// See `width`.
    pub height: u32,
    /// Depth range of the box (view coordinate along `back`), for depth offsets.
    pub depth_range: (f64, f64),
}

impl Camera {
    /// The camera of `view` that fits the box `[min, max]` into `width × height` with a
    /// margin of 5 % on each side. `None` when the box is not finite or the view's
    /// directions are degenerate.
    pub fn fit(view: &View, min: [f64; 3], max: [f64; 3], width: u32, height: u32) -> Option<Self> {
        let look = Vector3::from(view.look).try_normalize(1e-12)?;
        let back = -look;
        let right = look.cross(&Vector3::from(view.up)).try_normalize(1e-12)?;
        let up = right.cross(&look);
        if !min.iter().chain(&max).all(|c| c.is_finite()) {
            return None;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for k in 0..8 {
            let c = Vector3::new(
                if k & 1 == 0 { min[0] } else { max[0] },
                if k & 2 == 0 { min[1] } else { max[1] },
                if k & 4 == 0 { min[2] } else { max[2] },
            );
            let v = [c.dot(&right), c.dot(&up), c.dot(&back)];
            for i in 0..3 {
                lo[i] = lo[i].min(v[i]);
                hi[i] = hi[i].max(v[i]);
            }
        }
        let extent = ((hi[0] - lo[0]) / width as f64).max((hi[1] - lo[1]) / height as f64).max(f64::MIN_POSITIVE);
        let scale = 0.9 / extent;
        Some(Self {
            right,
            up,
            back,
            centre: ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0),
            scale,
            width,
            height,
            depth_range: (lo[2], hi[2]),
        })
    }

    /// Pixel coordinates (x right, y down, from the top-left corner) and depth (larger is
    /// nearer the eye) of `p`.
    pub fn project(&self, p: [f64; 3]) -> [f64; 3] {
        let p = Vector3::from(p);
        let x = (p.dot(&self.right) - self.centre.0) * self.scale + self.width as f64 / 2.0;
        let y = self.height as f64 / 2.0 - (p.dot(&self.up) - self.centre.1) * self.scale;
        [x, y, p.dot(&self.back)]
    }

    /// The direction towards the eye.
    pub fn towards_eye(&self) -> [f64; 3] {
        [self.back.x, self.back.y, self.back.z]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_view_maps_the_box_into_the_picture() {
        let c = Camera::fit(&VIEWS[0], [0.0, 0.0, 0.0], [100.0, 10.0, 10.0], 1000, 200).unwrap();
        // x runs right to left seen from +y; the long side takes 90 % of the width.
        let a = c.project([0.0, 5.0, 5.0]);
        let b = c.project([100.0, 5.0, 5.0]);
        assert!((a[0] - 950.0).abs() < 1e-9 && (b[0] - 50.0).abs() < 1e-9, "{a:?} {b:?}");
        assert!((a[1] - 100.0).abs() < 1e-9);
        // Up is up: a higher point has a smaller row.
        assert!(c.project([0.0, 5.0, 10.0])[1] < a[1]);
        // Nearer the eye (larger y) is larger depth.
        assert!(c.project([0.0, 10.0, 5.0])[2] > a[2]);
        assert!(Camera::fit(&VIEWS[0], [f64::NAN; 3], [1.0; 3], 10, 10).is_none());
    }
}
