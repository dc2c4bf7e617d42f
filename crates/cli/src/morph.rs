//! `cadmorph morph`: morph every face, keep the seams, write the result.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use cadmorph::model::{MorphOptions, Staged};
use cadmorph::seam::{SeamCheck, SeamRefineOptions};
use cadmorph::Format;

use crate::progress::Bar;

/// The default knot-removal tolerance of `--exact`, relative to the model size: a few
/// hundred ulps, so that the exact faces stay exact to rounding (gaps ≤ 1e-12 × size).
const EXACT_TOL: f64 = 1e-13;

/// A refused degree reduction of the exact FFD names the bound it would need; say which
/// flag allows it.
fn exact_hint(e: cadmorph::model::Error) -> anyhow::Error {
    let needs_tol =
        matches!(&e, cadmorph::model::Error::Exact { source: cadmorph::nurbs::Error::ComposedReduction { .. }, .. });
    let e = anyhow::Error::new(e);
    if needs_tol {
        e.context("exact FFD refused (an --exact-tol at or above the bound below allows the reduction to degree 25)")
    } else {
        e
    }
}

/// Which parameter file gives the morph: the positional PARAMS, whose kind (FFD, RBF or
/// IDW) is read from the file, or one of the flags, which also assert the kind.
#[derive(clap::Args)]
#[group(required = true, multiple = false)]
pub struct Source {
    /// The parameter file (PyGeM .prm, or .toml; see docs/parameters.md): FFD, RBF or
    /// IDW, as the file says.
    params: Option<PathBuf>,
    /// FFD parameters: as PARAMS, and fail unless the file holds an FFD.
    #[arg(long, value_name = "PARAMS")]
    ffd: Option<PathBuf>,
    /// RBF parameters: as PARAMS, and fail unless the file holds an RBF.
    #[arg(long, value_name = "PARAMS")]
    rbf: Option<PathBuf>,
    /// IDW parameters: as PARAMS, and fail unless the file holds an IDW.
    #[arg(long, value_name = "PARAMS")]
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
    /// Override an entry of the parameter file: `mu_y[1,1,1]=0.05` (FFD node i,j,k),
    /// `radius=0.3`, `box_origin[0]=90`, `deformed_control_points[2,1]=0.4`; names as in
    /// the TOML form (docs/parameters.md). Repeat for several.
    #[arg(long = "set", value_parser = crate::overrides::parse, value_name = "NAME=VALUE")]
    set: Vec<crate::overrides::Set>,
    /// Refine so that the seams stay within this gap (model units) after the morph.
    #[arg(long, value_parser = crate::limits::positive)]
    refine_tol: Option<f64>,
    /// The largest normal angle across a smooth seam, degrees, beyond the angle it had in
    /// the input: what --refine-tol refines for and what --tol checks.
    #[arg(long, default_value_t = 0.01, value_parser = crate::limits::positive)]
    angle_tol: f64,
    /// Check the written file's seams against the input's: exit 1, writing nothing, when
    /// an edge's gap grows by more than this (model units) over the gap it had before the
    /// morph, or a smooth edge's normal angle by more than --angle-tol. Defects the input
    /// already had are reported as such. Default with --refine-tol: the refinement's
    /// tolerance.
    #[arg(long, value_parser = crate::limits::positive)]
    tol: Option<f64>,
    /// With --refine-tol: stop refining (and fail) before the faces would hold more than
    /// this many control points in all. Default: 20 times the input's, at least 50 000.
    #[arg(long, requires = "refine_tol")]
    max_control_points: Option<usize>,
    /// PyGeM-style refinement instead: this many evenly spaced knots per direction.
    #[arg(long, conflicts_with = "refine_tol")]
    uniform_knots: Option<usize>,
    /// Make knots compatible across seams and make both sides identical after the morph.
    #[arg(long)]
    repair: bool,
    /// Exact FFD: every face inside the lattice's box becomes its exact image (degree
    /// p·(l+m+n) for an (l+1)×(m+1)×(n+1) lattice, l, m, n lowered where the moves make
    /// a lower-degree map; above 25, OCCT's limit, reduced to 25 within --exact-tol or
    /// refused), then knot removal within the rest of --exact-tol; faces crossing the box
    /// are morphed (and refined with --refine-tol) as without it.
    #[arg(long, conflicts_with_all = ["repair", "uniform_knots"])]
    exact: bool,
    /// With --exact: how far degree reduction (above degree 25) and knot removal
    /// together may move an exact face from the exact image, model units.
    /// Default: 1e-13 × the model size (rounding: no reduction).
    #[arg(long, requires = "exact", value_parser = crate::limits::positive)]
    exact_tol: Option<f64>,
    /// Morph the faces that convert and keep the others as they are (listed on standard
    /// error); without it, a file with faces that cannot be converted is refused.
    #[arg(long)]
    skip_unsupported: bool,
    /// With --ffd: correct the displacements of the nodes the file moves to the nearest
    /// ones that keep the enclosed volume of the closed model (exact; fails before
    /// writing when they cannot).
    #[arg(long, requires = "ffd", conflicts_with_all = ["refine_tol", "uniform_knots", "repair"])]
    keep_volume: bool,
    /// With --ffd: likewise keep the centroid of the enclosed volume.
    #[arg(long, requires = "ffd", conflicts_with_all = ["refine_tol", "uniform_knots", "repair"])]
    keep_barycentre: bool,
    /// Write the seam report (before and after) as JSON here.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Also write the HTML report of the morph here (the page of `cadmorph report`).
    #[arg(long)]
    report_html: Option<PathBuf>,
    /// Print the outcome as JSON (schema `cadmorph.morph/1`, see `cadmorph schema`).
    #[arg(long)]
    json: bool,
}

