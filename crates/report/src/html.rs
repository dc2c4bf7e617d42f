//! The report of one model or one morph as a single self-contained HTML page: the WebGL
//! view, the seam tables, the refinement, the timings and the static pictures.
//!
//! Everything is inside the file (data as JSON with base64 `f32`/`u32` arrays, the
//! viewer script, pictures as `data:` URLs): it opens offline and can be mailed.

use std::fmt::Write;

use base64::Engine;
use cadmorph_seam::{SeamRefinement, SeamReport};
use serde_json::{json, Value};

use crate::chart::PlotFormat;
use crate::growth::{growth_plot, growth_table};
use crate::page::{escape, head, num, png_data_url, script_json, SORT_JS, VIEWER_JS};
use crate::render::{Picture, FACE_COLOURS, LATTICE_MOVED, LATTICE_ORIGINAL, NET};
use crate::scene::{ModelView, Scene};
use crate::Result;

/// What the page says besides the scene.
#[derive(Debug, Clone, Default)]
pub struct PageInfo {
    /// The page title.
    pub title: String,
    /// The refinement of the morph, if it refined.
    pub refinement: Option<SeamRefinement>,
    /// Control points of all faces before and after the morph.
    pub control_points: Option<(usize, usize)>,
    /// Named durations, seconds (reading, morph, report...).
    pub timings: Vec<(String, f64)>,
    /// The refinement's tolerances `(gap in model units, angle in degrees)`, drawn as
    /// lines on the growth plot.
    pub refine_tolerances: Option<(f64, f64)>,
}

/// Pixel size of the refinement growth plot in the page.
pub const GROWTH_PLOT: (u32, u32) = (900, 320);

fn b64_f32(v: &[f32]) -> String {
    base64::engine::general_purpose::STANDARD.encode(v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>())
}

fn b64_u32(v: &[u32]) -> String {
    base64::engine::general_purpose::STANDARD.encode(v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>())
}

fn flat(points: &[[f64; 3]]) -> Vec<f64> {
    points.iter().flatten().copied().collect()
}

fn state_json(s: &ModelView, centre: [f64; 3]) -> Value {
    let faces: Vec<Value> = s
        .faces
        .iter()
        .map(|f| {
            let pos: Vec<f32> =
                f.mesh.positions.iter().flat_map(|p| (0..3).map(move |k| (p[k] - centre[k]) as f32)).collect();
            let nrm: Vec<f32> = f.mesh.normals.iter().flatten().map(|&c| c as f32).collect();
            let idx: Vec<u32> = f.mesh.triangles.iter().flatten().copied().collect();
            json!({
                "name": f.name, "kind": f.kind, "pos": b64_f32(&pos), "nrm": b64_f32(&nrm), "idx": b64_u32(&idx),
                "net": { "nu": f.net_u, "nv": f.net_v, "pts": flat(&f.net) },
            })
        })
        .collect();
    let seams: Vec<Value> = s
        .seams
        .iter()
        .map(|l| {
            json!({
                "faces": l.faces, "patches": l.patches, "edge": l.edge, "pts": flat(&l.points),
                "gap": l.gap, "angle": l.angle_deg, "report": l.report,
            })
        })
        .collect();
    json!({ "name": s.name, "source": s.source, "faces": faces, "seams": seams })
}

/// The data the viewer reads (the `cadmorph-data` script element).
///
/// # Errors
///
/// [`crate::Error::Json`] (non-finite numbers become `null`, which is no error).
pub fn viewer_data(scene: &Scene) -> Result<String> {
    // Face positions are f32 relative to the centre of the box (so they keep about 1e-7
    // of the model size); lines and nets are f64 model coordinates.
    let lattice = scene.lattice.as_ref().map(|l| {
        json!({
            "shape": l.shape, "original": flat(&l.original), "moved": flat(&l.moved),
            "lines": l.lines().into_iter().flatten().collect::<Vec<_>>(),
        })
    });
    let centre: [f64; 3] = std::array::from_fn(|k| (scene.min[k] + scene.max[k]) / 2.0);
    let states: Vec<Value> =
        std::iter::once(&scene.before).chain(scene.after.as_ref()).map(|s| state_json(s, centre)).collect();
    let v = json!({
        "unit": scene.unit, "size": scene.size, "min": scene.min, "max": scene.max, "centre": centre,
        "gapScale": scene.gap_scale, "angleScale": scene.angle_scale,
        "faceColours": FACE_COLOURS, "netColour": NET, "latticeColours": [LATTICE_ORIGINAL, LATTICE_MOVED],
        "camera": { "az": 1.15, "el": 0.35 },
        "states": states, "lattice": lattice,
    });
    Ok(script_json(&serde_json::to_string(&v)?))
}

