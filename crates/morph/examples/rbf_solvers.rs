//! Same-run timing of the sparse RBF solvers on one compactly supported case:
//! `Solver::Sparse` (faer's sparse Cholesky) against `Solver::Iterative` (conjugate
//! gradients), build time only (solve + assembly), as wall and process CPU time.
//!
//! ```text
//! cargo run --release -p cadmorph-morph --example rbf_solvers -- N_CENTRES SUPPORT PAIRS [sparse|iterative|both]
//! ```
//!
//! Centres uniform in [0, 1]³ from a fixed seed, displacements uniform in ±0.05 (the
//! inputs of `benches/pygem/compare.py`'s Wendland case, not its exact numbers).

use cadmorph_morph::math::{Point3, Vector3};
use cadmorph_morph::rbf::{Kernel, RbfOptions, Solver};
use cadmorph_morph::{Deformation, Rbf};
use rand::{Rng, SeedableRng};
use std::time::Instant;

/// User + system CPU time of the process so far, from `/proc/self/stat` (clock ticks).
fn cpu_s() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(f64::NAN);
    (ticks(11) + ticks(12)) / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|v| v.parse().ok()).unwrap_or(50_000);
    let support: f64 = args.get(2).and_then(|v| v.parse().ok()).unwrap_or(0.08);
    let pairs: usize = args.get(3).and_then(|v| v.parse().ok()).unwrap_or(1);
    let which = args.get(4).map_or("both", String::as_str);
    rayon::ThreadPoolBuilder::new().use_current_thread().build_global().expect("the global thread pool");
    let mut rng = rand_xorshift::XorShiftRng::seed_from_u64(7);
    let centres: Vec<Point3<f64>> =
        (0..n).map(|_| Point3::new(rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>())).collect();
    let d: Vec<Vector3<f64>> = (0..n)
        .map(|_| Vector3::new(rng.gen_range(-0.05..0.05), rng.gen_range(-0.05..0.05), rng.gen_range(-0.05..0.05)))
        .collect();
    let kernel = Kernel::from_name("wendland_c2", support, None).expect("wendland_c2");
    let mut solvers = Vec::new();
    if which != "iterative" {
        solvers.push(("sparse", Solver::Sparse));
    }
    if which != "sparse" {
        solvers.push(("iterative", Solver::Iterative));
    }
    for pair in 0..pairs {
        let mut line = format!("pair={pair} n={n} support={support}");
        let mut results = Vec::new();
        for &(name, solver) in &solvers {
            let (c0, t0) = (cpu_s(), Instant::now());
            let rbf = Rbf::try_new_with(&centres, &d, kernel, RbfOptions { solver, ..RbfOptions::default() });
            let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_s() - c0);
            match rbf {
                Ok(rbf) => {
                    let p = rbf.deform_point(&Point3::new(0.5, 0.5, 0.5));
                    line += &format!(" {name}_wall_s={wall:.3} {name}_cpu_s={cpu:.2}");
                    results.push(p);
                }
                Err(e) => line += &format!(" {name}=error({e})"),
            }
        }
        if results.len() == 2 {
            line += &format!(" max_diff={:.2e}", (results[0] - results[1]).norm());
        }
        let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
        line += &format!(" loadavg={}", load.split_whitespace().next().unwrap_or("?"));
        println!("{line}");
    }
}
