//! Criterion bench over a representative subset of the corpus: the smallest instance of
//! six optimal-control families (three transcriptions) and four CUTEst-style problems.
//! `cargo bench -p corpus --bench corpus`.
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

const SUBSET: &[&str] = &[
    "rocket_trap_400",
    "steering_trap_200",
    "catmix_colloc_100",
    "race_car_rk4_100",
    "vdp_rk4_20",
    "cartpole_trap_50",
];

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("corpus");
    group.sample_size(10);
    let options = corpus::run::options(60.0);
    let names = SUBSET.iter().map(|s| s.to_string()).chain(
        corpus::cute::FAMILIES
            .iter()
            .take(4)
            .map(|f| format!("{}_{}", f.name, f.sizes[0])),
    );
    for name in names {
        let inst = corpus::instance(&name).expect("instance exists");
        let mut compiled = inst.build().and_then(|p| p.compile()).expect("compiles");
        group.bench_function(&name, |b| {
            b.iter(|| {
                black_box(
                    corpus::run::solve_compiled(&inst, &mut compiled, 0.0, &options)
                        .expect("solves"),
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