/// The seam table of `r` (one row per edge, the worst marked) as HTML.
pub fn seam_table(scene: &Scene, state: &ModelView, r: &SeamReport) -> String {
    let mut t = String::from(
        "<table class=\"sortable\"><thead><tr><th>#</th><th class=\"l\">face a</th><th class=\"l\">face b</th>\
         <th>length</th><th>gap closest</th><th>gap matched</th><th>gap mean</th><th>G1 (deg)</th><th>C1 rel</th>\
         <th class=\"l\">edge</th></tr></thead><tbody>\n",
    );
    for (k, e) in r.edges.iter().enumerate() {
        let name = |p: usize| state.faces.get(p).map_or_else(|| p.to_string(), |f| f.name.clone());
        let bad = scene.gap_scale.position(e.gap_closest.max) > 0.5
            || (!e.sharp && scene.angle_scale.position(e.g1_angle_deg.max) > 0.5);
        let _ = writeln!(
            t,
            "<tr{}><td>{k}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td data-v=\"{}\">{}</td>\
             <td data-v=\"{}\">{}</td><td data-v=\"{}\">{}</td><td data-v=\"{}\">{}</td><td data-v=\"{}\">{}{}</td>\
             <td>{}</td><td class=\"l\">{}</td></tr>",
            if bad { " class=\"bad\"" } else { "" },
            escape(&name(e.a.patch)),
            escape(&name(e.b.patch)),
            e.length,
            num(e.length),
            e.gap_closest.max,
            num(e.gap_closest.max),
            e.gap_matched.max,
            num(e.gap_matched.max),
            e.gap_closest.mean,
            num(e.gap_closest.mean),
            e.g1_angle_deg.max,
            num(e.g1_angle_deg.max),
            if e.sharp { " *" } else { "" },
            e.c1_mismatch.map_or_else(|| "–".into(), |s| num(s.max)),
            escape(&e.edge.iter().map(|r| r.to_string()).collect::<Vec<_>>().join(", ")),
        );
    }
    let _ = writeln!(
        t,
        "</tbody></table><p>{} edges ({} sharp, *); max gap closest {} {u}, matched {} {u}; max G1 {} deg (smooth edges)</p>",
        r.edges.len(),
        r.sharp_edges,
        num(r.max_gap_closest),
        num(r.max_gap_matched),
        num(r.max_g1_angle_deg),
        u = escape(&scene.unit),
    );
    t
}

