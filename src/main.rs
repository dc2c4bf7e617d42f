//! The `cadmorph` command-line tool.
//!
//! Exit codes: 0 success, 1 runtime failure (unreadable or malformed input, a morph that
//! folds space or produces NaN: nothing is written then), 2 bad command line.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use cadmorph::model::{Model, MorphOptions, Progress};
use cadmorph::morph::{Deformation, Parameters};
use cadmorph::nurbs::Surface;
use cadmorph::refdata::read_faces;
use cadmorph::seam::SeamRefineOptions;
use clap::{Args, Parser, Subcommand};

mod cmd_mesh;

/// `println!` that ends the program quietly when standard output has been closed (output
/// piped into `head`), where the standard macro panics.
macro_rules! println {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout().lock(), $($t)*) {
            closed_stdout(e)
        }
    }};
}

/// `print!` with [`println!`]'s handling of a closed standard output.
macro_rules! print {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = write!(std::io::stdout().lock(), $($t)*) {
            closed_stdout(e)
        }
    }};
}

/// A reader that stopped reading (a closed pipe) ends the run successfully; any other
/// failure to write the output is an error.
fn closed_stdout(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0)
    }
    eprintln!("cadmorph: writing the output: {e}");
    std::process::exit(1)
}

#[derive(Parser)]
#[command(name = "cadmorph", version, about = "CAD/NURBS kernel and IGES/STEP processor for shape parameterisation")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Args)]
#[group(required = true, multiple = false)]
struct MorphSource {
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

#[derive(Subcommand)]
enum Command {
    /// Surface and volume meshes: morph, check.
    #[command(subcommand)]
    Mesh(cmd_mesh::MeshCommand),
    /// Units, entity counts and faces of an IGES or STEP file.
    Info {
        /// An IGES or STEP file.
        file: PathBuf,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Points and normals of every face on an n × n parameter grid.
    Sample {
        /// An IGES or STEP file.
        file: PathBuf,
        /// Grid points per direction.
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(2..=1000))]
        grid: u32,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// C0 gap, G1 angle and C1 mismatch along every shared edge.
    Seams {
        /// An IGES or STEP file.
        file: PathBuf,
        /// Samples per edge.
        #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(2..=100_000))]
        samples: u32,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Morph every face with an FFD, RBF or IDW, keep the seams, write the result.
    Morph {
        /// The input IGES or STEP file.
        input: PathBuf,
        /// The output file (written through a temporary file and a rename).
        #[arg(short, long)]
        output: PathBuf,
        #[command(flatten)]
        source: MorphSource,
        /// Refine so that the seams stay within this gap (model units) after the morph.
        #[arg(long)]
        refine_tol: Option<f64>,
        /// With --refine-tol: the largest normal angle across a seam, degrees.
        #[arg(long, default_value_t = 0.01, requires = "refine_tol")]
        angle_tol: f64,
        /// PyGeM-style refinement instead: this many evenly spaced knots per direction.
        #[arg(long, conflicts_with = "refine_tol")]
        uniform_knots: Option<usize>,
        /// Make knots compatible across seams and make both sides identical after the morph.
        #[arg(long)]
        repair: bool,
        /// Write the seam report (before and after) as JSON here.
        #[arg(long)]
        report: Option<PathBuf>,
        /// Print the outcome as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Insert knots: evenly spaced, or where a morph needs them to keep the seams.
    Refine {
        /// The input IGES or STEP file.
        input: PathBuf,
        /// The output file.
        #[arg(short, long)]
        output: PathBuf,
        /// This many evenly spaced knots per direction on every face.
        #[arg(long, conflicts_with_all = ["for_params", "tol"])]
        knots: Option<usize>,
        /// Refine for this morph (FFD/RBF/IDW parameter file) ...
        #[arg(long = "for", requires = "tol")]
        for_params: Option<PathBuf>,
        /// ... so that the seams stay within this gap after it.
        #[arg(long)]
        tol: Option<f64>,
    },
    /// Evaluate the B-spline faces of an OCCT reference file (`samples/*.ref.json`) on a
    /// grid and compare with OCCT's own evaluation.
    Eval {
        /// A `*.ref.json` file.
        file: PathBuf,
        /// Grid points per direction.
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(2..=1000))]
        grid: u32,
        /// Only this face (0-based).
        #[arg(long)]
        face: Option<usize>,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

fn open(path: &Path) -> Result<Model> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    Model::from_bytes(&bytes).with_context(|| format!("reading {}", path.display()))
}

fn deformation(path: &Path, expect: &str) -> Result<Box<dyn Deformation + Send>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let is_toml = path.extension().is_some_and(|e| e == "toml");
    let params = if is_toml { Parameters::from_toml(&text) } else { Parameters::from_prm(&text) }
        .with_context(|| format!("reading {}", path.display()))?;
    let kind = match params {
        Parameters::Ffd(_) => "ffd",
        Parameters::Rbf(_) => "rbf",
        Parameters::Idw(_) => "idw",
    };
    if kind != expect {
        bail!("{} holds {kind} parameters, but --{expect} was given", path.display());
    }
    params.build().with_context(|| format!("building the morph of {}", path.display()))
}

fn info(file: &Path, json: bool) -> Result<()> {
    let m = open(file)?;
    let i = m.info();
    if json {
        println!("{}", serde_json::to_string_pretty(&i)?);
        return Ok(());
    }
    println!("{}: {:?}, unit {}", file.display(), i.format, i.unit);
    let counts: Vec<String> = i.entity_counts.iter().map(|(k, v)| format!("{k}: {v}")).collect();
    println!("entities: {}", counts.join(", "));
    if i.unknown_entities > 0 {
        println!("kept verbatim without a typed view: {}", i.unknown_entities);
    }
    println!(
        "{:<28} {:<22} {:>7} {:>9} {:>9} {:>8} {:>8}",
        "face", "surface", "degree", "poles", "rational", "trimmed", "analytic"
    );
    for p in &i.patches {
        println!(
            "{:<28} {:<22} {:>7} {:>9} {:>9} {:>8} {:>8}",
            p.source,
            p.kind,
            format!("{}x{}", p.u_degree, p.v_degree),
            format!("{}x{}", p.n_u, p.n_v),
            p.rational,
            p.trimmed,
            p.analytic
        );
    }
    for (face, why) in &i.skipped {
        println!("not converted: {face}: {why}");
    }
    Ok(())
}

/// One grid point of `sample`/`eval`: `(u, v, point, normal)`.
type Row = (f64, f64, [f64; 3], Option<[f64; 3]>);

/// Points and (face-oriented) normals of `s` on an `n × n` grid over its domain.
fn grid_rows(s: &cadmorph::nurbs::NurbsSurface, n: usize, reversed: bool) -> Vec<Row> {
    let (ud, vd) = s.domain();
    let mut rows = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let u = ud.start() + (ud.end() - ud.start()) * i as f64 / (n - 1) as f64;
            let v = vd.start() + (vd.end() - vd.start()) * j as f64 / (n - 1) as f64;
            let q = s.eval(u, v);
            let nrm = s.normal(u, v).map(|n| if reversed { -n.into_inner() } else { n.into_inner() });
            rows.push((u, v, [q.x, q.y, q.z], nrm.map(|n| [n.x, n.y, n.z])));
        }
    }
    rows
}

