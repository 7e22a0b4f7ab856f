//! What one `rayon::join` costs on this machine (development aid for the parallel DEM step,
//! which makes two joins per step): a two-thread pool runs `rounds` joins of two equal spins
//! of `work` µs each, and the time per join beyond `work` is the join's cost (handing the
//! second half to the other thread, and waiting for the later of the two to end). Also the
//! same with 1 µs of serial work between joins, as the step has.
//!
//! Usage: `join_cost [work µs (20)] [rounds (20000)]`; prints medians of five repetitions.
use std::hint::black_box;
use std::time::Instant;

/// Spins for `us` µs of wall-clock time.
fn spin(us: f64) {
    let t = Instant::now();
    let mut x = 1.0f64;
    while t.elapsed().as_secs_f64() * 1e6 < us {
        for _ in 0..64 {
            x = black_box(x * 1.000_000_1 + 1e-9);
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let work: f64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(20.0);
    let rounds: u32 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(20_000);
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(2).build() {
        Ok(pool) => pool,
        Err(e) => {
            eprintln!("join_cost: no thread pool: {e}");
            std::process::exit(1);
        }
    };
    let per_join = |serial: f64| -> f64 {
        pool.install(|| {
            let t = Instant::now();
            for _ in 0..rounds {
                rayon::join(|| spin(work), || spin(work));
                if serial > 0.0 {
                    spin(serial);
                }
            }
            t.elapsed().as_secs_f64() * 1e6 / f64::from(rounds) - work - serial
        })
    };
    let back_to_back = median((0..5).map(|_| per_join(0.0)).collect());
    let with_serial = median((0..5).map(|_| per_join(1.0)).collect());
    println!(
        "rayon::join of two {work} µs halves on 2 threads: {back_to_back:.2} µs per join back to \
         back, {with_serial:.2} µs with 1 µs of serial work between joins (medians of 5 × \
         {rounds} joins)"
    );
}
