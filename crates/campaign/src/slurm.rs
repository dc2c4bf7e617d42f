//! `campaign slurm`: an `sbatch` job-array script for the campaign, with time and memory
//! estimates from a pilot run, optionally submitted; and what `squeue`/`sacct` say of it
//! (issue 16, Deliver 4). Slurm itself schedules: every array task runs
//! `cadmorph campaign run`, which takes its share from `SLURM_ARRAY_TASK_ID` and
//! `SLURM_ARRAY_TASK_COUNT` ([`Shard::from_slurm`](crate::Shard::from_slurm)).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::error::{io, Error, Result};
use crate::fsutil::write_atomic;
use crate::manifest::Manifest;
use crate::run::Prepared;
use crate::space::DesignSpace;

/// What a pilot run measured: the offline phase and one variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Pilot {
    /// Offline phase (refined base, basis), milliseconds.
    pub offline_ms: f64,
    /// One variant, milliseconds.
    pub variant_ms: f64,
    /// Peak resident memory of the process, kilobytes (Linux `VmHWM`; 0 elsewhere).
    pub peak_rss_kb: u64,
}

/// Peak resident set size of this process (`/proc/self/status` `VmHWM`, proc(5)), kB.
fn peak_rss_kb() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1).and_then(|v| v.parse().ok()))
        })
        .unwrap_or(0)
}

/// Runs the offline phase and the plan's first variant into `slurm/pilot/` of the
/// campaign folder, timing both (the refined base it makes is the campaign's cache, so
/// the array tasks load it instead of refining again).
///
/// # Errors
///
/// Those of [`Prepared::new`] and [`Prepared::make`].
pub fn pilot(space: &DesignSpace, manifest: &Manifest) -> Result<Pilot> {
    manifest.write(&space.output)?;
    let prepared = Prepared::new(space, manifest)?;
    let first = manifest.variants.first().ok_or_else(|| Error::Fit("the plan has no variant".into()))?;
    let t = Instant::now();
    prepared.make(first, &space.output.join("slurm").join("pilot"))?;
    Ok(Pilot {
        offline_ms: prepared.offline_ms,
        variant_ms: t.elapsed().as_secs_f64() * 1e3,
        peak_rss_kb: peak_rss_kb(),
    })
}

/// Settings of the job-array script.
#[derive(Debug, Clone, PartialEq)]
pub struct ScriptOptions {
    /// Variants each array task makes.
    pub variants_per_task: usize,
    /// The `cadmorph` binary the tasks run (absolute).
    pub binary: PathBuf,
    /// `--partition`, if any.
    pub partition: Option<String>,
    /// At most this many tasks at once (`--array=0-N%M`), if any.
    pub max_running: Option<usize>,
    /// CPUs per task (rayon threads inside a task).
    pub cpus_per_task: usize,
}

/// The array layout: tasks and their estimated time (minutes) and memory (MB).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Layout {
    /// Array tasks.
    pub tasks: usize,
    /// Variants per task (the last may have fewer).
    pub variants_per_task: usize,
    /// `--time`, minutes: three times the pilot's offline time plus its variant time
    /// per variant, plus one minute, rounded up.
    pub minutes: u64,
    /// `--mem`, MB: 1.5 times the pilot's peak plus 64 MB, rounded up.
    pub mem_mb: u64,
}

/// The layout of `variants` variants at `per_task` each, estimated from `pilot`.
pub fn layout(variants: usize, per_task: usize, pilot: &Pilot) -> Layout {
    let per_task = per_task.max(1);
    let tasks = variants.div_ceil(per_task).max(1);
    let ms = 3.0 * (pilot.offline_ms + per_task as f64 * pilot.variant_ms) + 60_000.0;
    let minutes = (ms / 60_000.0).ceil() as u64;
    let mem_mb = ((pilot.peak_rss_kb as f64 * 1.5) / 1024.0 + 64.0).ceil() as u64;
    Layout { tasks, variants_per_task: per_task, minutes, mem_mb }
}

/// Single-quoted for `sh`.
fn quote(p: &Path) -> String {
    format!("'{}'", p.display().to_string().replace('\'', "'\\''"))
}

