//! `cadmorph campaign plan|run|status|collect|slurm|sensitivity|active`: design-of-
//! experiments campaigns (the `cadmorph-campaign` crate).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use cadmorph_campaign::active::{active_subspace, Fit};
use cadmorph_campaign::{slurm, DesignSpace, Manifest, Shard};

/// Arguments of `campaign`.
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Command,
}

/// The campaign file and where its folder is.
#[derive(clap::Args)]
struct Campaign {
    /// The design space (campaign.toml).
    campaign: PathBuf,
    /// The campaign folder (default: `[campaign] output` of the file, or `<stem>.out` beside it).
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(clap::Subcommand)]
enum Command {
    /// Sample the design space and write manifest.csv and manifest.json.
    Plan(Campaign),
    /// Make every variant of a share that is not complete (resumable).
    Run {
        #[command(flatten)]
        c: Campaign,
        /// Make share K of N (0-based); inside a Slurm array the task's share is the default.
        #[arg(long)]
        shard: Option<String>,
        /// Make failed variants again.
        #[arg(long)]
        retry_failed: bool,
    },
    /// Variants pending, made, failed; the Slurm job's tasks when one was submitted.
    Status {
        #[command(flatten)]
        c: Campaign,
        /// Print the counts as JSON.
        #[arg(long)]
        json: bool,
    },
    /// One table of every variant's values and results, as CSV and Parquet.
    Collect {
        #[command(flatten)]
        c: Campaign,
        /// Where to write it: a `.parquet` path writes Parquet, any other CSV (default:
        /// both, results.csv and results.parquet in the campaign folder).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// The index page: a thumbnail per variant, the results table (sortable), failed and
    /// out-of-tolerance variants marked.
    Report {
        #[command(flatten)]
        c: Campaign,
        /// Where to write it (default: index.html in the campaign folder).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Write an sbatch job-array script (estimates from a pilot run) and optionally submit it.
    Slurm {
        #[command(flatten)]
        c: Campaign,
        /// Variants per array task.
        #[arg(long, default_value_t = 10)]
        variants_per_task: usize,
        /// CPUs per task.
        #[arg(long, default_value_t = 1)]
        cpus_per_task: usize,
        /// Partition.
        #[arg(long)]
        partition: Option<String>,
        /// At most this many tasks at once.
        #[arg(long)]
        max_running: Option<usize>,
        /// Submit it with sbatch.
        #[arg(long)]
        submit: bool,
    },
    /// The exact Jacobian of the control points with respect to the parameters.
    Sensitivity {
        #[command(flatten)]
        c: Campaign,
        /// Also compare it with central differences of the deformation.
        #[arg(long)]
        check: bool,
    },
    /// Active subspace of one output column of a results CSV (Constantine 2015).
    Active {
        #[command(flatten)]
        c: Campaign,
        /// The results table (a collect CSV with an output column added, or any CSV with
        /// one column per parameter name).
        #[arg(long)]
        results: PathBuf,
        /// The output column.
        #[arg(long)]
        output: String,
        /// Local linear fits on this many neighbours instead of one global quadratic.
        #[arg(long)]
        local_linear: Option<usize>,
    },
}

fn space(c: &Campaign) -> Result<DesignSpace> {
    let mut s = DesignSpace::read(&c.campaign)?;
    if let Some(o) = &c.out {
        s.output = o.clone();
    }
    Ok(s)
}

/// Runs `campaign`.
pub fn run(a: Args) -> Result<()> {
    match a.command {
        Command::Plan(c) => {
            let s = space(&c)?;
            let m = Manifest::plan(&s);
            m.write(&s.output)?;
            println!(
                "{} variants of {} parameters ({}) -> {}",
                m.variants.len(),
                m.parameters.len(),
                m.method,
                s.output.join("manifest.csv").display()
            );
        }
        Command::Run { c, shard, retry_failed } => {
            let s = space(&c)?;
            let shard = match shard {
                Some(t) => Shard::parse(&t)?,
                None => Shard::from_slurm(|k| std::env::var(k).ok())?.unwrap_or(Shard::ALL),
            };
            let each = |r: &cadmorph_campaign::Report, skipped: bool| {
                let state = if r.status != "ok" {
                    "FAILED"
                } else if r.in_tolerance {
                    "ok"
                } else {
                    "OUT OF TOLERANCE"
                };
                if skipped {
                    eprintln!("{} complete, skipped", r.id);
                } else {
                    eprintln!("{} {state} in {:.1} ms", r.id, r.timings.total_ms);
                }
            };
            let sum = cadmorph_campaign::run(&s, shard, retry_failed, &each)?;
            println!(
                "share {}/{}: {} variants, {} made ({} failed), {} skipped; offline {:.1} ms, wall {:.1} ms",
                shard.k, shard.n, sum.in_share, sum.made, sum.failed, sum.skipped, sum.offline_ms, sum.wall_ms
            );
            if sum.failed > 0 {
                bail!("{} variants failed (see their report.json)", sum.failed);
            }
        }
        Command::Status { c, json } => {
            let s = space(&c)?;
            let m = Manifest::plan(&s);
            let st = cadmorph_campaign::status(&s, &m);
            if json {
                println!("{}", serde_json::to_string_pretty(&st)?);
            } else {
                println!(
                    "{} planned: {} ok, {} out of tolerance, {} failed, {} pending",
                    st.planned, st.ok, st.out_of_tolerance, st.failed, st.pending
                );
            }
            if let Some(r) = slurm::scheduler_report(&s) {
                print!("{r}");
            }
        }
        Command::Report { c, output } => {
            let s = space(&c)?;
            let m = Manifest::plan(&s);
            crate::campaign_report::run(&s, &m, output)?;
        }
        Command::Collect { c, output } => {
            let s = space(&c)?;
            let m = Manifest::plan(&s);
            let table = cadmorph_campaign::table(&s, &m);
            let paths = match output {
                Some(p) => vec![p],
                None => vec![s.output.join("results.csv"), s.output.join("results.parquet")],
            };
            for path in &paths {
                let bytes = if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("parquet")) {
                    cadmorph_campaign::parquet::write(&table)
                        .map_err(|e| anyhow::anyhow!("{}: writing Parquet: {e}", path.display()))?
                } else {
                    table.to_csv().into_bytes()
                };
                cadmorph_campaign::fsutil::write_atomic(path, &bytes)?;
            }
            let st = cadmorph_campaign::status(&s, &m);
            println!(
                "{}: {} variants ({} ok, {} out of tolerance, {} failed, {} pending)",
                paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "),
                st.planned,
                st.ok,
                st.out_of_tolerance,
                st.failed,
                st.pending
            );
        }
        Command::Slurm { c, variants_per_task, cpus_per_task, partition, max_running, submit } => {
            let s = space(&c)?;
            let m = Manifest::plan(&s);
            let pilot = slurm::pilot(&s, &m)?;
            let layout = slurm::layout(m.variants.len(), variants_per_task, &pilot);
            let binary = std::env::current_exe().context("locating the cadmorph binary")?;
            let mut s_abs = s.clone();
            s_abs.path = absolute(&s.path)?;
            s_abs.output = absolute(&s.output)?;
            let text = slurm::script(
                &s_abs,
                &layout,
                &slurm::ScriptOptions { variants_per_task, binary, partition, max_running, cpus_per_task },
            );
            let path = slurm::write_script(&s_abs, &text)?;
            println!(
                "{}: {} tasks of {} variants, --time={} min, --mem={}M (pilot: offline {:.1} ms, one variant {:.1} ms, peak {} kB)",
                path.display(),
                layout.tasks,
                layout.variants_per_task,
                layout.minutes,
                layout.mem_mb,
                pilot.offline_ms,
                pilot.variant_ms,
                pilot.peak_rss_kb
            );
            if submit {
                let id = slurm::submit(&s_abs, &path)?;
                println!("submitted job {id}");
            }
        }
        Command::Sensitivity { c, check } => {
            let s = space(&c)?;
            let m = Manifest::plan(&s);
            let p = cadmorph_campaign::Prepared::new(&s, &m)?;
            let per_unit = cadmorph_campaign::sensitivity::max_displacement_per_unit(p.basis());
            println!("parameter  entry  max |dP/dmu| (model units per unit)");
            for (q, v) in s.parameters.iter().zip(&per_unit) {
                println!("{}  {}  {v:.6e}", q.name, q.entry);
            }
            if check {
                let base = cadmorph_campaign::online::Base::new(&s.deformation)?;
                let mu: Vec<f64> = s.parameters.iter().map(|q| q.values.base()).collect();
                let exact = cadmorph_campaign::sensitivity::jacobian(p.basis());
                let fd = cadmorph_campaign::sensitivity::finite_differences(&s, &base, p.basis(), &mu, 1e-4)?;
                println!("largest difference to central differences: {:.3e}", (exact - fd).abs().max());
            }
        }
        Command::Active { c, results, output, local_linear } => {
            let s = space(&c)?;
            active(&s, &results, &output, local_linear)?;
        }
    }
    Ok(())
}

fn absolute(p: &Path) -> Result<PathBuf> {
    Ok(if p.is_absolute() { p.to_owned() } else { std::env::current_dir()?.join(p) })
}

fn active(s: &DesignSpace, results: &Path, output: &str, local_linear: Option<usize>) -> Result<()> {
    let mut rd = csv::Reader::from_path(results).with_context(|| format!("reading {}", results.display()))?;
    let header = rd.headers()?.clone();
    let col = |name: &str| header.iter().position(|h| h == name);
    let cols: Vec<usize> = s
        .parameters
        .iter()
        .map(|p| col(&p.name).with_context(|| format!("{}: no column {:?}", results.display(), p.name)))
        .collect::<Result<_>>()?;
    let out = col(output).with_context(|| format!("{}: no column {output:?}", results.display()))?;
    let (mut x, mut f) = (Vec::new(), Vec::new());
    for (line, rec) in rd.records().enumerate() {
        let rec = rec?;
        let num = |i: usize| -> Result<f64> {
            rec.get(i).unwrap_or("").trim().parse::<f64>().with_context(|| {
                format!(
                    "{}: line {}, column {}: expected a number",
                    results.display(),
                    line + 2,
                    header.get(i).unwrap_or("")
                )
            })
        };
        if rec.get(out).unwrap_or("").trim().is_empty() {
            continue; // a variant without the output (pending or failed)
        }
        x.push(cols.iter().map(|&i| num(i)).collect::<Result<Vec<_>>>()?);
        f.push(num(out)?);
    }
    let names: Vec<String> = s.parameters.iter().map(|p| p.name.clone()).collect();
    let bounds: Vec<(f64, f64)> = s.parameters.iter().map(|p| p.values.bounds()).collect();
    let fit = local_linear.map_or(Fit::Quadratic, |n| Fit::LocalLinear { neighbours: n });
    let a = active_subspace(&names, &bounds, &x, &f, fit)?;
    println!("active subspace of {output} from {} samples ({fit:?}); inputs scaled to [-1, 1]", f.len());
    for (k, (e, d)) in a.eigenvalues.iter().zip(&a.directions).enumerate() {
        let w: Vec<String> = names.iter().zip(d).map(|(n, v)| format!("{n} {v:+.4}")).collect();
        println!("{k}: eigenvalue {e:.6e}  direction {}", w.join(", "));
    }
    Ok(())
}
