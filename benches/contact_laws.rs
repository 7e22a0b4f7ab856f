//! Cost of one normal-force evaluation per law: what the series (Hertz–Reissner) law costs
//! over plain Hertz and a linear spring.
use criterion::{criterion_group, criterion_main, Criterion};
use demfem::contact::NormalLaw;
use std::hint::black_box;

fn bench_laws(c: &mut Criterion) {
    let overlaps: Vec<f64> = (1..=1024).map(|i| i as f64 * 1e-9).collect();
    let laws = [
        ("hertz", NormalLaw::Hertz { k_h: 3.0e10 }),
        ("linear", NormalLaw::Linear { k: 2.0e7 }),
        (
            "hertz_reissner",
            NormalLaw::HertzReissner {
                k_h: 3.0e10,
                k_r: 4.0e6,
            },
        ),
    ];
    let mut g = c.benchmark_group("normal_force_1024");
    for (name, law) in laws {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut s = 0.0;
                for &d in &overlaps {
                    s += law.force_and_stiffness(black_box(d)).0;
                }
                s
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_laws);
criterion_main!(benches);
