//! A small software rasterizer for the static pictures: depth-buffered triangles with
//! normals interpolated per pixel and a head light, and thick depth-tested lines.
//!
//! No anti-aliasing and no randomness: the same triangles give the same pixels, so two
//! pictures can be compared exactly. Written here rather than taken from a crate because
//! what it needs is small (orthographic, opaque, no textures) and must be deterministic;
//! PNG encoding is the `png` crate's.

use crate::camera::Camera;
use crate::{Error, Result};

/// An RGB picture with its depth buffer.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height × 3` bytes, row by row from the top.
    pub rgb: Vec<u8>,
    depth: Vec<f64>,
}

/// The background of every picture.
pub const BACKGROUND: [u8; 3] = [255, 255, 255];

impl Image {
    /// A blank picture of `width × height` (each 1..=8192).
    ///
    /// # Errors
    ///
    /// [`Error::ImageSize`] out of range.
    pub fn new(width: u32, height: u32) -> Result<Self> {
        if !(1..=8192).contains(&width) || !(1..=8192).contains(&height) {
            return Err(Error::ImageSize { width, height });
        }
        let n = width as usize * height as usize;
        Ok(Self { width, height, rgb: BACKGROUND.repeat(n), depth: vec![f64::NEG_INFINITY; n] })
    }

