//! Plan lookup (precomputed table) vs the iterative search, per query over all 225 pairs.
//! Run: `cargo bench -p mmic-benches --bench motion`.

use criterion::{criterion_group, criterion_main, Criterion};
use mmic::motion::{route, State};
use std::hint::black_box;
use std::time::Duration;

fn plans(c: &mut Criterion) {
    let pairs: Vec<(State, State)> = State::ALL
        .iter()
        .flat_map(|f| State::ALL.iter().map(move |t| (*f, *t)))
        .collect();
    let mut g = c.benchmark_group("plan (all 225 pairs per iteration)");
    g.bench_function("lookup (table)", |b| {
        b.iter(|| {
            pairs
                .iter()
                .map(|(f, t)| route::lookup(black_box(*f), black_box(*t)).len())
                .sum::<usize>()
        })
    });
    g.bench_function("search (iterative deepening)", |b| {
        b.iter(|| {
            pairs
                .iter()
                .map(|(f, t)| route::search(black_box(*f), black_box(*t)).len())
                .sum::<usize>()
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_millis(500)).sample_size(30);
    targets = plans
}
criterion_main!(benches);
