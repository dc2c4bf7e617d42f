//! `cadmorph campaign report`: the campaign's index page: a thumbnail of every made
//! variant, the results table of `collect` (sortable), failed and out-of-tolerance
//! variants marked.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use cadmorph::model::Staged;
use cadmorph_campaign::run::variant_dir;
use cadmorph_campaign::{DesignSpace, Manifest, Report};
use cadmorph_report::camera::VIEWS;
use cadmorph_report::campaign::{CampaignPage, Row, RowState};
use cadmorph_report::render::{camera, render, Layers};
use cadmorph_report::{Input, Scene};

/// Thumbnail size, pixels.
const THUMB: (u32, u32) = (240, 120);

/// The side view of the model in `file`, seams coloured around `gap_tol` (default 1e-7 of
/// its size), as PNG.
fn thumbnail(file: &Path, gap_tol: Option<f64>, angle_tol: f64) -> Result<Vec<u8>> {
    let m = cadmorph::open(file)?;
    let seams = m.seams(100);
    let tol = gap_tol.unwrap_or(1e-7 * m.size());
    let scene = Scene::new::<_, Box<dyn cadmorph::CadDocument>>(
        Input { model: &m, seams: &seams, source: file.display().to_string() },
        None,
        None,
        tol,
        angle_tol,
    )?;
    let cam = camera(&scene, &VIEWS[0], THUMB.0, THUMB.1).context("the model has no finite bounds")?;
    Ok(render(&scene, &scene.before, &cam, Layers::SEAMS)?.to_png()?)
}

/// Writes the index page of `space` (planned as `manifest`) to `output` (default
/// `index.html` in the campaign folder).
pub fn run(space: &DesignSpace, manifest: &Manifest, output: Option<PathBuf>) -> Result<()> {
    let csv_text = cadmorph_campaign::collect(space, manifest);
    let mut reader = csv::Reader::from_reader(csv_text.as_bytes());
    let columns: Vec<String> = reader.headers()?.iter().map(str::to_owned).collect();
    let state_col = columns.iter().position(|c| c == "state").context("collect's table has no state column")?;
    let mut rows = Vec::new();
    for (record, v) in reader.records().zip(&manifest.variants) {
        let record = record?;
        let cells: Vec<String> = record.iter().map(str::to_owned).collect();
        let state = RowState::parse(&cells[state_col]).with_context(|| format!("state {:?}", cells[state_col]))?;
        let dir = variant_dir(space, &v.id);
        let thumbnail = match (state, Report::read(&dir)) {
            (RowState::Ok | RowState::OutOfTolerance, Some(r)) => match r.outputs.first() {
                Some(o) => Some(
                    thumbnail(&dir.join(&o.file), space.settings.refine_tol, space.settings.angle_tol)
                        .with_context(|| format!("drawing variant {}", v.id))?,
                ),
                None => None,
            },
            _ => None,
        };
        rows.push(Row { id: v.id.clone(), cells, state, thumbnail });
    }
    let page = CampaignPage { title: format!("cadmorph campaign: {}", space.path.display()), columns, rows };
    let out = output.unwrap_or_else(|| space.output.join("index.html"));
    Staged::new(&out, page.to_html().as_bytes())?.commit()?;
    println!("{} written: {} variants", out.display(), page.rows.len());
    Ok(())
}
