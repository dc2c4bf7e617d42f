//! glTF 2.0 binary (`.glb`) export: one node per face, named by its entity, with the
//! seam colouring as vertex colours, plus the seam edges (and the FFD lattice) as lines.
//!
//! Each face is a triangle mesh (`POSITION`, `NORMAL`, `COLOR_0`, `u32` indices) on the
//! parameter grid of [`crate::grid`]. Vertices on a face's boundary that lie on a seam
//! take the colour of the seam's gap there ([`crate::colour`], converted to linear as
//! glTF colours are); the others the face's colour. Node and mesh names are the face
//! entities (`DE 3`, `#12`); `extras` carry the entity and the surface type.

use serde_json::{json, Value};

use crate::render::{FACE_COLOURS, LATTICE_MOVED, LATTICE_ORIGINAL};
use crate::scene::{ModelView, Scene};
use crate::seamline::SeamLine;
use crate::Result;

fn linear(c: [u8; 3]) -> [f32; 3] {
    c.map(|v| {
        let s = v as f64 / 255.0;
        (if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }) as f32
    })
}

/// Binary buffer and the JSON objects that point into it.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn view(&mut self, bytes: &[u8], target: u32) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.views.push(json!({ "buffer": 0, "byteOffset": offset, "byteLength": bytes.len(), "target": target }));
        self.views.len() - 1
    }

    fn vec3(&mut self, v: &[[f32; 3]], bounds: bool) -> usize {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, 34962);
        let mut a = json!({ "bufferView": view, "componentType": 5126, "count": v.len(), "type": "VEC3" });
        if bounds {
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for p in v {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            a["min"] = json!(lo);
            a["max"] = json!(hi);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    fn indices(&mut self, idx: &[u32], vertices: usize) -> usize {
        let bytes: Vec<u8> = idx.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, 34963);
        let max = idx.iter().copied().max().unwrap_or(0).min(vertices.saturating_sub(1) as u32);
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5125, "count": idx.len(), "type": "SCALAR",
            "min": [idx.iter().copied().min().unwrap_or(0)], "max": [max],
        }));
        self.accessors.len() - 1
    }
}

fn f32s(p: &[f64; 3]) -> [f32; 3] {
    p.map(|c| c as f32)
}

/// A unit normal in `f32` (the validator checks unit length); a zero normal (a singular
/// point) becomes the face's mean normal, or +z.
fn unit_normals(n: &[[f64; 3]]) -> Vec<[f32; 3]> {
    let mean = n.iter().fold([0.0; 3], |a, v| [a[0] + v[0], a[1] + v[1], a[2] + v[2]]);
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let fallback = if norm(mean) > 1e-12 { mean.map(|c| c / norm(mean)) } else { [0.0, 0.0, 1.0] };
    n.iter()
        .map(|&v| {
            let l = norm(v);
            let u = if l > 0.5 { v.map(|c| c / l) } else { fallback };
            let f = u.map(|c| c as f32);
            let lf = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            f.map(|c| c / lf)
        })
        .collect()
}

/// Vertex colours of face `index` of `state`: the face colour, and on boundary vertices
/// that lie on one of the face's seams (within `band`) the seam's gap colour there.
fn face_colours(scene: &Scene, state: &ModelView, index: usize, band: f64) -> Vec<[f32; 3]> {
    let f = &state.faces[index];
    let base = linear(FACE_COLOURS[index % FACE_COLOURS.len()]);
    let mut out = vec![base; f.mesh.positions.len()];
    let seams: Vec<&SeamLine> = state.seams.iter().filter(|s| s.patches.contains(&index)).collect();
    if seams.is_empty() {
        return out;
    }
    let (nu, nv) = (f.mesh.nu, f.mesh.nv);
    for j in 0..nv {
        for i in 0..nu {
            if !(i == 0 || j == 0 || i == nu - 1 || j == nv - 1) {
                continue;
            }
            let k = j * nu + i;
            let p = f.mesh.positions[k];
            let mut best = (band * band, None);
            for s in &seams {
                for (q, g) in s.points.iter().zip(&s.gap) {
                    let d = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
                    if d <= best.0 {
                        best = (d, Some(*g));
                    }
                }
            }
            if let (_, Some(g)) = best {
                out[k] = linear(scene.gap_scale.colour(g));
            }
        }
    }
    out
}

