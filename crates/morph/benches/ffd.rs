//! FFD on a million points (3×3×3 and 6×6×6 lattices): full deformation, and the online
//! product of a bound FFD.
#![allow(missing_docs)] // criterion_group! generates an undocumented public function

mod common;

use cadmorph_morph::{Deformation, Displacements, Ffd};
use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use std::time::Duration;

fn ffd_with_mu(n: usize) -> Ffd {
    let mut ffd = Ffd::unit([n, n, n]);
    let m = common::moves(n * n * n, 0.1, 1);
    let mu = Displacements::try_from_arrays(
        [n, n, n],
        m.iter().map(|v| v.x).collect(),
        m.iter().map(|v| v.y).collect(),
        m.iter().map(|v| v.z).collect(),
    )
    .unwrap();
    ffd.set_mu(mu).unwrap();
    ffd
}

fn bench(c: &mut Criterion) {
    let pts = common::points(1_000_000, -0.1, 1.1, 0);
    let mut g = c.benchmark_group("morph/ffd_deform");
    g.sample_size(10).measurement_time(Duration::from_secs(2)).throughput(Throughput::Elements(pts.len() as u64));
    for n in [3, 6] {
        let ffd = ffd_with_mu(n);
        g.bench_function(format!("{n}x{n}x{n}/1e6_pts"), |b| {
            b.iter_batched_ref(|| pts.clone(), |p| ffd.deform(black_box(p)), BatchSize::LargeInput)
        });
    }
    g.finish();
    let mut g = c.benchmark_group("morph/ffd_bound_deform_with");
    g.sample_size(10).measurement_time(Duration::from_secs(2)).throughput(Throughput::Elements(pts.len() as u64));
    for n in [3, 6] {
        let ffd = ffd_with_mu(n);
        let bound = ffd.bind(&pts);
        let mut out = pts.clone();
        g.bench_function(format!("{n}x{n}x{n}/1e6_pts"), |b| {
            b.iter(|| bound.deform_with(black_box(ffd.mu()), &mut out).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
