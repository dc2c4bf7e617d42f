//! Timing driver for `benches/pygem/compare.py`: runs one morph case on inputs written by
//! the script (NumPy `.npy`, PyGeM `.prm`) and prints time and peak memory.
//!
//! ```text
//! cargo run --release -p cadmorph-morph --example morph_bench -- CASE DIR
//! ```
//!
//! CASE is `ffd` (reads `DIR/ffd.prm`), `rbf:<kernel>:<radius>` or `idw:pygem:<p>` /
//! `idw:paper:<p>` (read `DIR/centres.npy`, `DIR/deformed.npy`); all read `DIR/points.npy`
//! (n × 3, little-endian f64, C order) and write the deformed points to
//! `DIR/out_cadmorph.npy`. The printed line is `key=value` pairs:
//! `build_s` (solve / parse), `deform_s`, `total_s`, `peak_rss_mb` (the process's VmHWM
//! while the morph ran, reset after the inputs were read),
//! `points_mb` (the point array), `rss_before_mb` (resident size before the morph ran).
//! With `CADMORPH_BENCH_REPEAT=n` the deformation is run on n more copies of the input
//! and `deform_min_s` is the fastest of all runs (the other figures are the first run's).

use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::rbf::Kernel;
use cadmorph_morph::{Deformation, Ffd, Idw, IdwVariant, Rbf};
use std::path::Path;
use std::time::Instant;

fn read_npy_points(path: &Path) -> Vec<Point3<f64>> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(&bytes[..6], b"\x93NUMPY", "{}: not .npy", path.display());
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        _ => (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12),
    };
    let header = std::str::from_utf8(&bytes[start..start + len]).unwrap();
    assert!(header.contains("'<f8'") && header.contains("False"), "{header}");
    bytes[start + len..]
        .chunks_exact(24)
        .map(|c| {
            let f = |i: usize| f64::from_le_bytes(c[8 * i..8 * i + 8].try_into().unwrap());
            Point3::new(f(0), f(1), f(2))
        })
        .collect()
}

fn write_npy_points(path: &Path, pts: &[Point3<f64>]) {
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, 3), }}", pts.len());
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 24 * pts.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for p in pts {
        for v in [p.x, p.y, p.z] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(path, out).unwrap();
}

/// A `kB` field of `/proc/self/status` in MB.
fn status_mb(field: &str) -> f64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find(|l| l.starts_with(field))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        eprintln!("usage: morph_bench CASE DIR   (CASE: ffd | rbf:<kernel>:<radius> | idw:<pygem|paper>:<p>)");
        std::process::exit(2);
    }
    let (case, dir) = (&args[1], Path::new(&args[2]));
    // As the cadmorph CLI does: the main thread is worker 0 of the pool, so a parallel
    // loop starts on it instead of waking every worker (see `start_thread_pool` in the
    // CLI). Process set-up, like PyGeM's imports, so before the clock.
    rayon::ThreadPoolBuilder::new().use_current_thread().build_global().expect("the global thread pool");
    let mut points = read_npy_points(&dir.join("points.npy"));
    let points_mb = (points.len() * 24) as f64 / 1048576.0;
    let rss_before = status_mb("VmRSS:");
    // Reset the high-water mark so that the peak below is the morph's (with the point
    // array resident), not the file reading's.
    let _ = std::fs::write("/proc/self/clear_refs", "5");
    let t0 = Instant::now();
    let parts: Vec<&str> = case.split(':').collect();
    let morph: Box<dyn Deformation> = match parts[0] {
        "ffd" => {
            let text = std::fs::read_to_string(dir.join("ffd.prm")).unwrap();
            Box::new(Ffd::from_prm(&text).unwrap_or_else(|e| panic!("ffd.prm: {e}")))
        }
        "rbf" | "idw" => {
            let centres = read_npy_points(&dir.join("centres.npy"));
            let deformed = read_npy_points(&dir.join("deformed.npy"));
            let d: Vec<Vector3<f64>> = centres.iter().zip(&deformed).map(|(a, b)| b - a).collect();
            if parts[0] == "rbf" {
                let radius: f64 = parts[2].parse().unwrap();
                let kernel = Kernel::from_name(parts[1], radius, None).unwrap_or_else(|| panic!("kernel {}", parts[1]));
                Box::new(Rbf::try_new(&centres, &d, kernel).unwrap_or_else(|e| panic!("rbf: {e}")))
            } else {
                let p: u32 = parts[2].parse().unwrap();
                let variant = match parts[1] {
                    "pygem" => IdwVariant::PyGem { power: p },
                    _ => IdwVariant::Paper { power: p as f64, cutoff: None },
                };
                Box::new(Idw::try_new(&centres, &d, variant).unwrap())
            }
        }
        other => panic!("unknown case {other}"),
    };
    let build = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    morph.deform(&mut points);
    let deform = t1.elapsed().as_secs_f64();
    let total = t0.elapsed().as_secs_f64();
    let peak = status_mb("VmHWM:");
    // CADMORPH_BENCH_REPEAT=n: deform n more copies of the input and report the fastest
    // deformation too (build excluded), to see through the noise of a shared machine.
    let repeat: usize = std::env::var("CADMORPH_BENCH_REPEAT").ok().and_then(|v| v.parse().ok()).unwrap_or(0);
    let mut extra = String::new();
    if repeat > 0 {
        let input = read_npy_points(&dir.join("points.npy"));
        let mut best = deform;
        for _ in 0..repeat {
            let mut copy = input.clone();
            let t = Instant::now();
            morph.deform(&mut copy);
            best = best.min(t.elapsed().as_secs_f64());
        }
        extra = format!(" deform_min_s={best:.6} repeats={}", repeat + 1);
    }
    drop(morph);
    write_npy_points(&dir.join("out_cadmorph.npy"), &points);
    println!(
        "case={case} n_points={} build_s={build:.4} deform_s={deform:.4} total_s={total:.4} peak_rss_mb={peak:.1} points_mb={points_mb:.1} rss_before_mb={rss_before:.1}{extra}",
        points.len()
    );
}