    /// The colour at pixel `(x, y)`.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = (y as usize * self.width as usize + x as usize) * 3;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    fn put(&mut self, x: i64, y: i64, z: f64, c: [u8; 3], bias: f64) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return;
        }
        let i = y as usize * self.width as usize + x as usize;
        if z + bias >= self.depth[i] {
            self.depth[i] = self.depth[i].max(z);
            self.rgb[i * 3..i * 3 + 3].copy_from_slice(&c);
        }
    }

    /// Draws the triangles `tris` of `positions` with vertex `normals`, in `base` colour
    /// shaded by a light at the eye (both sides lit).
    pub fn triangles(
        &mut self,
        cam: &Camera,
        positions: &[[f64; 3]],
        normals: &[[f64; 3]],
        tris: &[[u32; 3]],
        base: [u8; 3],
    ) {
        let eye = cam.towards_eye();
        let screen: Vec<[f64; 3]> = positions.iter().map(|&p| cam.project(p)).collect();
        let light: Vec<f64> = normals
            .iter()
            .map(|n| {
                let d = (n[0] * eye[0] + n[1] * eye[1] + n[2] * eye[2]).abs();
                0.3 + 0.7 * d
            })
            .collect();
        let (w, h) = (self.width as f64, self.height as f64);
        for t in tris {
            let [a, b, c] = t.map(|k| k as usize);
            let (pa, pb, pc) = (screen[a], screen[b], screen[c]);
            let area = (pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0]);
            if area.abs() < 1e-12 || !area.is_finite() {
                continue;
            }
            let x0 = pa[0].min(pb[0]).min(pc[0]).floor().max(0.0);
            let x1 = pa[0].max(pb[0]).max(pc[0]).ceil().min(w - 1.0);
            let y0 = pa[1].min(pb[1]).min(pc[1]).floor().max(0.0);
            let y1 = pa[1].max(pb[1]).max(pc[1]).ceil().min(h - 1.0);
            if x0 > x1 || y0 > y1 {
                continue;
            }
            for y in y0 as i64..=y1 as i64 {
                let py = y as f64 + 0.5;
                for x in x0 as i64..=x1 as i64 {
                    let px = x as f64 + 0.5;
                    let wa = ((pb[0] - px) * (pc[1] - py) - (pb[1] - py) * (pc[0] - px)) / area;
                    let wb = ((pc[0] - px) * (pa[1] - py) - (pc[1] - py) * (pa[0] - px)) / area;
                    let wc = 1.0 - wa - wb;
                    if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                        continue;
                    }
                    let z = wa * pa[2] + wb * pb[2] + wc * pc[2];
                    let l = wa * light[a] + wb * light[b] + wc * light[c];
                    let col = base.map(|v| (v as f64 * l).round().clamp(0.0, 255.0) as u8);
                    self.put(x, y, z, col, 0.0);
                }
            }
        }
    }

    /// Draws the polyline `points` `thickness` pixels wide, vertex `colours` (one per
    /// point) held along each segment from its first point; a line shows where it is at
    /// most `bias` (model units) behind what is drawn (`f64::INFINITY`: always on top).
    pub fn polyline(&mut self, cam: &Camera, points: &[[f64; 3]], colours: &[[u8; 3]], thickness: u32, bias: f64) {
        let r = thickness.max(1) as i64 / 2;
        let s: Vec<[f64; 3]> = points.iter().map(|&p| cam.project(p)).collect();
        for (k, seg) in s.windows(2).enumerate() {
            let (p, q) = (seg[0], seg[1]);
            let steps = ((q[0] - p[0]).abs().max((q[1] - p[1]).abs()).ceil() as i64).clamp(1, 1 << 16);
            let c = colours.get(k).or(colours.last()).copied().unwrap_or([0, 0, 0]);
            for i in 0..=steps {
                let f = i as f64 / steps as f64;
                let (x, y, z) = (p[0] + (q[0] - p[0]) * f, p[1] + (q[1] - p[1]) * f, p[2] + (q[2] - p[2]) * f);
                let (cx, cy) = (x.floor() as i64, y.floor() as i64);
                for dy in -r..=r {
                    for dx in -r..=r {
                        self.put(cx + dx, cy + dy, z, c, bias);
                    }
                }
            }
        }
    }

    /// The picture as PNG bytes.
    ///
    /// # Errors
    ///
    /// [`Error::Png`] if the encoder fails.
    pub fn to_png(&self) -> Result<Vec<u8>> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header()?;
            w.write_image_data(&self.rgb)?;
            w.finish()?;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Camera, View};

    const FRONT: View = View { name: "t", look: [0.0, 0.0, -1.0], up: [0.0, 1.0, 0.0] };

    #[test]
    fn nearer_triangle_wins_and_covers_its_area() {
        let cam = Camera::fit(&FRONT, [0.0, 0.0, -1.0], [10.0, 10.0, 1.0], 100, 100).unwrap();
        let mut img = Image::new(100, 100).unwrap();
        let n = [[0.0, 0.0, 1.0]; 4];
        let far = [[0.0, 0.0, -1.0], [10.0, 0.0, -1.0], [0.0, 10.0, -1.0], [10.0, 10.0, -1.0]];
        let near = [[0.0, 0.0, 1.0], [5.0, 0.0, 1.0], [0.0, 5.0, 1.0], [5.0, 5.0, 1.0]];
        // Near first, then far: the far one must not paint over it.
        img.triangles(&cam, &near, &n, &[[0, 1, 2], [1, 3, 2]], [200, 0, 0]);
        img.triangles(&cam, &far, &n, &[[0, 1, 2], [1, 3, 2]], [0, 0, 200]);
        let [x, y, _] = cam.project([2.5, 2.5, 1.0]);
        assert_eq!(img.pixel(x as u32, y as u32), [200, 0, 0]);
        let [x, y, _] = cam.project([7.5, 7.5, -1.0]);
        assert_eq!(img.pixel(x as u32, y as u32), [0, 0, 200]);
        assert_eq!(img.pixel(1, 1), BACKGROUND);
        let red = img.rgb.chunks(3).filter(|c| c == &[200, 0, 0]).count();
        // A quarter of the 90 x 90 pixels the box takes.
        assert!((red as f64 - 45.0 * 45.0).abs() < 120.0, "{red}");
        let png = img.to_png().unwrap();
        assert_eq!(&png[1..4], b"PNG");
        assert!(Image::new(0, 10).is_err());
    }
}
