//! RBF: thin-plate spline with 1000 centres on 1e5 points and 4000 centres on 1e6 points
//! (dense: null-space method, faer Cholesky), Wendland C2 with 50,000 centres on 1e6 points (sparse
//! Cholesky or conjugate gradients). Solve and evaluation are timed separately.
#![allow(missing_docs)] // criterion_group! generates an undocumented public function

mod common;

use cadmorph_morph::rbf::Kernel;
use cadmorph_morph::{Deformation, Rbf};
use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use std::time::Duration;

/// `time_solve`: whether to time the solve too (the 50k Wendland solve takes a minute, so
/// `benches/pygem/compare.py` reports it once instead of ten times here).
fn case(c: &mut Criterion, name: &str, kernel: Kernel, nc: usize, np: usize, time_solve: bool) {
    let centres = common::points(nc, 0.0, 1.0, 1);
    let d = common::moves(nc, 0.05, 2);
    let pts = common::points(np, 0.0, 1.0, 3);
    let mut g = c.benchmark_group("morph/rbf");
    g.sample_size(10).measurement_time(Duration::from_secs(2));
    if time_solve {
        g.bench_function(format!("{name}/solve"), |b| {
            b.iter(|| Rbf::try_new(black_box(&centres), &d, kernel).unwrap())
        });
    }
    let rbf = Rbf::try_new(&centres, &d, kernel).unwrap();
    g.throughput(Throughput::Elements(np as u64));
    g.bench_function(format!("{name}/deform"), |b| {
        b.iter_batched_ref(|| pts.clone(), |p| rbf.deform(black_box(p)), BatchSize::LargeInput)
    });
    g.finish();
}

fn bench(c: &mut Criterion) {
    case(c, "thin_plate_nc1000/1e5_pts", Kernel::ThinPlate { radius: 0.5, k: 2 }, 1000, 100_000, true);
    case(c, "thin_plate_nc4000/1e6_pts", Kernel::ThinPlate { radius: 0.5, k: 2 }, 4000, 1_000_000, true);
    case(c, "wendland_c2_nc50000/1e6_pts", Kernel::WendlandC2 { support: 0.08 }, 50_000, 1_000_000, false);
}

criterion_group!(benches, bench);
criterion_main!(benches);