fn lines(b: &mut Builder, name: &str, segments: &[([f64; 3], [f64; 3], [u8; 3])]) -> Value {
    let pos: Vec<[f32; 3]> = segments.iter().flat_map(|(p, q, _)| [f32s(p), f32s(q)]).collect();
    let col: Vec<[f32; 3]> = segments.iter().flat_map(|(_, _, c)| [linear(*c), linear(*c)]).collect();
    let p = b.vec3(&pos, true);
    let c = b.vec3(&col, false);
    json!({ "name": name, "primitives": [{ "attributes": { "POSITION": p, "COLOR_0": c }, "mode": 1 }] })
}

/// The `.glb` bytes of the state shown by default ([`Scene::shown`]).
///
/// # Errors
///
/// [`crate::Error::Json`].
pub fn to_glb(scene: &Scene) -> Result<Vec<u8>> {
    let state = scene.shown();
    let mut b = Builder::default();
    let (mut meshes, mut nodes) = (Vec::new(), Vec::new());
    let band = 1e-3 * scene.size;
    for (k, f) in state.faces.iter().enumerate() {
        let pos: Vec<[f32; 3]> = f.mesh.positions.iter().map(f32s).collect();
        let p = b.vec3(&pos, true);
        let n = b.vec3(&unit_normals(&f.mesh.normals), false);
        let c = b.vec3(&face_colours(scene, state, k, band), false);
        let idx: Vec<u32> = f.mesh.triangles.iter().flatten().copied().collect();
        let i = b.indices(&idx, pos.len());
        meshes.push(json!({
            "name": f.name,
            "primitives": [{ "attributes": { "POSITION": p, "NORMAL": n, "COLOR_0": c }, "indices": i, "mode": 4 }],
        }));
        nodes.push(json!({ "name": f.name, "mesh": meshes.len() - 1, "extras": { "face": f.name, "kind": f.kind } }));
    }
    let seg: Vec<_> = state
        .seams
        .iter()
        .flat_map(|s| {
            s.points.windows(2).zip(&s.gap).map(|(w, g)| (w[0], w[1], scene.gap_scale.colour(*g))).collect::<Vec<_>>()
        })
        .collect();
    if !seg.is_empty() {
        meshes.push(lines(&mut b, "seams", &seg));
        nodes.push(json!({ "name": "seams", "mesh": meshes.len() - 1 }));
    }
    if let Some(l) = &scene.lattice {
        for (name, pts, c) in [
            ("FFD lattice (original)", &l.original, LATTICE_ORIGINAL),
            ("FFD lattice (moved)", &l.moved, LATTICE_MOVED),
        ] {
            let seg: Vec<_> = l.lines().iter().map(|&[i, j]| (pts[i], pts[j], c)).collect();
            if !seg.is_empty() {
                meshes.push(lines(&mut b, name, &seg));
                nodes.push(json!({ "name": name, "mesh": meshes.len() - 1 }));
            }
        }
    }
    while b.bin.len() % 4 != 0 {
        b.bin.push(0);
    }
    let doc = json!({
        "asset": { "version": "2.0", "generator": format!("cadmorph {}", env!("CARGO_PKG_VERSION")) },
        "scene": 0,
        "scenes": [{ "name": state.source, "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": meshes,
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{ "byteLength": b.bin.len() }],
    });
    let mut j = serde_json::to_vec(&doc)?;
    while j.len() % 4 != 0 {
        j.push(b' ');
    }
    let total = 12 + 8 + j.len() + 8 + b.bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b.bin);
    Ok(out)
}
