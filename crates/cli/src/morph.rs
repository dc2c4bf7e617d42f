//! `cadmorph morph`: morph every face, keep the seams, write the result.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use cadmorph::model::{MorphOptions, Staged};
use cadmorph::seam::SeamRefineOptions;
use cadmorph::Format;

use crate::progress::Bar;

/// The default knot-removal tolerance of `--exact`, relative to the model size: a few
/// hundred ulps, so that the exact faces stay exact to rounding (gaps ≤ 1e-12 × size).
const EXACT_TOL: f64 = 1e-13;

/// Which parameter file gives the morph.
#[derive(clap::Args)]
#[group(required = true, multiple = false)]
pub struct Source {
    /// FFD parameters (PyGeM .prm or TOML).
    #[arg(long)]
    ffd: Option<PathBuf>,
    /// RBF parameters (PyGeM .prm or TOML).
    #[arg(long)]
    rbf: Option<PathBuf>,
    /// IDW parameters (PyGeM .prm or TOML).
    #[arg(long)]
    idw: Option<PathBuf>,
}

/// Arguments of `morph`.
#[derive(clap::Args)]
pub struct Args {
    /// The input IGES or STEP file.
    input: PathBuf,
    /// The output file (written through a temporary file and a rename), in the format
    /// its extension names (.igs/.iges, .stp/.step).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    source: Source,
    /// Refine so that the seams stay within this gap (model units) after the morph.
    #[arg(long, value_parser = crate::limits::positive)]
    refine_tol: Option<f64>,
    /// With --refine-tol: the largest normal angle across a seam, degrees.
    #[arg(long, default_value_t = 0.01, requires = "refine_tol", value_parser = crate::limits::positive)]
    angle_tol: f64,
    /// With --refine-tol: stop refining (and fail) before the faces would hold more than
    /// this many control points in all. Default: 20 times the input's.
    #[arg(long, requires = "refine_tol")]
    max_control_points: Option<usize>,
    /// PyGeM-style refinement instead: this many evenly spaced knots per direction.
    #[arg(long, conflicts_with = "refine_tol")]
    uniform_knots: Option<usize>,
    /// Make knots compatible across seams and make both sides identical after the morph.
    #[arg(long)]
    repair: bool,
    /// Exact FFD: every face inside the lattice's box becomes its exact image (degree
    /// p·(l+m+n) for an (l+1)×(m+1)×(n+1) lattice; refused above 25, OCCT's limit), then
    /// knot removal within --exact-tol; faces crossing the box are morphed (and refined
    /// with --refine-tol) as without it.
    #[arg(long, conflicts_with_all = ["repair", "uniform_knots"])]
    exact: bool,
    /// With --exact: how far knot removal may move an exact face, model units.
    /// Default: 1e-13 × the model size.
    #[arg(long, requires = "exact", value_parser = crate::limits::positive)]
    exact_tol: Option<f64>,
    /// Morph the faces that convert and keep the others as they are (listed on standard
    /// error); without it, a file with faces that cannot be converted is refused.
    #[arg(long)]
    skip_unsupported: bool,
    /// Write the seam report (before and after) as JSON here.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Print the outcome as JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `morph`.
pub fn run(a: Args) -> Result<()> {
    let start = Instant::now();
    if Format::from_extension(&a.output).is_none() {
        return Err(cadmorph::Error::UnknownExtension { path: a.output.clone() }.into());
    }
    let (path, kind) = match (&a.source.ffd, &a.source.rbf, &a.source.idw) {
        (Some(p), _, _) => (p, "ffd"),
        (_, Some(p), _) => (p, "rbf"),
        (_, _, Some(p)) => (p, "idw"),
        _ => bail!("one of --ffd, --rbf, --idw is needed"),
    };
    if a.exact && kind != "ffd" {
        bail!("--exact composes an FFD's Bernstein volume with the faces; --{kind} has none (use --ffd)");
    }
    let d = crate::params::deformation(path, Some(kind))?;
    let mut m = cadmorph::open(&a.input)?;
    crate::skipped::check(&m.info().skipped, a.skip_unsupported)?;
    let before: usize = m.patches().iter().map(|p| p.surface.control_points().len()).sum();
    let refine = match a.refine_tol {
        Some(t) => {
            crate::limits::check_gap_tolerance("--refine-tol", t, m.size(), m.unit())?;
            crate::limits::check_angle_tolerance("--angle-tol", a.angle_tol)?;
            let mut r = SeamRefineOptions::new(t, a.angle_tol);
            r.max_control_points = a.max_control_points.unwrap_or(before.saturating_mul(20).max(1000));
            Some(r)
        }
        None => None,
    };
    let opts = MorphOptions { refine, uniform_knots: a.uniform_knots, repair: a.repair };
    let exact = match a.exact {
        true => {
            let ffd = crate::params::ffd(path)?;
            let tol = a.exact_tol.unwrap_or(EXACT_TOL * m.size());
            Some((cadmorph::model::ExactFfd::new(&ffd, tol)?, ffd))
        }
        false => None,
    };
    let (mut outcome, exact_report) = {
        let bar = Bar::new();
        let context = || format!("morphing {}", a.input.display());
        match &exact {
            Some((e, ffd)) => {
                let (o, r) = m.morph_exact(ffd, e, &opts, &bar).with_context(context)?;
                (o, Some(r))
            }
            None => (m.morph_with_progress(d.as_ref(), &opts, &bar).with_context(context)?, None),
        }
    };
    if let (Some(r), Some(o)) = (&outcome.refinement, &opts.refine) {
        if !r.converged {
            bail!(
                "seam refinement did not converge: after {} rounds the largest gap is {:.3e} {} (asked {:.3e}) and \
                 the largest angle {:.4} deg (asked {}), with {} control points (from {}, limit {}); nothing written",
                r.rounds,
                r.max_gap,
                m.unit(),
                o.tol,
                r.max_angle_deg,
                o.angle_tol_deg,
                r.control_points_after,
                r.control_points_before,
                o.max_control_points
            );
        }
    }
    // Everything that can fail is done before the output replaces anything: the output's
    // bytes, the read-back "after" report, the report file, all staged beside their targets.
    let format = Format::from_extension(&a.output).expect("checked above");
    let bytes = if format == m.format() { m.to_bytes() } else { cadmorph::convert(&m, format)?.to_bytes() };
    let elapsed = start.elapsed().as_secs_f64();
    // The "after" report describes the written document, read back.
    outcome.seams_after = m.verify()?.seams;
    let mut json = serde_json::to_value(&outcome)?;
    if let (Some(r), Some(obj)) = (&exact_report, json.as_object_mut()) {
        obj.insert("exact".into(), serde_json::to_value(r)?);
    }
    let report = match &a.report {
        Some(r) => Some(Staged::new(r, serde_json::to_string_pretty(&json)?.as_bytes())?),
        None => None,
    };
    Staged::new(&a.output, &bytes)?.commit()?;
    if let Some(r) = report {
        r.commit()?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&json)?);
        return Ok(());
    }
    println!(
        "{} -> {} in {:.1} ms: {} faces and {} curves rewritten, control points {} -> {}",
        a.input.display(),
        a.output.display(),
        elapsed * 1e3,
        outcome.faces_rewritten,
        outcome.curves_rewritten,
        outcome.control_points_before,
        outcome.control_points_after
    );
    if let Some(r) = &exact_report {
        println!(
            "exact FFD: {} faces exact ({} control points composed, {} after knot removal, bound {:.3e} {}), {} \
             curves exact, {} faces crossing the box morphed by their control points",
            r.exact_faces,
            r.composed_control_points,
            r.written_control_points,
            r.removal_bound,
            m.unit(),
            r.exact_curves,
            r.other_faces
        );
    }
    if let Some(r) = &outcome.refinement {
        println!(
            "seam refinement: {} rounds, {}; max gap {:.3e}, max angle {:.4} deg",
            r.rounds,
            if r.converged { "converged" } else { "NOT converged" },
            r.max_gap,
            r.max_angle_deg
        );
    }
    println!("seams before ({}):\n{}", m.unit(), outcome.seams_before.table());
    println!("seams after, read back from the written document:\n{}", outcome.seams_after.table());
    Ok(())
}
