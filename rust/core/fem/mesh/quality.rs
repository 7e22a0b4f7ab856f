//! Element quality measures for tetrahedra: dihedral angles and the normalised aspect
//! ratio (longest edge over inradius, scaled so that a regular tetrahedron scores 1).

use super::{cross, dot, norm, signed_volume, sub};

/// Quality of one tetrahedron.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TetQuality {
    /// Smallest of the six dihedral angles, degrees (70.53° for a regular tet).
    pub min_dihedral_deg: f64,
    /// Largest of the six dihedral angles, degrees.
    pub max_dihedral_deg: f64,
    /// Longest edge / (2√6 · inradius); 1 for a regular tet, grows without bound for slivers.
    pub aspect_ratio: f64,
    /// Signed volume, m³.
    pub volume: f64,
}

/// Quality summary of a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshQuality {
    /// Number of elements measured.
    pub n_elements: usize,
    /// Smallest dihedral angle in the mesh, degrees.
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle in the mesh, degrees.
    pub max_dihedral_deg: f64,
    /// Largest normalised aspect ratio (1 = regular tet).
    pub max_aspect_ratio: f64,
    /// Mean normalised aspect ratio.
    pub mean_aspect_ratio: f64,
    /// Smallest element volume, m³.
    pub min_volume: f64,
    /// Index of the element with the smallest dihedral angle.
    pub worst_element: usize,
}

/// Dihedral angles and aspect ratio of the tetrahedron with vertices `x`.
pub fn tet_quality(x: [[f64; 3]; 4]) -> TetQuality {
    const EDGES: [(usize, usize, usize, usize); 6] = [
        (0, 1, 2, 3),
        (0, 2, 1, 3),
        (0, 3, 1, 2),
        (1, 2, 0, 3),
        (1, 3, 0, 2),
        (2, 3, 0, 1),
    ];
    let mut dmin = 180.0f64;
    let mut dmax = 0.0f64;
    let mut lmax = 0.0f64;
    for &(a, b, c, d) in &EDGES {
        let e = sub(x[b], x[a]);
        let le = norm(e);
        lmax = lmax.max(le);
        let en = [e[0] / le, e[1] / le, e[2] / le];
        let pc = sub(x[c], x[a]);
        let pd = sub(x[d], x[a]);
        let u = sub(
            pc,
            [
                en[0] * dot(pc, en),
                en[1] * dot(pc, en),
                en[2] * dot(pc, en),
            ],
        );
        let w = sub(
            pd,
            [
                en[0] * dot(pd, en),
                en[1] * dot(pd, en),
                en[2] * dot(pd, en),
            ],
        );
        let c = (dot(u, w) / (norm(u) * norm(w))).clamp(-1.0, 1.0);
        let ang = if c.is_finite() {
            c.acos().to_degrees()
        } else {
            0.0
        };
        dmin = dmin.min(ang);
        dmax = dmax.max(ang);
    }
    let v = signed_volume(x[0], x[1], x[2], x[3]);
    let area = |a: usize, b: usize, c: usize| 0.5 * norm(cross(sub(x[b], x[a]), sub(x[c], x[a])));
    let total_area = area(1, 2, 3) + area(0, 2, 3) + area(0, 1, 3) + area(0, 1, 2);
    let inradius = 3.0 * v.abs() / total_area;
    let aspect = if inradius > 0.0 {
        lmax / (2.0 * 6f64.sqrt() * inradius)
    } else {
        f64::INFINITY
    };
    TetQuality {
        min_dihedral_deg: dmin,
        max_dihedral_deg: dmax,
        aspect_ratio: aspect,
        volume: v,
    }
}

impl MeshQuality {
    /// Summarise the quality of every tetrahedron of a mesh.
    pub fn of_tets(nodes: &[[f64; 3]], tets: &[[usize; 4]]) -> Self {
        let mut q = MeshQuality {
            n_elements: tets.len(),
            min_dihedral_deg: 180.0,
            max_dihedral_deg: 0.0,
            max_aspect_ratio: 0.0,
            mean_aspect_ratio: 0.0,
            min_volume: f64::INFINITY,
            worst_element: 0,
        };
        let mut sum = 0.0;
        for (e, t) in tets.iter().enumerate() {
            let tq = tet_quality([nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]]);
            if tq.min_dihedral_deg < q.min_dihedral_deg {
                q.min_dihedral_deg = tq.min_dihedral_deg;
                q.worst_element = e;
            }
            q.max_dihedral_deg = q.max_dihedral_deg.max(tq.max_dihedral_deg);
            q.max_aspect_ratio = q.max_aspect_ratio.max(tq.aspect_ratio);
            q.min_volume = q.min_volume.min(tq.volume);
            sum += tq.aspect_ratio;
        }
        if !tets.is_empty() {
            q.mean_aspect_ratio = sum / tets.len() as f64;
        }
        q
    }
}
