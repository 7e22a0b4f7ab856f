//! Deterministic parallel reductions: sums over fixed chunks of nodes, added in chunk order,
//! so that a result is bitwise the same for any number of threads.

use rayon::prelude::*;

/// Nodes per parallel work item of a reduction.
pub(crate) const NODE_CHUNK: usize = 2048;

/// Deterministic parallel sum over fixed chunks (independent of the thread count).
pub(crate) fn det_sum<F: Fn(usize) -> f64 + Sync>(n: usize, f: F) -> f64 {
    let n_chunks = n.div_ceil(NODE_CHUNK);
    let partial: Vec<f64> = (0..n_chunks)
        .into_par_iter()
        .map(|c| {
            let mut s = 0.0;
            for i in c * NODE_CHUNK..((c + 1) * NODE_CHUNK).min(n) {
                s += f(i);
            }
            s
        })
        .collect();
    partial.iter().sum()
}