fn rows_json(rows: &[Row]) -> Vec<serde_json::Value> {
    rows.iter().map(|(u, v, q, n)| serde_json::json!({"u": u, "v": v, "p": q, "n": n})).collect()
}

fn print_rows(rows: &[Row]) {
    println!("{:>10} {:>10} {:>14} {:>14} {:>14} {:>9} {:>9} {:>9}", "u", "v", "x", "y", "z", "nx", "ny", "nz");
    for (u, v, q, n) in rows {
        let n =
            n.map_or("    (degenerate point)".to_string(), |n| format!("{:>9.5} {:>9.5} {:>9.5}", n[0], n[1], n[2]));
        println!("{u:>10.5} {v:>10.5} {:>14.6} {:>14.6} {:>14.6} {n}", q[0], q[1], q[2]);
    }
}

fn sample(file: &Path, grid: usize, json: bool) -> Result<()> {
    let m = open(file)?;
    let mut out = Vec::new();
    for p in m.patches() {
        let rows = grid_rows(&p.surface, grid, p.reversed);
        if json {
            out.push(serde_json::json!({
                "face": p.source.to_string(),
                "grid": rows_json(&rows),
            }));
        } else {
            println!("face {} ({}):", p.source, p.kind);
            print_rows(&rows);
        }
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&out)?);
    }
    Ok(())
}

