//! `cadmorph report`: one self-contained HTML page of a model or a morph (WebGL view,
//! seam tables, static pictures), with glTF, VTU and PNG files on request; also the
//! page `morph --report-html` writes.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use cadmorph::model::{MorphOutcome, Staged};
use cadmorph::morph::{Ffd, Parameters};
use cadmorph::seam::{SeamRefinement, SeamReport};
use cadmorph::Model;
use cadmorph_report::html::{report_html, PageInfo};
use cadmorph_report::render::pictures;
use cadmorph_report::{Input, Scene};

/// Pixel size of each static picture in the page.
const PICTURE: (u32, u32) = (640, 320);

/// Arguments of `report`.
#[derive(clap::Args)]
pub struct Args {
    /// The model (IGES or STEP) as it was before the morph.
    input: PathBuf,
    /// The morphed model, shown beside the original.
    #[arg(long)]
    after: Option<PathBuf>,
    /// The FFD parameters (PyGeM .prm or TOML) of the morph: its lattice is drawn,
    /// original and moved.
    #[arg(long)]
    ffd: Option<PathBuf>,
    /// The HTML page to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Also write the shown model (after, else before) as glTF 2.0 binary here.
    #[arg(long)]
    glb: Option<PathBuf>,
    /// Also write the control nets (net_before.vtu, net_after.vtu) and the lattice
    /// (lattice.vtu) into this existing folder.
    #[arg(long)]
    vtu_dir: Option<PathBuf>,
    /// Also write the static pictures (VIEW_STATE.png) into this existing folder.
    #[arg(long)]
    png_dir: Option<PathBuf>,
    /// Gaps at this many model units are the middle (yellow) of the colour scale.
    /// Default: 1e-7 of the model size.
    #[arg(long, value_parser = crate::limits::positive)]
    gap_tol: Option<f64>,
    /// G1 angles at this many degrees are the middle of the colour scale.
    #[arg(long, default_value_t = 0.01, value_parser = crate::limits::positive)]
    angle_tol: f64,
    /// The `morph --json` output of the morph that made --after: the page shows its
    /// refinement (rounds, growth per round) and control-point counts.
    #[arg(long, requires = "after")]
    morph_json: Option<PathBuf>,
}

/// The refinement in a `morph --json` document, if it refined.
fn refinement_of(path: &Path) -> Result<Option<SeamRefinement>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let doc: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    if !doc["schema"].as_str().is_some_and(|s| s.starts_with("cadmorph.morph/")) {
        bail!("{} is not the output of `cadmorph morph --json`", path.display());
    }
    match &doc["refinement"] {
        serde_json::Value::Null => Ok(None),
        r => Ok(Some(
            serde_json::from_value(r.clone()).with_context(|| format!("{}: reading its refinement", path.display()))?,
        )),
    }
}

/// The FFD of the parameter file `path`.
pub fn read_ffd(path: &Path) -> Result<Ffd> {
    match crate::params::read(path)? {
        Parameters::Ffd(f) => Ok(f),
        _ => bail!("{} does not hold FFD parameters (--ffd)", path.display()),
    }
}

/// The seams of `m` to draw: `known` when it describes `m`'s edges (as many edges as
/// `m` has), else measured again.
fn seams_of(m: &Model, known: Option<&SeamReport>) -> SeamReport {
    match known {
        Some(r) if r.edges.len() == m.edges().len() + m.trim_edges().len() => r.clone(),
        _ => m.seams(200),
    }
}

/// Everything a report writes, staged beside its targets (nothing replaced yet).
pub struct Files {
    staged: Vec<Staged>,
}

impl Files {
    /// Replaces the targets.
    pub fn commit(self) -> Result<()> {
        for s in self.staged {
            s.commit()?;
        }
        Ok(())
    }
}

/// What to write besides the page.
#[derive(Default)]
pub struct Extras<'a> {
    /// glTF binary.
    pub glb: Option<&'a Path>,
    /// Folder of the VTU files.
    pub vtu_dir: Option<&'a Path>,
    /// Folder of the PNG files.
    pub png_dir: Option<&'a Path>,
}

fn folder(p: &Path) -> Result<&Path> {
    if !p.is_dir() {
        bail!("{} is not a folder", p.display());
    }
    Ok(p)
}

