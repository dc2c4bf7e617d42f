//! The cadmorph side of `benches/nurbs_vs_occt.sh`: the same surface, points and knots
//! as `benches/occt/nurbs_occt.cpp`, timed the same way (best of `--repeat`, single
//! thread), printed as one JSON line with the same field names.

use std::hint::black_box;
use std::time::Instant;

use cadmorph_nurbs::Surface;

fn best<F: FnMut() -> f64>(repeat: usize, mut f: F) -> (f64, f64) {
    let mut best = f64::INFINITY;
    let mut out = 0.0;
    for _ in 0..repeat {
        let t = Instant::now();
        out = f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best, out)
}

fn main() {
    let repeat = std::env::args().skip_while(|a| a != "--repeat").nth(1).and_then(|r| r.parse().ok()).unwrap_or(5usize);
    let s = cadmorph_testkit::occt_bench_surface();
    let grid: Vec<f64> = (0..1000).map(|a| a as f64 / 999.0).collect();
    let (eval_s, checksum_eval) = best(repeat, || {
        let mut sum = 0.0;
        for &u in &grid {
            for &v in &grid {
                let p = s.eval(black_box(u), black_box(v));
                sum += p.x + p.y + p.z;
            }
        }
        sum
    });
    let (d1_s, checksum_d1) = best(repeat, || {
        let mut sum = 0.0;
        for &u in &grid {
            for &v in &grid {
                let d = s.eval_d1(black_box(u), black_box(v));
                sum += d.point.x + d.point.y + d.point.z + d.du.sum() + d.dv.sum();
            }
        }
        sum
    });
    let x: Vec<f64> = (0..100).map(|k| (k as f64 + 0.5) / 100.0).collect();
    let mut refined = s.clone();
    let (refine_s, _) = best(repeat * 10, || {
        let mut r = black_box(s.clone());
        r.refine_u(&x).expect("inside the domain");
        r.refine_v(&x).expect("inside the domain");
        refined = r;
        0.0
    });
    let checksum_refine_poles: f64 = refined.control_points().iter().map(|p| p.x + p.y + p.z).sum();
    let mut max_dev: f64 = 0.0;
    for a in 0..=100 {
        for b in 0..=100 {
            let (u, v) = (a as f64 / 100.0, b as f64 / 100.0);
            max_dev = max_dev.max((refined.eval(u, v) - s.eval(u, v)).norm());
        }
    }
    println!(
        "{{\"eval_1e6_s\":{eval_s},\"d1_1e6_s\":{d1_s},\"refine_100_s\":{refine_s},\"checksum_eval\":{checksum_eval},\
\"checksum_d1\":{checksum_d1},\"checksum_refine_poles\":{checksum_refine_poles},\"refine_poles\":[{},{}],\
\"refine_max_dev\":{max_dev:e},\"eval_points_per_s\":{},\"repeat\":{repeat}}}",
        refined.n_u(),
        refined.n_v(),
        1e6 / eval_s
    );
}