/// A progress bar on standard error for the stages of long work. indicatif draws
/// nothing when standard error is not a terminal, so pipes, logs and `--json` output
/// stay clean.
struct Bar(indicatif::ProgressBar);

impl Bar {
    fn new() -> Self {
        let bar = indicatif::ProgressBar::with_draw_target(None, indicatif::ProgressDrawTarget::stderr());
        if let Ok(style) =
            indicatif::ProgressStyle::with_template("{spinner} {msg:<22} {wide_bar} {pos}/{len} {elapsed}")
        {
            bar.set_style(style);
        }
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        Self(bar)
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}

impl Progress for Bar {
    fn start(&self, stage: &str, total: u64) {
        self.0.set_message(stage.to_owned());
        self.0.set_length(total);
        self.0.set_position(0);
    }
    fn step(&self, n: u64) {
        self.0.inc(n);
    }
}

fn seams(file: &Path, samples: usize, json: bool) -> Result<()> {
    let m = open(file)?;
    let r = {
        let bar = Bar::new();
        m.seams_with_progress(samples, &bar)
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        println!("{} ({}):", file.display(), m.unit());
        print!("{}", r.table());
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn morph(
    input: &Path,
    output: &Path,
    d: &dyn Deformation,
    opts: MorphOptions,
    report: Option<&Path>,
    json: bool,
) -> Result<()> {
    let start = Instant::now();
    let mut m = open(input)?;
    let outcome = {
        let bar = Bar::new();
        let outcome = m.morph_with_progress(d, &opts, &bar);
        outcome.with_context(|| format!("morphing {}", input.display()))?
    };
    m.save(output).with_context(|| format!("writing {}", output.display()))?;
    let elapsed = start.elapsed().as_secs_f64();
    if let Some(r) = report {
        let text = serde_json::to_string_pretty(&outcome)?;
        std::fs::write(r, text).with_context(|| format!("writing {}", r.display()))?;
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&outcome)?);
        return Ok(());
    }
    println!(
        "{} -> {} in {:.1} ms: {} faces and {} curves rewritten, control points {} -> {}",
        input.display(),
        output.display(),
        elapsed * 1e3,
        outcome.faces_rewritten,
        outcome.curves_rewritten,
        outcome.control_points_before,
        outcome.control_points_after
    );
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
    println!("seams after, read back from the written file:\n{}", outcome.seams_after.table());
    Ok(())
}

fn eval(file: &PathBuf, grid: usize, only: Option<usize>, json: bool) -> Result<()> {
    let text = std::fs::read_to_string(file).with_context(|| format!("reading {}", file.display()))?;
    let faces = read_faces(&text).with_context(|| format!("reading {}", file.display()))?;
    let mut out = Vec::new();
    for f in faces.iter().filter(|f| only.is_none_or(|i| i == f.index)) {
        let Some(s) = &f.surface else {
            if !json {
                println!("face {}: {} (analytic: see `cadmorph sample` on the data file)\n", f.index, f.class);
            }
            continue;
        };
        let scale = s.control_extent().max(f64::MIN_POSITIVE);
        let (mut dp, mut dn) = (0.0f64, 0.0f64);
        for smp in &f.samples {
            dp = dp.max((s.eval(smp.u, smp.v) - smp.point).norm() / scale);
            if let (Some(a), Some(b)) = (s.normal(smp.u, smp.v), smp.normal) {
                dn = dn.max((a.into_inner() - b).norm());
            }
        }
        let rows = grid_rows(s, grid, false);
        if json {
            out.push(serde_json::json!({
                "face": f.index,
                "degrees": [s.u_degree(), s.v_degree()],
                "poles": [s.n_u(), s.n_v()],
                "rational": s.is_rational(),
                "occt_samples": f.samples.len(),
                "max_point_difference_relative": dp,
                "max_normal_difference": dn,
                "grid": rows_json(&rows),
            }));
        } else {
            println!(
                "face {}: degree {}x{}, {}x{} poles{}; against OCCT at {} samples: max |Δp| = {:.1e} (relative), max |Δn| = {:.1e}",
                f.index,
                s.u_degree(),
                s.v_degree(),
                s.n_u(),
                s.n_v(),
                if s.is_rational() { ", rational" } else { "" },
                f.samples.len(),
                dp,
                dn
            );
            print_rows(&rows);
            println!();
        }
    }
    if json {
        println!("{}", serde_json::to_string_pretty(&out)?);
    }
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Info { file, json } => info(&file, json),
        Command::Sample { file, grid, json } => sample(&file, grid as usize, json),
        Command::Seams { file, samples, json } => seams(&file, samples as usize, json),
        Command::Morph { input, output, source, refine_tol, angle_tol, uniform_knots, repair, report, json } => {
            let (path, kind) = match (&source.ffd, &source.rbf, &source.idw) {
                (Some(p), _, _) => (p, "ffd"),
                (_, Some(p), _) => (p, "rbf"),
                (_, _, Some(p)) => (p, "idw"),
                _ => bail!("one of --ffd, --rbf, --idw is needed"),
            };
            let d = deformation(path, kind)?;
            let opts = MorphOptions {
                refine: refine_tol.map(|t| SeamRefineOptions::new(t, angle_tol)),
                uniform_knots,
                repair,
            };
            morph(&input, &output, d.as_ref(), opts, report.as_deref(), json)
        }
        Command::Refine { input, output, knots, for_params, tol } => {
            let mut m = open(&input)?;
            let outcome = match (knots, for_params, tol) {
                (Some(n), _, _) => m.refine(&MorphOptions { uniform_knots: Some(n), ..Default::default() }, None)?,
                (None, Some(p), Some(t)) => {
                    let d = deformation(&p, detect_kind(&p)?)?;
                    let opts = MorphOptions { refine: Some(SeamRefineOptions::new(t, 0.01)), ..Default::default() };
                    m.refine(&opts, Some(d.as_ref()))?
                }
                _ => bail!("give --knots N, or --for PARAMS with --tol T"),
            };
            m.save(&output).with_context(|| format!("writing {}", output.display()))?;
            println!("{} -> {}: control points {} -> {}", input.display(), output.display(), outcome.0, outcome.1);
            Ok(())
        }
        Command::Eval { file, grid, face, json } => eval(&file, grid as usize, face, json),
        Command::Mesh(cmd) => cmd_mesh::run(cmd),
    }
}

