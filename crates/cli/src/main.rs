//! The `cadmorph` command-line tool: one file per subcommand, this one only parses the
//! command line and dispatches.
//!
//! Exit codes: 0 success, 1 runtime failure (unreadable or malformed input, a morph that
//! folds space or produces NaN: nothing is written then), 2 bad command line. Errors are
//! printed as one line, each cause once (`cadmorph: reading x.igs: section D, line 7...`).

#[macro_use]
mod output;
mod blade;
mod campaign;
mod campaign_report;
mod completions;
mod convert;
mod entity_names;
mod eval;
mod faces;
mod ffd;
mod grid;
mod hull;
mod info;
mod limits;
mod mesh;
mod morph;
mod morph_json;
mod morph_warnings;
mod overrides;
mod params;
mod progress;
mod refine;
mod report;
mod sample;
mod schema;
mod seam_report;
mod seams;
mod skipped;
mod units;

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};

#[derive(Parser)]
#[command(name = "cadmorph", version, about = "CAD/NURBS kernel and IGES/STEP processor for shape parameterisation")]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// The most memory one structure of the run may take (an FFD lattice, a dense RBF
    /// system, a refined net): sizes over it are refused before anything is allocated.
    /// Examples: 8G, 512M, 2GiB. Default: half of the machine's memory.
    #[arg(long, global = true, value_parser = limits::parse_memory, value_name = "SIZE")]
    max_memory: Option<u64>,
    /// Worker threads for parallel work (1 to 1024). Default: one per CPU, or
    /// `RAYON_NUM_THREADS` when that is set.
    #[arg(long, global = true, value_parser = clap::value_parser!(u16).range(1..=1024), value_name = "N")]
    threads: Option<u16>,
}

#[derive(Subcommand)]
enum Command {
    /// Blades and propellers from design tables (BladeX-compatible).
    Blade {
        #[command(subcommand)]
        command: blade::BladeCommand,
    },
    /// Surface and volume meshes: morph, check.
    #[command(subcommand)]
    Mesh(mesh::MeshCommand),
    /// Format, units, bounding box, entity counts, faces and curves of an IGES or STEP file.
    Info(info::Args),
    /// Points and normals of every face on an n × n parameter grid.
    Sample(sample::Args),
    /// C0 gap, G1 angle and C1 derivative mismatch along every shared edge; with --tol
    /// or --angle-tol, exit 1 when an edge fails them.
    Seams(seams::Args),
    /// Morph every face with an FFD, RBF or IDW, keep the seams, write the result.
    Morph(morph::Args),
    /// Hull laws and enclosed-volume measures.
    #[command(subcommand)]
    Hull(hull::HullCommand),
    /// Insert knots: evenly spaced, or where a morph needs them to keep the seams.
    Refine(refine::Args),
    /// Write an IGES file as STEP or a STEP file as IGES (the format of the output's
    /// extension).
    Convert(convert::Args),
    /// Evaluate the B-spline faces of an OCCT reference file (`samples/*.ref.json`) on a
    /// grid and compare with OCCT's own evaluation.
    Eval(eval::Args),
    /// Design-of-experiments campaigns: plan, run (sharded, Slurm), status, collect.
    Campaign(campaign::Args),
    /// FFD boxes: fit one around a model or some of its faces, show a lattice.
    #[command(subcommand)]
    Ffd(ffd::FfdCommand),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(completions::CompletionArgs),
    /// Print the manual page, or write one per command into a folder.
    Man(completions::ManArgs),
    /// Print the JSON Schema of every `--json` output (each document's `schema` field
    /// names its definition).
    Schema(schema::Args),
    /// One self-contained HTML page of a model or a morph: 3D view, seams, pictures.
    Report(report::Args),
}

/// Make the main thread worker 0 of rayon's global pool. A parallel loop then starts on
/// the main thread itself and the other workers steal from it, instead of the main thread
/// sleeping while it wakes all the workers: on a small VM the scheduler often puts the woken
/// workers on one CPU (next to the waker) for the few milliseconds a morph of 10⁶ points
/// takes, which halves the speed of about one run in three (measured with FFD 3×3×3 on
/// 10⁶ points, 2 vCPUs: 3.6–4.6 ms in 14 of 14 runs this way, 7.0–7.3 ms in 4 of 14
/// without). `threads` (`--threads`) sets the pool's size; without it
/// `RAYON_NUM_THREADS` is still honoured. A pool that already exists is kept.
fn start_thread_pool(threads: Option<u16>) {
    let mut pool = rayon::ThreadPoolBuilder::new().use_current_thread();
    if let Some(n) = threads {
        pool = pool.num_threads(n.into());
    }
    let _ = pool.build_global();
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    start_thread_pool(cli.threads);
    if let Some(bytes) = cli.max_memory {
        cadmorph::morph::budget::set_limit(bytes);
    }
    // A write past the file-size limit (`ulimit -f`) then fails with an error, which
    // removes the temporary file, instead of killing the process with SIGXFSZ.
    let _ = signal_hook::flag::register(signal_hook::consts::SIGXFSZ, std::sync::Arc::default());
    let result = match cli.command {
        Command::Blade { command } => blade::run(command),
        Command::Mesh(cmd) => mesh::run(cmd),
        Command::Info(a) => info::run(a),
        Command::Sample(a) => sample::run(a),
        Command::Seams(a) => seams::run(a),
        Command::Morph(a) => morph::run(a),
        Command::Hull(cmd) => hull::run(cmd),
        Command::Refine(a) => refine::run(a),
        Command::Convert(a) => convert::run(a),
        Command::Eval(a) => eval::run(a),
        Command::Campaign(a) => campaign::run(a),
        Command::Schema(a) => schema::run(a),
        Command::Ffd(c) => ffd::run(c),
        Command::Completions(a) => completions::completions(a, Cli::command()),
        Command::Man(a) => completions::man(a, Cli::command()),
        Command::Report(a) => report::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // `{:#}` prints each cause once: no error in cadmorph repeats its source.
            eprintln!("cadmorph: {e:#}");
            ExitCode::FAILURE
        }
    }
}
