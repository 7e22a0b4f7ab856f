//! The element-force kernel of the explicit tet solver: nodal forces K·u of constant-strain
//! tets, in one pass over the elements with no per-element buffer.
//!
//! **Colours of blocks.** The elements, in mesh order, are cut into blocks of
//! [`BLOCK`] consecutive elements, and the blocks are coloured greedily (in order, smallest
//! free colour) so that no two blocks of a colour share a node. The blocks of a colour run
//! in parallel, each on one thread adding its elements' nodal forces straight into the
//! output in element order, without races; the colours run one after another. Each node's
//! force is therefore the sum of its elements' contributions in a fixed order, whatever the
//! number of threads (bitwise). Consecutive elements share nodes, so a block reads and
//! writes a compact part of the nodal arrays; a banded mesh needs a few colours.
//!
//! **Streamed data.** Per element only √V ∇N_1..∇N_3 (72 bytes) and the connectivity (16
//! bytes) are read, in colour order: ∇N_0 = −(∇N_1 + ∇N_2 + ∇N_3), and with g̃ = √V ∇N the
//! gradient h̃ = Σ u_a ⊗ g̃_a = √V h gives a stress σ̃ = √V σ (linear elasticity), so the
//! nodal force V σ ∇N_a = σ̃ g̃_a needs no volume. Against the earlier kernel (104 bytes of
//! gradients and volume, a 96-byte force buffer written and read back through a node
//! adjacency) this moves about a third of the bytes; what is left is mostly the scalar
//! arithmetic (about 110 cycles a tet on the 2-layer cluster).

use rayon::prelude::*;

use crate::error::{DemfemError, Result};
use crate::fem::assembly::precompute_tets;
use crate::fem::element::Tet4;
use crate::fem::mesh::TetMesh;

/// Consecutive elements per block (one work item).
pub const BLOCK: usize = 256;
/// Nodes per parallel work item when the output is cleared.
const NODE_CHUNK: usize = 4096;

/// Element-force kernel: precomputed scaled gradients and 32-bit connectivity in colour
/// order, and the elements' geometry in mesh order.
#[derive(Debug, Clone)]
pub struct TetForceKernel {
    tets: Vec<Tet4>,
    scaled: Vec<[[f64; 3]; 3]>,
    conn: Vec<[u32; 4]>,
    // Block b holds the elements blocks[b]..blocks[b + 1] of the reordered arrays; colour c
    // the blocks colours[c]..colours[c + 1].
    blocks: Vec<usize>,
    colours: Vec<usize>,
    n_nodes: usize,
    lambda: f64,
    mu: f64,
    avx2: bool,
}

/// The output of one colour, shared by the threads: every block of a colour writes only
/// its own nodes, and no two blocks of a colour share one.
#[derive(Clone, Copy)]
struct SharedOut(*mut [f64; 3]);

// SAFETY: the pointer is only written through `add`, at nodes that no other block of the
// same colour (the only ones running concurrently) touches.
unsafe impl Send for SharedOut {}
unsafe impl Sync for SharedOut {}

impl SharedOut {
    /// Add `f` to node `i`.
    ///
    /// # Safety
    /// `i` is within the output, and no other thread reads or writes node `i` meanwhile.
    #[inline(always)]
    unsafe fn add(&self, i: usize, f: [f64; 3]) {
        let p = self.0.add(i);
        (*p)[0] += f[0];
        (*p)[1] += f[1];
        (*p)[2] += f[2];
    }
}

/// Greedy colouring of `n_items` items whose nodes are `nodes(i)` (in item order, smallest
/// colour not held by an earlier item sharing a node): returns the colour of every item.
fn greedy_colours<'a>(
    n_items: usize,
    n_nodes: usize,
    nodes: impl Fn(usize) -> &'a [u32],
) -> Vec<u32> {
    let mut words = 1usize;
    let mut used = vec![0u64; n_nodes];
    let mut colour = Vec::with_capacity(n_items);
    for item in 0..n_items {
        let n = nodes(item);
        let c = loop {
            let mut free = None;
            for w in 0..words {
                let mut mask = 0u64;
                for &i in n {
                    mask |= used[i as usize * words + w];
                }
                if mask != u64::MAX {
                    free = Some(64 * w + (!mask).trailing_zeros() as usize);
                    break;
                }
            }
            match free {
                Some(c) => break c,
                None => {
                    // More than 64·words colours: widen every node's set by one word.
                    let mut wider = vec![0u64; n_nodes * (words + 1)];
                    for i in 0..n_nodes {
                        wider[i * (words + 1)..i * (words + 1) + words]
                            .copy_from_slice(&used[i * words..(i + 1) * words]);
                    }
                    used = wider;
                    words += 1;
                }
            }
        };
        for &i in n {
            used[i as usize * words + c / 64] |= 1u64 << (c % 64);
        }
        colour.push(c as u32);
    }
    colour
}