fn detect_kind(path: &Path) -> Result<&'static str> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let is_toml = path.extension().is_some_and(|e| e == "toml");
    let params = if is_toml { Parameters::from_toml(&text) } else { Parameters::from_prm(&text) }
        .with_context(|| format!("reading {}", path.display()))?;
    Ok(match params {
        Parameters::Ffd(_) => "ffd",
        Parameters::Rbf(_) => "rbf",
        Parameters::Idw(_) => "idw",
    })
}

/// Make the main thread worker 0 of rayon's global pool. A parallel loop then starts on
/// the main thread itself and the other workers steal from it, instead of the main thread
/// sleeping while it wakes all the workers: on a small VM the scheduler often puts the woken
/// workers on one CPU (next to the waker) for the few milliseconds a morph of 10⁶ points
/// takes, which halves the speed of about one run in three (measured with FFD 3×3×3 on
/// 10⁶ points, 2 vCPUs: 3.6–4.6 ms in 14 of 14 runs this way, 7.0–7.3 ms in 4 of 14
/// without). `RAYON_NUM_THREADS` is still honoured. A pool that already exists is kept.
fn start_thread_pool() {
    let _ = rayon::ThreadPoolBuilder::new().use_current_thread().build_global();
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    start_thread_pool();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cadmorph: {e:#}");
            ExitCode::FAILURE
        }
    }
}
