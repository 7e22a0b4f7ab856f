//! Cost of one normal-force evaluation per law: what the series (Hertz–Reissner) law costs
//! over plain Hertz and a linear spring, both through `NormalLaw` (constants derived per call)
//! and as the DEM step evaluates it (`HertzReissnerScaled`, constants precomputed per contact:
//! force, tangent stiffness and Hertz indentation for the Mindlin spring).
//!
//! Run: `CARGO_TARGET_DIR=... cargo bench --bench contact_laws -- --noplot`; time per 1024
//! evaluations. The overlaps 1–1024 nm with k_H = 3e10 N/m^1.5, k_R = 4e6 N/m span
//! s = δ (k_H/k_R)² = 0.06 … 58, where both parts of the law matter.
use criterion::{criterion_group, criterion_main, Criterion};
use demfem::contact::{HertzReissnerScaled, NormalLaw};
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
    let scaled = HertzReissnerScaled::new(3.0e10, 4.0e6).expect("valid stiffnesses");
    g.bench_function("hertz_reissner_precomputed", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &d in &overlaps {
                let (f, k, d_h) = scaled.evaluate(black_box(d));
                s += f + k + d_h;
            }
            s
        })
    });
    g.finish();
}

criterion_group!(benches, bench_laws);
criterion_main!(benches);