/// The `sbatch` script: a job array of `layout.tasks` tasks, each running
/// `cadmorph campaign run CAMPAIGN --out FOLDER` (its share from the array variables), logs in
/// `slurm/` of the campaign folder.
pub fn script(space: &DesignSpace, layout: &Layout, opts: &ScriptOptions) -> String {
    let mut s = String::from("#!/bin/bash\n");
    let _ = writeln!(s, "# cadmorph campaign job array for {}", space.path.display());
    let _ = writeln!(
        s,
        "# {} tasks of {} variants; --time and --mem from a pilot run (cadmorph campaign slurm)",
        layout.tasks, layout.variants_per_task
    );
    let name = space.path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "campaign".into());
    let _ = writeln!(s, "#SBATCH --job-name=cadmorph-{name}");
    let throttle = opts.max_running.map(|m| format!("%{m}")).unwrap_or_default();
    let _ = writeln!(s, "#SBATCH --array=0-{}{throttle}", layout.tasks - 1);
    let _ = writeln!(s, "#SBATCH --ntasks=1");
    let _ = writeln!(s, "#SBATCH --cpus-per-task={}", opts.cpus_per_task);
    let _ = writeln!(s, "#SBATCH --time={}", layout.minutes);
    let _ = writeln!(s, "#SBATCH --mem={}M", layout.mem_mb);
    if let Some(p) = &opts.partition {
        let _ = writeln!(s, "#SBATCH --partition={p}");
    }
    let logs = space.output.join("slurm");
    let _ = writeln!(s, "#SBATCH --output={}", logs.join("task_%A_%a.out").display());
    s.push_str("set -euo pipefail\n");
    s.push_str("export RAYON_NUM_THREADS=\"${SLURM_CPUS_PER_TASK:-1}\"\n");
    let _ =
        writeln!(s, "exec {} campaign run {} --out {}", quote(&opts.binary), quote(&space.path), quote(&space.output));
    s
}

/// Writes the script to `slurm/array.sbatch` in the campaign folder; returns its path.
///
/// # Errors
///
/// [`Error::Io`].
pub fn write_script(space: &DesignSpace, text: &str) -> Result<PathBuf> {
    let dir = space.output.join("slurm");
    std::fs::create_dir_all(&dir).map_err(io(&dir))?;
    let path = dir.join("array.sbatch");
    write_atomic(&path, text.as_bytes())?;
    Ok(path)
}

/// Submits `script` with `sbatch --parsable` and records the job id in `slurm/job_id`.
///
/// # Errors
///
/// [`Error::External`] when `sbatch` cannot be run or refuses the script.
pub fn submit(space: &DesignSpace, script: &Path) -> Result<String> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .arg(script)
        .output()
        .map_err(|e| Error::External { program: "sbatch".into(), message: e.to_string() })?;
    if !out.status.success() {
        return Err(Error::External {
            program: "sbatch".into(),
            message: String::from_utf8_lossy(&out.stderr).trim().to_string(),
        });
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(Error::External { program: "sbatch".into(), message: format!("unexpected output {text:?}") });
    }
    write_atomic(&space.output.join("slurm").join("job_id"), format!("{id}\n").as_bytes())?;
    Ok(id)
}

/// The job id recorded by [`submit`], if any.
pub fn job_id(space: &DesignSpace) -> Option<String> {
    std::fs::read_to_string(space.output.join("slurm").join("job_id")).ok().map(|s| s.trim().to_string())
}

/// What the scheduler says of the recorded job: `squeue` lines (tasks pending or
/// running) and `sacct` lines (every task's state), each when the tool is present and
/// answers. `None` without a recorded job.
pub fn scheduler_report(space: &DesignSpace) -> Option<String> {
    let id = job_id(space)?;
    let mut s = format!("Slurm job {id}\n");
    let run = |program: &str, args: &[&str]| -> Option<String> {
        let out = Command::new(program).args(args).output().ok()?;
        out.status.success().then(|| String::from_utf8_lossy(&out.stdout).into_owned())
    };
    match run("squeue", &["-h", "-r", "-j", &id, "-o", "%i %T %M"]) {
        Some(q) if q.trim().is_empty() => s.push_str("squeue: no task pending or running\n"),
        Some(q) => {
            s.push_str("squeue (task state elapsed):\n");
            s.push_str(&q);
        }
        None => s.push_str("squeue: not available\n"),
    }
    match run("sacct", &["-n", "-X", "-P", "-j", &id, "-o", "JobID,State,Elapsed,ExitCode"]) {
        Some(a) if !a.trim().is_empty() => {
            s.push_str("sacct (task|state|elapsed|exit):\n");
            s.push_str(&a);
        }
        _ => s.push_str("sacct: no accounting answer (no slurmdbd?)\n"),
    }
    Some(s)
}
