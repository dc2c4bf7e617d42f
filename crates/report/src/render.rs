//! Static pictures of a scene: one state of the model in one [`View`], with its seams
//! coloured by gap and optionally the FFD lattice and control nets.

use crate::camera::{Camera, View};
use crate::raster::Image;
use crate::scene::{ModelView, Scene};
use crate::Result;

/// What a picture shows besides the faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layers {
    /// The seam lines, coloured by gap.
    pub seams: bool,
    /// The FFD lattice (original in grey, moved in blue).
    pub lattice: bool,
    /// The faces' control nets.
    pub nets: bool,
    /// Faces shaded by a head light; unlit, each face is flat in its colour, so two
    /// pictures differ exactly where the faces' outlines moved by a pixel or more.
    pub lit: bool,
}

impl Layers {
    /// Faces only.
    pub const FACES: Layers = Layers { seams: false, lattice: false, nets: false, lit: true };
    /// Faces, unlit.
    pub const OUTLINES: Layers = Layers { seams: false, lattice: false, nets: false, lit: false };
    /// Faces and seams.
    pub const SEAMS: Layers = Layers { seams: true, lattice: false, nets: false, lit: true };
}

/// Colours of the faces, by face index (repeating).
pub const FACE_COLOURS: [[u8; 3]; 6] =
    [[176, 190, 205], [205, 190, 170], [180, 205, 180], [205, 180, 200], [200, 200, 160], [170, 195, 215]];
/// Colour of the undisplaced lattice.
pub const LATTICE_ORIGINAL: [u8; 3] = [120, 120, 120];
/// Colour of the displaced lattice.
pub const LATTICE_MOVED: [u8; 3] = [30, 80, 220];
/// Colour of the control nets.
pub const NET: [u8; 3] = [150, 60, 160];

/// The camera of `view` for pictures of `scene` of `width × height` pixels: framed on
/// the box of every state and the lattice, so it is the same for before and after.
pub fn camera(scene: &Scene, view: &View, width: u32, height: u32) -> Option<Camera> {
    Camera::fit(view, scene.min, scene.max, width, height)
}

/// Draws `state` of `scene` with `cam`.
///
/// # Errors
///
/// [`crate::Error::ImageSize`] for a camera of an impossible size.
pub fn render(scene: &Scene, state: &ModelView, cam: &Camera, layers: Layers) -> Result<Image> {
    let mut img = Image::new(cam.width, cam.height)?;
    for (k, f) in state.faces.iter().enumerate() {
        let colour = FACE_COLOURS[k % FACE_COLOURS.len()];
        let normals = if layers.lit { None } else { Some(vec![cam.towards_eye(); f.mesh.normals.len()]) };
        img.triangles(cam, &f.mesh.positions, normals.as_deref().unwrap_or(&f.mesh.normals), &f.mesh.triangles, colour);
    }
    // Lines show through a little depth (their own sampling against the triangles').
    let bias = 2e-3 * scene.size;
    if layers.nets {
        for f in &state.faces {
            for i in 0..f.net_u {
                let row: Vec<_> = (0..f.net_v).map(|j| f.net[i * f.net_v + j]).collect();
                img.polyline(cam, &row, &[NET], 1, f64::INFINITY);
            }
            for j in 0..f.net_v {
                let col: Vec<_> = (0..f.net_u).map(|i| f.net[i * f.net_v + j]).collect();
                img.polyline(cam, &col, &[NET], 1, f64::INFINITY);
            }
        }
    }
    if layers.lattice {
        if let Some(l) = &scene.lattice {
            for [a, b] in l.lines() {
                img.polyline(cam, &[l.original[a], l.original[b]], &[LATTICE_ORIGINAL], 1, f64::INFINITY);
                img.polyline(cam, &[l.moved[a], l.moved[b]], &[LATTICE_MOVED], 1, f64::INFINITY);
            }
        }
    }
    if layers.seams {
        for s in &state.seams {
            let colours: Vec<[u8; 3]> = s.gap.iter().map(|&g| scene.gap_scale.colour(g)).collect();
            img.polyline(cam, &s.points, &colours, 3, bias);
        }
    }
    Ok(img)
}

/// A static picture: a view of one state, as PNG.
#[derive(Debug, Clone)]
pub struct Picture {
    /// The view's name (`side`, `plan`, ...).
    pub view: &'static str,
    /// The state's name (`before`, `after`).
    pub state: String,
    /// The PNG file's bytes.
    pub png: Vec<u8>,
}

/// Every [`VIEWS`](crate::camera::VIEWS) view of every state of `scene`, faces and seams
/// (and the lattice on the "after" pictures), `width × height` pixels each.
///
/// # Errors
///
/// [`crate::Error::ImageSize`], [`crate::Error::NotFinite`] for a scene without finite bounds,
/// [`crate::Error::Png`].
pub fn pictures(scene: &Scene, width: u32, height: u32) -> Result<Vec<Picture>> {
    let mut out = Vec::new();
    for view in &crate::camera::VIEWS {
        let cam = camera(scene, view, width, height)
            .ok_or_else(|| crate::Error::NotFinite { what: "the scene's bounding box".into() })?;
        for state in std::iter::once(&scene.before).chain(scene.after.as_ref()) {
            let layers = Layers { seams: true, lattice: state.name == "after", nets: false, lit: true };
            let png = render(scene, state, &cam, layers)?.to_png()?;
            out.push(Picture { view: view.name, state: state.name.clone(), png });
        }
    }
    Ok(out)
}
