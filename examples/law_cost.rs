//! Cost of one normal-law evaluation, for `perf stat` (cycles and instructions of the process
//! do not depend on the load of a shared machine, unlike wall-clock benches):
//!
//! ```text
//! cargo build --release --example law_cost
//! B=$CARGO_TARGET_DIR/release/examples/law_cost
//! perf stat -e cycles:u,instructions:u $B hertz_reissner 0        # setup only
//! perf stat -e cycles:u,instructions:u $B hertz_reissner 20000    # + 20000 × 1024 evaluations
//! ```
//!
//! (difference of the two counts) / (1024 × rounds) = cycles per evaluation. Variants:
//! `hertz`, `linear`, `hertz_reissner` (through `NormalLaw`: constants derived per call),
//! `hertz_reissner_precomputed` (`HertzReissnerScaled`, as the DEM step evaluates it: force,
//! tangent stiffness and Hertz indentation). The overlaps and stiffnesses are those of
//! `benches/contact_laws.rs` (s = 0.06 … 58).
use demfem::contact::{HertzReissnerScaled, NormalLaw};
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let variant = args.get(1).map(String::as_str).unwrap_or("hertz_reissner");
    let rounds: usize = match args.get(2).map(|a| a.parse()) {
        None => 10_000,
        Some(Ok(n)) => n,
        Some(Err(_)) => {
            eprintln!("usage: law_cost VARIANT ROUNDS (ROUNDS a whole number)");
            std::process::exit(2);
        }
    };
    let overlaps: Vec<f64> = (1..=1024).map(|i| i as f64 * 1e-9).collect();
    let (k_h, k_r) = (3.0e10, 4.0e6);
    let law = match variant {
        "hertz" => NormalLaw::Hertz { k_h },
        "linear" => NormalLaw::Linear { k: 2.0e7 },
        "hertz_reissner" | "hertz_reissner_precomputed" => NormalLaw::HertzReissner { k_h, k_r },
        other => {
            eprintln!("unknown variant {other:?}: hertz, linear, hertz_reissner, hertz_reissner_precomputed");
            std::process::exit(2);
        }
    };
    let mut sum = 0.0;
    if variant == "hertz_reissner_precomputed" {
        let scaled = match HertzReissnerScaled::new(k_h, k_r) {
            Ok(law) => law,
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(2);
            }
        };
        for _ in 0..rounds {
            for &d in &overlaps {
                let (f, k, d_h) = scaled.evaluate(black_box(d));
                sum += f + k + d_h;
            }
        }
    } else {
        for _ in 0..rounds {
            for &d in &overlaps {
                sum += law.force_and_stiffness(black_box(d)).0;
            }
        }
    }
    println!("{variant}: {rounds} × 1024 evaluations, checksum {sum:e}");
}
