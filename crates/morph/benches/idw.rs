//! IDW with 100 control points on 1e5 points, power 2: PyGeM's variant (Minkowski distance,
//! weight 1/d) and the paper's (weight d⁻²), plus the paper's with a k-d tree cutoff.
#![allow(missing_docs)] // criterion_group! generates an undocumented public function

mod common;

use cadmorph_morph::{Deformation, Idw, IdwVariant};
use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let centres = common::points(100, 0.0, 1.0, 1);
    let d = common::moves(100, 0.05, 2);
    let pts = common::points(100_000, 0.0, 1.0, 3);
    let mut g = c.benchmark_group("morph/idw_deform");
    g.sample_size(10).measurement_time(Duration::from_secs(2)).throughput(Throughput::Elements(pts.len() as u64));
    for (name, variant) in [
        ("pygem_p2", IdwVariant::PyGem { power: 2 }),
        ("paper_p2", IdwVariant::Paper { power: 2.0, cutoff: None }),
        ("paper_p2_cutoff0.3", IdwVariant::Paper { power: 2.0, cutoff: Some(0.3) }),
    ] {
        let idw = Idw::try_new(&centres, &d, variant).unwrap();
        g.bench_function(format!("{name}/nc100/1e5_pts"), |b| {
            b.iter_batched_ref(|| pts.clone(), |p| idw.deform(black_box(p)), BatchSize::LargeInput)
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