/// The whole page.
///
/// # Errors
///
/// [`crate::Error::Json`]; [`crate::Error::Plot`] when the growth plot cannot be drawn.
pub fn report_html(scene: &Scene, info: &PageInfo, pictures: &[Picture]) -> Result<String> {
    let mut h = head(&info.title);
    let _ = writeln!(h, "<h1>{}</h1>", escape(&info.title));
    let _ = write!(h, "<p>{}", escape(&scene.before.source));
    if let Some(a) = &scene.after {
        let _ = write!(h, " → {}", escape(&a.source));
    }
    let _ = writeln!(
        h,
        "; {} faces, unit {}, size {}; gaps coloured from {} (green) to {} (red), angles from {} to {} deg.</p>",
        scene.before.faces.len(),
        escape(&scene.unit),
        num(scene.size),
        num(scene.gap_scale.good),
        num(scene.gap_scale.bad),
        num(scene.angle_scale.good),
        num(scene.angle_scale.bad),
    );
    let has_after = scene.after.is_some();
    let check = |id: &str, label: &str, on: bool| {
        format!("<label><input type=\"checkbox\" id=\"{id}\"{}> {label}</label>", if on { " checked" } else { "" })
    };
    h.push_str("<div class=\"viewer\"><canvas id=\"view\" width=\"960\" height=\"540\"></canvas><div class=\"side\"><div class=\"layers\">");
    h.push_str(&check("layer-before", "faces before", !has_after));
    if has_after {
        h.push_str(&check("layer-after", "faces after", true));
    }
    h.push_str(&check("layer-net", "control net", false));
    if scene.lattice.is_some() {
        h.push_str(&check("layer-lattice", "FFD lattice (original)", false));
        h.push_str(&check("layer-lattice-moved", "FFD lattice (moved)", false));
    }
    h.push_str(&check("layer-seams", "seam edges", true));
    h.push_str(
        "<label><input type=\"radio\" name=\"colour\" id=\"colour-gap\" checked> colour by C0 gap</label>\
         <label><input type=\"radio\" name=\"colour\" id=\"colour-angle\"> colour by G1 angle</label></div>\
         <p><b id=\"legend-title\"></b></p><canvas id=\"legend\" width=\"320\" height=\"36\"></canvas>\
         <p><button id=\"reset-view\">reset view</button> drag: turn, shift-drag: pan, wheel: zoom</p>\
         <div id=\"edge-info\"></div></div></div>\n",
    );
    h.push_str("<p class=\"static-fallback\">No WebGL here: the static pictures below show the views.</p>\n");
    for state in std::iter::once(&scene.before).chain(scene.after.as_ref()) {
        let _ = writeln!(h, "<h2>Seams {} ({})</h2>", escape(&state.name), escape(&state.source));
        h.push_str(&seam_table(scene, state, &state.report));
    }
    if info.refinement.is_some() || info.control_points.is_some() {
        h.push_str("<h2>Refinement</h2><table>");
        if let Some((b, a)) = info.control_points {
            let _ = write!(
                h,
                "<tr><th class=\"l\">control points</th><td>{b} → {a} (×{:.2})</td></tr>",
                a as f64 / b.max(1) as f64
            );
        }
        if let Some(r) = &info.refinement {
            let _ = write!(
                h,
                "<tr><th class=\"l\">rounds</th><td>{}</td></tr><tr><th class=\"l\">converged</th><td>{}</td></tr>\
                 <tr><th class=\"l\">largest gap after</th><td>{} {}</td></tr><tr><th class=\"l\">largest angle after</th><td>{} deg</td></tr>",
                r.rounds,
                if r.converged { "yes" } else { "no" },
                num(r.max_gap),
                escape(&scene.unit),
                num(r.max_angle_deg)
            );
        }
        h.push_str("</table>\n");
        if let Some(r) = info.refinement.as_ref().filter(|r| !r.per_round.is_empty()) {
            h.push_str("<h3>Growth per round</h3>\n");
            h.push_str(&growth_table(r, &scene.unit));
            let plot = growth_plot(r, &scene.unit, info.refine_tolerances, GROWTH_PLOT, PlotFormat::Svg)?;
            let _ =
                writeln!(h, "<figure class=\"plot\" id=\"growth-plot\">{}</figure>", plot.html("refinement growth"));
        }
    }
    if !info.timings.is_empty() {
        h.push_str("<h2>Timings</h2><table>");
        for (name, s) in &info.timings {
            let _ = write!(h, "<tr><th class=\"l\">{}</th><td>{:.1} ms</td></tr>", escape(name), s * 1e3);
        }
        h.push_str("</table>\n");
    }
    h.push_str("<div class=\"static static-fallback\"><h2>Static views</h2>\n");
    for p in pictures {
        let _ = writeln!(
            h,
            "<figure><img alt=\"{v} view, {s}\" src=\"{}\"><figcaption>{v}, {s}</figcaption></figure>",
            png_data_url(&p.png),
            v = escape(p.view),
            s = escape(&p.state)
        );
    }
    h.push_str("</div>\n");
    let _ = write!(
        h,
        "<script type=\"application/json\" id=\"cadmorph-data\">{}</script>\n<script>{VIEWER_JS}</script>\n<script>{SORT_JS}</script>\n</body></html>\n",
        viewer_data(scene)?
    );
    Ok(h)
}