impl TetForceKernel {
    /// Precompute for `mesh` with Lamé constants `lambda`, `mu` (Pa).
    pub fn new(mesh: &TetMesh, lambda: f64, mu: f64) -> Result<Self> {
        mesh.validate()?;
        if mesh.nodes.len() >= u32::MAX as usize {
            return Err(DemfemError::ShapeMismatch {
                field: "mesh.nodes".into(),
                detail: "too many nodes for 32-bit indices".into(),
            });
        }
        let tets = precompute_tets(mesh)?;
        let conn: Vec<[u32; 4]> = mesh.tets.iter().map(|t| t.map(|i| i as u32)).collect();
        // Blocks of consecutive elements and the nodes of each (sorted, unique).
        let n_blocks = conn.len().div_ceil(BLOCK);
        let block_nodes: Vec<Vec<u32>> = (0..n_blocks)
            .map(|b| {
                let mut v: Vec<u32> = conn[b * BLOCK..((b + 1) * BLOCK).min(conn.len())]
                    .iter()
                    .flatten()
                    .copied()
                    .collect();
                v.sort_unstable();
                v.dedup();
                v
            })
            .collect();
        let colour = greedy_colours(n_blocks, mesh.nodes.len(), |b| &block_nodes[b]);
        let n_colours = colour.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
        let mut colours = vec![0usize; n_colours + 1];
        for &c in &colour {
            colours[c as usize + 1] += 1;
        }
        for c in 0..n_colours {
            colours[c + 1] += colours[c];
        }
        // Blocks in colour order (ascending within a colour), elements in mesh order inside.
        let mut block_order = vec![0usize; n_blocks];
        let mut fill = colours.clone();
        for (b, &c) in colour.iter().enumerate() {
            block_order[fill[c as usize]] = b;
            fill[c as usize] += 1;
        }
        let mut order = Vec::with_capacity(conn.len());
        let mut blocks = vec![0usize];
        for &b in &block_order {
            order.extend(b * BLOCK..((b + 1) * BLOCK).min(conn.len()));
            blocks.push(order.len());
        }
        let scaled = order
            .iter()
            .map(|&e| {
                let t = &tets[e];
                let s = t.volume.sqrt();
                [1, 2, 3].map(|a| t.grads[a].map(|g| g * s))
            })
            .collect();
        let conn = order.iter().map(|&e| conn[e]).collect();
        Ok(Self {
            tets,
            scaled,
            conn,
            blocks,
            colours,
            n_nodes: mesh.nodes.len(),
            lambda,
            mu,
            avx2: crate::cpu::has_avx2(),
        })
    }

    /// Precomputed element geometry, in mesh order.
    pub fn tets(&self) -> &[Tet4] {
        &self.tets
    }

    /// Number of elements.
    pub fn n_elements(&self) -> usize {
        self.tets.len()
    }

    /// Number of colours (groups of blocks with no shared node).
    pub fn n_colours(&self) -> usize {
        self.colours.len().saturating_sub(1)
    }