/// Runs `morph`.
pub fn run(a: Args) -> Result<()> {
    let start = Instant::now();
    if Format::from_extension(&a.output).is_none() {
        return Err(cadmorph::Error::UnknownExtension { path: a.output.clone() }.into());
    }
    let s = &a.source;
    let (path, kind) = match (&s.params, &s.ffd, &s.rbf, &s.idw) {
        (Some(p), ..) => (p, None),
        (_, Some(p), _, _) => (p, Some("ffd")),
        (_, _, Some(p), _) => (p, Some("rbf")),
        (_, _, _, Some(p)) => (p, Some("idw")),
        _ => bail!("give the parameter file (PARAMS, or one of --ffd, --rbf, --idw)"),
    };
    if let Some(k) = kind.filter(|k| a.exact && *k != "ffd") {
        bail!("--exact composes an FFD's Bernstein volume with the faces; --{k} has none (use --ffd)");
    }
    let params = crate::overrides::apply(crate::params::read_as(path, kind)?, &a.set)?;
    let d = params.build().with_context(|| format!("building the morph of {}", path.display()))?;
    let mut m = cadmorph::open(&a.input)?;
    crate::skipped::check(&m.info().skipped, a.skip_unsupported)?;
    for w in crate::morph_warnings::warnings(&params, m.patches()) {
        eprintln!("cadmorph: warning: {w}");
    }
    let d = if a.keep_volume || a.keep_barycentre {
        crate::hull::keep_hook(&m, path, a.keep_volume, a.keep_barycentre)?
    } else {
        d
    };
    let before: usize = m.patches().iter().map(|p| p.surface.control_points().len()).sum();
    let refine = match a.refine_tol {
        Some(t) => {
            crate::limits::check_gap_tolerance("--refine-tol", t, m.size(), m.unit())?;
            crate::limits::check_angle_tolerance("--angle-tol", a.angle_tol)?;
            let mut r = SeamRefineOptions::new(t, a.angle_tol);
            r.max_control_points = a.max_control_points.unwrap_or(SeamRefineOptions::default_budget(before));
            Some(r)
        }
        None => None,
    };
    let opts = MorphOptions { refine, uniform_knots: a.uniform_knots, repair: a.repair };
    let exact = match a.exact {
        true => {
            let ffd = crate::params::ffd(path, &params)?;
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
                let (o, r) = m.morph_exact(ffd, e, &opts, &bar).map_err(exact_hint).with_context(context)?;
                (o, Some(r))
            }
            None => (m.morph_with_progress(d.as_ref(), &opts, &bar).with_context(context)?, None),
        }
    };
    if let (Some(r), Some(o)) = (&outcome.refinement, &opts.refine) {
        if !r.converged {
            bail!(
                "seam refinement did not converge: after {} rounds the largest gap grows by {:.3e} {} over the \
                 input's (asked {:.3e}) and the largest angle by {:.4} deg (asked {}), with {} control points \
                 (from {}, limit {}); nothing written",
                r.rounds,
                r.max_gap_growth,
                m.unit(),
                o.tol,
                r.max_angle_growth_deg,
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
    // The "after" report is the written file's, found and measured as `seams` would.
    // A converted output names its faces by its own entities.
    let written = if format != m.format() { Some(cadmorph::from_bytes(&bytes)?) } else { None };
    if let Some(w) = &written {
        outcome.seams_after = w.seams(200);
    }
    if let Some(tol) = a.tol.or(a.refine_tol) {
        let check = SeamCheck::new(&outcome.seams_before, &outcome.seams_after, tol, a.angle_tol);
        let failed = check.failed;
        let summary = check.summary(&outcome.seams_after);
        outcome.check = Some(check);
        if failed > 0 {
            bail!(
                "{summary}{failed} of {} edges of the morphed model fail the seam check (gap + {tol:e} {}, angle + {} deg over \
                 the input's); nothing written",
                outcome.seams_after.edges.len(),
                m.unit(),
                a.angle_tol
            );
        }
    }
    let mut json = serde_json::to_value(&outcome)?;
    if let (Some(r), Some(obj)) = (&exact_report, json.as_object_mut()) {
        obj.insert("exact".into(), serde_json::to_value(r)?);
    }
    let report = match &a.report {
        Some(r) => Some(Staged::new(r, serde_json::to_string_pretty(&json)?.as_bytes())?),
        None => None,
    };
    let html = match &a.report_html {
        Some(p) => Some(crate::report::for_morph(
            &a.input,
            &a.output,
            &m,
            &outcome,
            matches!(params, cadmorph::morph::Parameters::Ffd(_)).then_some(path.as_path()),
            a.refine_tol,
            a.angle_tol,
            opts.refine.map(|r| (r.tol, r.angle_tol_deg)),
            elapsed,
            p,
        )?),
        None => None,
    };
    Staged::new(&a.output, &bytes)?.commit()?;
    if let Some(r) = report {
        r.commit()?;
    }
    if outcome.faces_rewritten == 0 && outcome.curves_rewritten == 0 {
        eprintln!(
            "cadmorph: warning: the morph moved no control point: 0 faces rewritten, the output equals the input"
        );
    }
    if let (Some((files, seconds)), Some(p)) = (html, &a.report_html) {
        files.commit()?;
        eprintln!("report {} written in {:.1} ms", p.display(), seconds * 1e3);
    }
    if a.json {
        return crate::morph_json::print(
            &a.input,
            &a.output,
            path,
            &params,
            &m,
            &outcome,
            written.as_ref(),
            json.get("exact").cloned(),
            elapsed,
        );
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
    if outcome.parts_copied > 0 {
        println!(
            "{} placed part{} copied first, so that placements of one part move their own ways",
            outcome.parts_copied,
            if outcome.parts_copied == 1 { "" } else { "s" }
        );
    }
    if let Some(r) = &exact_report {
        if r.map_degrees != r.lattice_degrees {
            let [l0, m0, n0] = r.lattice_degrees;
            let [l1, m1, n1] = r.map_degrees;
            println!(
                "exact FFD: the lattice's degrees {l0} x {m0} x {n0} lowered to the map's own {l1} x {m1} x {n1} (bound \
                 {:.3e} {})",
                r.lowering_bound,
                m.unit()
            );
        }
        if r.reduction_bound > 0.0 {
            println!(
                "exact FFD: images above degree 25 reduced to 25 within {:.3e} {} (of the bound below)",
                r.reduction_bound,
                m.unit()
            );
        }
        println!(
            "exact FFD: {} faces exact ({} control points composed, {} after knot removal, bound {:.3e} {}), {} \
             curves exact, {} faces crossing the box morphed by their control points",
            r.exact_faces,
            r.composed_control_points,
            r.written_control_points,
            r.removal_bound + r.reduction_bound,
            m.unit(),
            r.exact_curves,
            r.other_faces
        );
    }
    if let Some(r) = &outcome.refinement {
        println!(
            "seam refinement: {} rounds, {}; max gap {:.3e} (growth over the input {:.3e}), max angle {:.4} deg \
             (growth {:.4} deg); {} edges with a pre-existing defect carried, not refined",
            r.rounds,
            if r.converged { "converged" } else { "NOT converged" },
            r.max_gap,
            r.max_gap_growth,
            r.max_angle_deg,
            r.max_angle_growth_deg,
            r.input_defects
        );
    }
    let info = m.info();
    let unit = crate::units::words(info.metres_per_unit, &info.unit);
    let none = crate::seam_report::Check::default();
    println!("seams before (lengths and gaps in {unit}, angles in degrees):");
    print!("{}", crate::seam_report::table(&outcome.seams_before, m.patches(), &unit, &none));
    println!("seams after, read back from the written document:");
    print!("{}", crate::seam_report::table(&outcome.seams_after, m.patches(), &unit, &none));
    print!("{}", crate::seam_report::legend(&unit, &none));
    if let Some(c) = &outcome.check {
        print!("{}", c.summary(&outcome.seams_after));
        println!(
            "seam check against the input: {} edges, {} failed, {} with a pre-existing defect (gap + {:e}, angle + {} deg)",
            c.edges.len(),
            c.failed,
            c.input_defects,
            c.tol,
            c.angle_tol_deg
        );
    }
    Ok(())
}
