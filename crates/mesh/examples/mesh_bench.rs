//! The cadmorph side of `benches/mesh/run.sh`: one operation on an OpenFOAM case, timed,
//! printed as one JSON line (seconds, peak resident memory in MB).
//!
//! ```text
//! mesh_bench quality CASE          PolyMesh::read, then Quality::of (both timed)
//! mesh_bench readwrite CASE OUT    PolyMesh::read + write of a moved mesh (timed together)
//! mesh_bench vtu FILE OUT          Vtu read + write of a moved mesh (timed together)
//! mesh_bench rbf CASE CENTRES [single|multilevel [RATIO [TOL]]]
//!                                  boundary → interior RBF morph of the bump patch,
//!                                  Wendland C2, support 0.6, at most CENTRES centres:
//!                                  multilevel (default; support halved per level,
//!                                  RATIO support / centre spacing, default 4) or the
//!                                  single level with greedy centres; TOL the
//!                                  asked match at the constrained nodes (default 1e-3)
//! mesh_bench rbf-export CASE DIR    the nodes (DIR/points.npy), the constrained ones
//!                                  (DIR/constrained.npy, indices) and their
//!                                  displacements (DIR/displacements.npy) of the rbf
//!                                  case, for benches/mesh/rbf_vs_pygem.py
//! ```
//!
//! The rbf line also gives the levels and centres per level, the seconds of the solve
//! alone, the resident memory before it (the mesh and constraints) and the peak right
//! after it, the peak of the whole run (`peak_mb`), the negative volumes (`Quality::of` after the morph) and the smallest ratio of a
//! cell's volume after / before (both outside the timing).

use std::path::Path;
use std::time::Instant;

use cadmorph_mesh::format::foam::PolyMesh;
use cadmorph_mesh::format::vtu::Vtu;
use cadmorph_mesh::quality::{Geometry, Quality};
use cadmorph_mesh::volume::{patch_constraints, BoundaryMorph, Constraint, Multilevel, PatchMotion};
use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::Deformation;

fn peak_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map(|kb| kb / 1024.0)
        .unwrap_or(0.0)
}

fn rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmRSS:")).and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map(|kb| kb / 1024.0)
        .unwrap_or(0.0)
}

/// A smooth lift of the bump: y += 0.1 · sin(π x / 3)², the channel being 3 long.
struct Lift;
impl Deformation for Lift {
    fn deform_point(&self, p: &Point3<f64>) -> Point3<f64> {
        let s = (std::f64::consts::PI * p.x / 3.0).sin();
        p + Vector3::new(0.0, 0.1 * s * s, 0.0)
    }
}

/// A NumPy `.npy` file (format 1.0, C order) of `data` with dtype `descr` and `shape`.
fn npy(descr: &str, shape: &str, data: &[u8]) -> Vec<u8> {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend((header.len() as u16).to_le_bytes());
    out.extend(header.as_bytes());
    out.extend(data);
    out
}

fn fail(e: &dyn std::fmt::Display) -> ! {
    eprintln!("mesh_bench: {e}");
    std::process::exit(1)
}

