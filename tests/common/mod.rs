//! Helpers shared by the integration tests.
#![allow(dead_code)]

use demfem::fem::mesh::TriMesh;

/// Structured triangulation of the map (s, t) ∈ [0,1]² → `f(s, t)`, `n`×`m` cells, each
/// cut by alternating diagonals. Node (i, j) has index j·(n+1) + i.
pub fn grid(n: usize, m: usize, h: f64, f: impl Fn(f64, f64) -> [f64; 3]) -> TriMesh {
    let mut nodes = Vec::new();
    for j in 0..=m {
        for i in 0..=n {
            nodes.push(f(i as f64 / n as f64, j as f64 / m as f64));
        }
    }
    let triangles = alternating_triangles(n, m, |i, j| j * (n + 1) + i);
    let thickness = vec![h; triangles.len()];
    TriMesh {
        nodes,
        triangles,
        thickness,
    }
}

/// Two triangles per cell of an `n`×`m` grid of cells, cut by alternating diagonals; `id(i, j)`
/// numbers the node at column i, row j (i up to n, j up to m; a closed tube wraps i).
pub fn alternating_triangles(
    n: usize,
    m: usize,
    id: impl Fn(usize, usize) -> usize,
) -> Vec<[usize; 3]> {
    let mut triangles = Vec::new();
    for j in 0..m {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            } else {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            }
        }
    }
    triangles
}