/// Builds the page (and extras) of `before` → `after` and stages the files.
pub fn stage(
    scene: Scene,
    info: &PageInfo,
    html_path: &Path,
    extras: &Extras,
    started: Instant,
) -> Result<(Files, f64)> {
    let pics = pictures(&scene, PICTURE.0, PICTURE.1)?;
    let mut info = info.clone();
    info.timings.push(("report (tessellation, seam lines, pictures)".into(), started.elapsed().as_secs_f64()));
    let html = report_html(&scene, &info, &pics)?;
    let mut staged = vec![Staged::new(html_path, html.as_bytes())?];
    if let Some(p) = extras.glb {
        staged.push(Staged::new(p, &cadmorph_report::gltf::to_glb(&scene)?)?);
    }
    if let Some(dir) = extras.vtu_dir {
        let dir = folder(dir)?;
        staged.push(Staged::new(&dir.join("net_before.vtu"), cadmorph_report::vtk::net_vtu(&scene.before).as_bytes())?);
        if let Some(a) = &scene.after {
            staged.push(Staged::new(&dir.join("net_after.vtu"), cadmorph_report::vtk::net_vtu(a).as_bytes())?);
        }
        if let Some(l) = &scene.lattice {
            staged.push(Staged::new(&dir.join("lattice.vtu"), cadmorph_report::vtk::lattice_vtu(l).as_bytes())?);
        }
    }
    if let Some(dir) = extras.png_dir {
        let dir = folder(dir)?;
        for p in &pics {
            staged.push(Staged::new(&dir.join(format!("{}_{}.png", p.view, p.state)), &p.png)?);
        }
    }
    Ok((Files { staged }, started.elapsed().as_secs_f64()))
}

/// The page `morph --report-html` writes: the input (read again) before, the morphed
/// model `after` (its seams as the morph read them back), the lattice when the morph is
/// an FFD. Returns the staged files and the seconds the report took.
pub fn for_morph(
    input: &Path,
    output: &Path,
    after: &Model,
    outcome: &MorphOutcome,
    ffd: Option<&Path>,
    gap_tol: Option<f64>,
    angle_tol: f64,
    refine_tolerances: Option<(f64, f64)>,
    morph_seconds: f64,
    html_path: &Path,
) -> Result<(Files, f64)> {
    let started = Instant::now();
    let before = cadmorph::open(input)?;
    let lattice = ffd.map(read_ffd).transpose()?;
    let gap_tol = gap_tol.unwrap_or(1e-7 * before.size());
    let b_seams = seams_of(&before, Some(&outcome.seams_before));
    let a_seams = seams_of(after, Some(&outcome.seams_after));
    let scene = Scene::new(
        Input { model: &before, seams: &b_seams, source: input.display().to_string() },
        Some(Input { model: after, seams: &a_seams, source: output.display().to_string() }),
        lattice.as_ref(),
        gap_tol,
        angle_tol,
    )?;
    let info = PageInfo {
        title: format!("cadmorph morph: {}", input.display()),
        refinement: outcome.refinement.clone(),
        control_points: Some((outcome.control_points_before, outcome.control_points_after)),
        timings: vec![("morph (read, refine, morph, write)".into(), morph_seconds)],
        refine_tolerances,
    };
    stage(scene, &info, html_path, &Extras::default(), started)
}

/// Runs `report`.
pub fn run(a: Args) -> Result<()> {
    let started = Instant::now();
    let before = cadmorph::open(&a.input)?;
    crate::skipped::warn(&before.info().skipped);
    let after = a.after.as_ref().map(|p| cadmorph::open(p)).transpose()?;
    let lattice = a.ffd.as_deref().map(read_ffd).transpose()?;
    let read = started.elapsed().as_secs_f64();
    let b_seams = before.seams(200);
    let a_seams = after.as_ref().map(|m| m.seams(200));
    let seams = started.elapsed().as_secs_f64() - read;
    let gap_tol = a.gap_tol.unwrap_or(1e-7 * before.size());
    let scene = Scene::new(
        Input { model: &before, seams: &b_seams, source: a.input.display().to_string() },
        after.as_ref().zip(a_seams.as_ref()).zip(a.after.as_ref()).map(|((m, s), p)| Input {
            model: m,
            seams: s,
            source: p.display().to_string(),
        }),
        lattice.as_ref(),
        gap_tol,
        a.angle_tol,
    )
    .with_context(|| format!("drawing {}", a.input.display()))?;
    let control_points = after.as_ref().map(|m| {
        let n = |m: &Model| m.patches().iter().map(|p| p.surface.control_points().len()).sum::<usize>();
        (n(&before), n(m))
    });
    let refinement = a.morph_json.as_deref().map(refinement_of).transpose()?.flatten();
    let info = PageInfo {
        title: format!("cadmorph report: {}", a.input.display()),
        refinement,
        control_points,
        timings: vec![("read".into(), read), ("measure seams".into(), seams)],
        refine_tolerances: None,
    };
    let extras = Extras { glb: a.glb.as_deref(), vtu_dir: a.vtu_dir.as_deref(), png_dir: a.png_dir.as_deref() };
    let (files, seconds) = stage(scene, &info, &a.output, &extras, started)?;
    files.commit()?;
    println!("{} written in {:.1} ms", a.output.display(), seconds * 1e3);
    Ok(())
}