fn main() {
    let _ = rayon::ThreadPoolBuilder::new().use_current_thread().build_global();
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize| args.get(i).map(String::as_str).unwrap_or_else(|| fail(&"missing argument"));
    match args.get(1).map(String::as_str) {
        Some("quality") => {
            let t0 = Instant::now();
            let m = PolyMesh::read(Path::new(arg(2))).unwrap_or_else(|e| fail(&e));
            let t = Instant::now();
            let q = Quality::of(&m);
            let s = t.elapsed().as_secs_f64();
            let total = t0.elapsed().as_secs_f64();
            println!(
                "{{\"op\":\"quality\",\"read_and_check_seconds\":{total},\"seconds\":{s},\"cells\":{},\"max_non_orth\":{},\"max_skewness\":{},\"ok\":{},\"peak_mb\":{}}}",
                q.cells,
                q.max_non_orthogonality.value,
                q.max_skewness.value,
                q.ok(),
                peak_mb()
            );
        }
        Some("readwrite") => {
            let t = Instant::now();
            let mut m = PolyMesh::read(Path::new(arg(2))).unwrap_or_else(|e| fail(&e));
            // Move one point so that the points file is written anew.
            if let Some(p) = m.points.first_mut() {
                p.z += 1e-12;
            }
            m.write(Path::new(arg(3))).unwrap_or_else(|e| fail(&e));
            println!(
                "{{\"op\":\"readwrite\",\"seconds\":{},\"points\":{},\"peak_mb\":{}}}",
                t.elapsed().as_secs_f64(),
                m.points.len(),
                peak_mb()
            );
        }
        Some("vtu") => {
            let t = Instant::now();
            let bytes = std::fs::read(arg(2)).unwrap_or_else(|e| fail(&e));
            let mut v = Vtu::parse(&bytes).unwrap_or_else(|e| fail(&e));
            if let Some(p) = v.points.first_mut() {
                p.z += 1e-12;
            }
            std::fs::write(arg(3), v.write()).unwrap_or_else(|e| fail(&e));
            println!(
                "{{\"op\":\"vtu\",\"seconds\":{},\"points\":{},\"peak_mb\":{}}}",
                t.elapsed().as_secs_f64(),
                v.points.len(),
                peak_mb()
            );
        }
        Some("rbf") => {
            let m = PolyMesh::read(Path::new(arg(2))).unwrap_or_else(|e| fail(&e));
            let max: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(20_000);
            let multilevel = match args.get(4).map(String::as_str) {
                None | Some("multilevel") => Some(Multilevel {
                    ratio: args.get(5).and_then(|s| s.parse().ok()).unwrap_or(Multilevel::default().ratio),
                    ..Multilevel::default()
                }),
                Some("single") => None,
                Some(other) => fail(&format!("unknown rbf variant {other:?} (single or multilevel)")),
            };
            let cons = patch_constraints(&m, &[("bump", PatchMotion::Follow(&Lift)), ("sides", PatchMotion::Slip)])
                .unwrap_or_else(|e| fail(&e));
            let rss_before = rss_mb();
            let tol: f64 = args.get(6).and_then(|s| s.parse().ok()).unwrap_or(1e-3);
            let opts =
                BoundaryMorph { max_centres: max, multilevel, greedy_tol: Some(tol), ..BoundaryMorph::wendland(0.6) };
            let t = Instant::now();
            let (disp, r) = opts.solve(&m.points, &cons).unwrap_or_else(|e| fail(&e));
            let s = t.elapsed().as_secs_f64();
            let solve_peak = peak_mb();
            let mut moved = m.clone();
            for (p, d) in moved.points.iter_mut().zip(&disp) {
                *p += d;
            }
            let q = Quality::of(&moved);
            let (v0, v1) = (Geometry::of(&m).cell_volumes, Geometry::of(&moved).cell_volumes);
            let min_ratio = v0.iter().zip(&v1).map(|(a, b)| b / a).fold(f64::INFINITY, f64::min);
            println!(
                "{{\"op\":\"rbf\",\"variant\":\"{}\",\"seconds\":{s},\"cells\":{},\"constrained\":{},\"centres\":{},\"levels\":{},\"level_centres\":{:?},\"max_rel_error\":{},\"negative_volumes\":{},\"min_volume_ratio\":{min_ratio},\"rss_before_mb\":{rss_before},\"solve_peak_mb\":{solve_peak},\"peak_mb\":{}}}",
                if multilevel.is_some() { "multilevel" } else { "single" },
                m.n_cells(),
                r.constrained,
                r.centres,
                r.rounds,
                r.level_centres,
                r.max_relative_error,
                q.negative_volumes,
                peak_mb()
            );
        }
        Some("rbf-export") => {
            let m = PolyMesh::read(Path::new(arg(2))).unwrap_or_else(|e| fail(&e));
            let dir = Path::new(arg(3));
            let cons = patch_constraints(&m, &[("bump", PatchMotion::Follow(&Lift)), ("sides", PatchMotion::Slip)])
                .unwrap_or_else(|e| fail(&e));
            let (mut idx, mut disp) = (Vec::new(), Vec::new());
            for (i, c) in cons.iter().enumerate() {
                let d = match c {
                    Constraint::Fixed => Vector3::zeros(),
                    Constraint::Moved(d) => *d,
                    _ => continue,
                };
                idx.push(i as i64);
                disp.extend([d.x, d.y, d.z]);
            }
            let pts: Vec<f64> = m.points.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
            let write = |name: &str, descr: &str, shape: String, data: Vec<u8>| {
                std::fs::write(dir.join(name), npy(descr, &shape, &data)).unwrap_or_else(|e| fail(&e))
            };
            write("points.npy", "<f8", format!("({}, 3)", m.points.len()), pts.iter().flat_map(|v| v.to_le_bytes()).collect());
            write("constrained.npy", "<i8", format!("({},)", idx.len()), idx.iter().flat_map(|v| v.to_le_bytes()).collect());
            write(
                "displacements.npy",
                "<f8",
                format!("({}, 3)", idx.len()),
                disp.iter().flat_map(|v| v.to_le_bytes()).collect(),
            );
        }
        _ => fail(&"usage: mesh_bench quality CASE | readwrite CASE OUT | vtu FILE OUT | rbf CASE CENTRES [single|multilevel [RATIO [TOL]]] | rbf-export CASE DIR"),
    }
}