    /// Nodal forces K·`u` (N) for nodal displacements `u` (m), written into `out`; no
    /// allocation. `u` and `out` must have one entry per node of the mesh (else the call
    /// panics: a programming error, not user input).
    pub fn apply(&mut self, u: &[[f64; 3]], out: &mut [[f64; 3]]) {
        assert!(
            u.len() == self.n_nodes && out.len() == self.n_nodes,
            "TetForceKernel::apply: {} displacements and {} outputs for {} nodes",
            u.len(),
            out.len(),
            self.n_nodes
        );
        out.par_chunks_mut(NODE_CHUNK)
            .for_each(|c| c.fill([0.0; 3]));
        let (lambda, mu) = (self.lambda, self.mu);
        let shared = SharedOut(out.as_mut_ptr());
        let (scaled, conn) = (&self.scaled, &self.conn);
        let avx2 = self.avx2;
        let run = |e0: usize, e1: usize| {
            // SAFETY: the nodes of elements e0..e1 are < n_nodes (validated mesh, checked
            // lengths), and no other block of this colour, the only ones running
            // concurrently, has any of them; `avx2` is set only when the CPU has AVX2.
            unsafe { run_block(avx2, &scaled[e0..e1], &conn[e0..e1], u, lambda, mu, shared) }
        };
        let blocks = &self.blocks;
        for w in self.colours.windows(2) {
            let (lo, hi) = (w[0], w[1]);
            if hi - lo == 1 {
                run(blocks[lo], blocks[lo + 1]);
            } else {
                (lo..hi)
                    .into_par_iter()
                    .for_each(|b| run(blocks[b], blocks[b + 1]));
            }
        }
    }
}

/// Add the nodal forces of the elements (`scaled`, `conn`) into `shared`, through the same
/// body compiled with AVX2 when `avx2` is set (the same IEEE operations in the same order:
/// Rust never fuses a multiply and an add on its own, so the results are bitwise those of
/// the baseline build; the VEX encoding and the wider registers make it faster).
///
/// # Safety
/// Every node of `conn` is within the output, no other thread touches those nodes
/// meanwhile, and `avx2` is set only when the CPU has AVX2.
#[inline(always)]
unsafe fn run_block(
    avx2: bool,
    scaled: &[[[f64; 3]; 3]],
    conn: &[[u32; 4]],
    u: &[[f64; 3]],
    lambda: f64,
    mu: f64,
    shared: SharedOut,
) {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        return run_block_avx2(scaled, conn, u, lambda, mu, shared);
    }
    let _ = avx2;
    block_body(scaled, conn, u, lambda, mu, shared)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_block_avx2(
    scaled: &[[[f64; 3]; 3]],
    conn: &[[u32; 4]],
    u: &[[f64; 3]],
    lambda: f64,
    mu: f64,
    shared: SharedOut,
) {
    block_body(scaled, conn, u, lambda, mu, shared)
}

/// The loop of [`run_block`] (same safety contract).
#[inline(always)]
unsafe fn block_body(
    scaled: &[[[f64; 3]; 3]],
    conn: &[[u32; 4]],
    u: &[[f64; 3]],
    lambda: f64,
    mu: f64,
    shared: SharedOut,
) {
    for (g, &n) in scaled.iter().zip(conn) {
        let f = tet_force(g, n, u, lambda, mu);
        for a in 0..4 {
            shared.add(n[a] as usize, f[a]);
        }
    }
}

