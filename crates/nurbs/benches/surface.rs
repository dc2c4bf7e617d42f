//! Surface evaluation (point, point + first partials) at 1e6 parameter pairs, and knot
//! refinement with 100 knots per direction, on the bicubic 10×10 surface that
//! `benches/occt/nurbs_occt.cpp` times in OCCT (see `benches/nurbs_vs_occt.sh`).
#![allow(missing_docs)] // criterion_group! generates an undocumented public fn

use std::hint::black_box;

use cadmorph_nurbs::{NurbsSurface, Surface};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};

fn rational() -> NurbsSurface {
    let s = cadmorph_testkit::occt_bench_surface();
    let w = (0..100).map(|k| 1.0 + 0.5 * ((k % 7) as f64 / 7.0)).collect();
    NurbsSurface::new(
        (3, 3),
        (s.u_knots().clone(), s.v_knots().clone()),
        (10, 10),
        s.control_points().to_vec(),
        Some(w),
    )
}

fn eval(c: &mut Criterion) {
    let grid: Vec<f64> = (0..1000).map(|a| a as f64 / 999.0).collect();
    let mut g = c.benchmark_group("nurbs/eval_surface");
    g.sample_size(10);
    g.throughput(Throughput::Elements(1_000_000));
    for (name, s) in [("deg3_10x10", cadmorph_testkit::occt_bench_surface()), ("deg3_10x10_rational", rational())] {
        g.bench_function(format!("point/{name}/1e6"), |b| {
            b.iter(|| {
                let mut sum = 0.0;
                for &u in &grid {
                    for &v in &grid {
                        sum += s.eval(black_box(u), black_box(v)).x;
                    }
                }
                sum
            })
        });
        g.bench_function(format!("d1/{name}/1e6"), |b| {
            b.iter(|| {
                let mut sum = 0.0;
                for &u in &grid {
                    for &v in &grid {
                        let d = s.eval_d1(black_box(u), black_box(v));
                        sum += d.point.x + d.du.y + d.dv.z;
                    }
                }
                sum
            })
        });
    }
    g.finish();
}

fn refine(c: &mut Criterion) {
    let s = cadmorph_testkit::occt_bench_surface();
    let x: Vec<f64> = (0..100).map(|k| (k as f64 + 0.5) / 100.0).collect();
    let mut g = c.benchmark_group("nurbs/refine_surface");
    g.throughput(Throughput::Elements(200));
    g.bench_function("deg3_10x10/100_per_direction", |b| {
        b.iter_batched(
            || s.clone(),
            |mut r| {
                r.refine_u(black_box(&x)).expect("inside");
                r.refine_v(black_box(&x)).expect("inside");
                r
            },
            BatchSize::SmallInput,
        )
    });
    g.finish();
}

criterion_group!(benches, eval, refine);
criterion_main!(benches);