/// Nodal forces V σ ∇N_a of one constant-strain tet from its scaled gradients g̃ = √V ∇N_1..3
/// (the hot loop: no allocation).
#[inline(always)]
fn tet_force(
    g3: &[[f64; 3]; 3],
    n: [u32; 4],
    u: &[[f64; 3]],
    lambda: f64,
    mu: f64,
) -> [[f64; 3]; 4] {
    let g = [
        [
            -(g3[0][0] + g3[1][0] + g3[2][0]),
            -(g3[0][1] + g3[1][1] + g3[2][1]),
            -(g3[0][2] + g3[1][2] + g3[2][2]),
        ],
        g3[0],
        g3[1],
        g3[2],
    ];
    let mut h = [[0.0f64; 3]; 3];
    for a in 0..4 {
        let ua = u[n[a] as usize];
        for i in 0..3 {
            h[i][0] += ua[i] * g[a][0];
            h[i][1] += ua[i] * g[a][1];
            h[i][2] += ua[i] * g[a][2];
        }
    }
    let lv = lambda * (h[0][0] + h[1][1] + h[2][2]);
    let s00 = lv + 2.0 * mu * h[0][0];
    let s11 = lv + 2.0 * mu * h[1][1];
    let s22 = lv + 2.0 * mu * h[2][2];
    let s12 = mu * (h[1][2] + h[2][1]);
    let s02 = mu * (h[0][2] + h[2][0]);
    let s01 = mu * (h[0][1] + h[1][0]);
    g.map(|ga| {
        [
            s00 * ga[0] + s01 * ga[1] + s02 * ga[2],
            s01 * ga[0] + s11 * ga[1] + s12 * ga[2],
            s02 * ga[0] + s12 * ga[1] + s22 * ga[2],
        ]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_share_no_node_and_cover_every_item() {
        // Eight tets around one node plus a chain: greedy colouring must separate them.
        let mut conn = Vec::new();
        for k in 0..8u32 {
            conn.push([0, 1 + k, 2 + k, 3 + k]);
        }
        for k in 0..20u32 {
            conn.push([20 + k, 21 + k, 22 + k, 23 + k]);
        }
        let colour = greedy_colours(conn.len(), 60, |e| &conn[e][..]);
        assert_eq!(colour.len(), conn.len());
        for (a, ca) in colour.iter().enumerate() {
            for (b, cb) in colour.iter().enumerate().skip(a + 1) {
                if ca == cb {
                    assert!(conn[a].iter().all(|i| !conn[b].contains(i)));
                }
            }
        }
        // The eight around node 0 need eight colours.
        let mut first: Vec<u32> = colour[..8].to_vec();
        first.sort_unstable();
        first.dedup();
        assert_eq!(first.len(), 8);
    }

    /// A two-layer cartridge-size tube and a smooth displacement field on it.
    fn tube() -> (TetMesh, Vec<[f64; 3]>) {
        let mesh = crate::fem::AxisymmetricProfile::tube(4.7e-3, 5.8e-3, 20e-3)
            .unwrap()
            .tet_mesh(24, 2, 0.55e-3)
            .unwrap()
            .mesh;
        let u = mesh
            .nodes
            .iter()
            .map(|x| {
                [
                    1e-6 * x[2] + 3e-5 * x[0] * x[1],
                    -2e-6 * x[0],
                    3e-6 * x[1] * x[1],
                ]
            })
            .collect();
        (mesh, u)
    }

    #[test]
    fn forces_match_the_assembled_stiffness_and_do_not_depend_on_threads_or_avx2() {
        let (mesh, u) = tube();
        let (lambda, mu) = (30e9, 28e9);
        let mut kernel = TetForceKernel::new(&mesh, lambda, mu).unwrap();
        assert!(kernel.n_colours() >= 2, "{} colours", kernel.n_colours());
        let n = mesh.nodes.len();
        // Reference: the assembled element stiffnesses (the static solver's) times u.
        let mut reference = vec![[0.0f64; 3]; n];
        for (r, c, k) in
            crate::fem::assembly::stiffness_triplets(&mesh, kernel.tets(), lambda, mu, false)
        {
            reference[r / 3][r % 3] += k * u[c / 3][c % 3];
        }
        let scale = reference
            .iter()
            .flatten()
            .fold(0.0f64, |m, &x| m.max(x.abs()));
        let run = |threads: usize, kernel: &mut TetForceKernel| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut out = vec![[7.0; 3]; n];
            pool.install(|| kernel.apply(&u, &mut out));
            out
        };
        let one = run(1, &mut kernel);
        for (a, b) in one.iter().flatten().zip(reference.iter().flatten()) {
            assert!((a - b).abs() <= 1e-12 * scale, "{a} against {b}");
        }
        let bits = |f: &[[f64; 3]]| f.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&one), bits(&run(2, &mut kernel)));
        assert_eq!(bits(&one), bits(&run(3, &mut kernel)));
        if kernel.avx2 {
            let mut baseline = kernel.clone();
            baseline.avx2 = false;
            assert_eq!(bits(&one), bits(&run(2, &mut baseline)));
        }
    }

    #[test]
    fn more_than_64_colours_widen_the_sets() {
        let conn: Vec<[u32; 4]> = (0..70u32)
            .map(|k| [0, 1 + 3 * k, 2 + 3 * k, 3 + 3 * k])
            .collect();
        let colour = greedy_colours(conn.len(), 300, |e| &conn[e][..]);
        let expect: Vec<u32> = (0..70).collect();
        assert_eq!(colour, expect);
    }
}
