//! Structured meshes: the cartridge revolved about its axis (tets through the wall,
//! triangles on the mid-surface) and a structured box (verification problems).

use super::{signed_volume, TetMesh, TriMesh};
use crate::error::{check_positive, DemfemError, Result};

/// Default largest element count of [`AxisymmetricProfile::tet_mesh`]: beyond it a mesh is
/// refused before meshing (5e6 linear tets is already several GB with the solver's arrays).
pub const MAX_TET_ELEMENTS: usize = 5_000_000;

/// Axisymmetric description of a hollow body of revolution about the z axis: at height
/// `z[k]` the material is the annulus `r_in[k] <= r <= r_out[k]`; radii vary linearly
/// between stations. Both ends are open. All lengths in metres.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisymmetricProfile {
    /// Axial stations, m, strictly increasing.
    pub z: Vec<f64>,
    /// Inner radius at each station, m, > 0.
    pub r_in: Vec<f64>,
    /// Outer radius at each station, m, > `r_in`.
    pub r_out: Vec<f64>,
}

/// Result of [`AxisymmetricProfile::tet_mesh`]: the mesh and its structured grid sizes,
/// so callers can address nodes by (θ index, layer, axial station).
#[derive(Debug, Clone, PartialEq)]
pub struct RevolvedTetMesh {
    /// The tetrahedral mesh.
    pub mesh: TetMesh,
    /// Divisions around the circumference.
    pub n_theta: usize,
    /// Element layers through the wall (node layers = `n_layers + 1`, layer 0 is the inner surface).
    pub n_layers: usize,
    /// Axial coordinates of the node rings, m (one entry per axial node station).
    pub z_stations: Vec<f64>,
}

impl RevolvedTetMesh {
    /// Node index of θ division `i` (mod `n_theta`), node layer `j` (0 = inner surface)
    /// and axial station `k`.
    pub fn node_index(&self, i: usize, j: usize, k: usize) -> usize {
        k * self.n_theta * (self.n_layers + 1) + j * self.n_theta + (i % self.n_theta)
    }
}

impl AxisymmetricProfile {
    /// A checked profile (see the struct docs for the rules).
    pub fn new(z: Vec<f64>, r_in: Vec<f64>, r_out: Vec<f64>) -> Result<Self> {
        let p = Self { z, r_in, r_out };
        p.validate()?;
        Ok(p)
    }

    /// The default 3 mL cartridge of the brief (body OD 11.6 mm, wall 1.1 mm, conical
    /// shoulder, neck and crimp flange, 64 mm long).
    pub fn default_cartridge() -> Self {
        let mm = 1e-3;
        Self {
            z: [0.0, 54.5, 58.5, 61.0, 61.3, 64.0]
                .iter()
                .map(|v| v * mm)
                .collect(),
            r_in: [4.7, 4.7, 1.9, 1.9, 1.9, 1.9]
                .iter()
                .map(|v| v * mm)
                .collect(),
            r_out: [5.8, 5.8, 3.0, 3.0, 3.65, 3.65]
                .iter()
                .map(|v| v * mm)
                .collect(),
        }
    }

    /// A straight tube of inner radius `r_in`, outer radius `r_out` and length `length`, m.
    pub fn tube(r_in: f64, r_out: f64, length: f64) -> Result<Self> {
        Self::new(vec![0.0, length], vec![r_in, r_in], vec![r_out, r_out])
    }

    /// Check array lengths, monotonic stations and 0 < r_in < r_out.
    pub fn validate(&self) -> Result<()> {
        let n = self.z.len();
        if n < 2 || self.r_in.len() != n || self.r_out.len() != n {
            return Err(DemfemError::ShapeMismatch {
                field: "profile".into(),
                detail: format!(
                    "z, r_in, r_out need equal lengths >= 2, got {}, {}, {}",
                    n,
                    self.r_in.len(),
                    self.r_out.len()
                ),
            });
        }
        for k in 0..n {
            if !self.z[k].is_finite() {
                return Err(DemfemError::invalid("z", self.z[k], "finite"));
            }
            check_positive("r_in", self.r_in[k])?;
            if !(self.r_out[k] > self.r_in[k]) || !self.r_out[k].is_finite() {
                return Err(DemfemError::invalid(
                    "r_out",
                    self.r_out[k],
                    "finite and > r_in at the same station",
                ));
            }
            if k > 0 && !(self.z[k] > self.z[k - 1]) {
                return Err(DemfemError::invalid("z", self.z[k], "strictly increasing"));
            }
        }
        Ok(())
    }

    /// Axial node stations: each profile segment is divided into
    /// `max(1, ceil(length / target_size))` equal parts, so every profile station is a node ring.
    fn axial_stations(&self, target_size: f64) -> Vec<(f64, f64, f64)> {
        let mut out = vec![(self.z[0], self.r_in[0], self.r_out[0])];
        for s in 0..self.z.len() - 1 {
            let len = self.z[s + 1] - self.z[s];
            let n = ((len / target_size).ceil() as usize).max(1);
            for q in 1..=n {
                let t = q as f64 / n as f64;
                let lerp = |a: &[f64]| a[s] + t * (a[s + 1] - a[s]);
                out.push((lerp(&self.z), lerp(&self.r_in), lerp(&self.r_out)));
            }
        }
        out
    }

    /// Structured revolved mesh of linear tetrahedra: `n_theta` divisions around,
    /// `n_layers` through the wall, axial divisions from `target_size` (m). Each hexahedral
    /// cell is split into six tets (Kuhn subdivision), giving a conforming mesh.
    /// Fails for `n_theta < 3`, `n_layers < 1`, a non-positive size, or inverted cells.
    ///
    /// Meshes estimated above [`MAX_TET_ELEMENTS`] elements are refused before any memory
    /// is allocated (see [`AxisymmetricProfile::tet_mesh_limited`]).
    pub fn tet_mesh(
        &self,
        n_theta: usize,
        n_layers: usize,
        target_size: f64,
    ) -> Result<RevolvedTetMesh> {
        self.tet_mesh_limited(n_theta, n_layers, target_size, MAX_TET_ELEMENTS)
    }

    /// Number of elements [`AxisymmetricProfile::tet_mesh`] would make (6 per hexahedral
    /// cell), computed without meshing, as a float so that no size overflows.
    pub fn tet_mesh_element_count(&self, n_theta: usize, n_layers: usize, target_size: f64) -> f64 {
        let axial: f64 = self
            .z
            .windows(2)
            .map(|w| ((w[1] - w[0]) / target_size).ceil().max(1.0))
            .sum();
        axial * n_layers as f64 * n_theta as f64 * 6.0
    }

    /// [`AxisymmetricProfile::tet_mesh`] refusing, before meshing, a mesh of more than
    /// `max_elements` elements (the error names `target_size`, the estimated count and the
    /// limit), so a tiny target size fails at once instead of exhausting memory.
    pub fn tet_mesh_limited(
        &self,
        n_theta: usize,
        n_layers: usize,
        target_size: f64,
        max_elements: usize,
    ) -> Result<RevolvedTetMesh> {
        self.validate()?;
        check_positive("target_size", target_size)?;
        if n_theta < 3 {
            return Err(DemfemError::invalid("n_theta", n_theta as f64, ">= 3"));
        }
        if n_layers < 1 {
            return Err(DemfemError::invalid("n_layers", n_layers as f64, ">= 1"));
        }
        let estimate = self.tet_mesh_element_count(n_theta, n_layers, target_size);
        if !(estimate <= max_elements as f64) {
            let length = self.z[self.z.len() - 1] - self.z[0];
            return Err(DemfemError::InvalidParameter {
                field: "target_size".into(),
                value: format!(
                    "{target_size:e} m (with n_theta = {n_theta}, n_layers = {n_layers}: \
                     about {estimate:.3e} elements)"
                ),
                allowed: format!(
                    "large enough for at most max_elements = {max_elements} elements \
                     (over the {length:e} m length, >= about {:.3e} m here)",
                    target_size * estimate / max_elements as f64
                ),
            });
        }
        let stations = self.axial_stations(target_size);
        let nj = n_layers + 1;
        let mut nodes = Vec::with_capacity(stations.len() * nj * n_theta);
        for &(z, ri, ro) in &stations {
            for j in 0..nj {
                let r = ri + (ro - ri) * j as f64 / n_layers as f64;
                for i in 0..n_theta {
                    let th = 2.0 * std::f64::consts::PI * i as f64 / n_theta as f64;
                    nodes.push([r * th.cos(), r * th.sin(), z]);
                }
            }
        }
        let idx = |i: usize, j: usize, k: usize| k * n_theta * nj + j * n_theta + (i % n_theta);
        let mut tets = Vec::with_capacity((stations.len() - 1) * n_layers * n_theta * 6);
        for k in 0..stations.len() - 1 {
            for j in 0..n_layers {
                for i in 0..n_theta {
                    let corner = |c: [usize; 3]| idx(i + c[0], j + c[1], k + c[2]);
                    kuhn_split(&corner, &nodes, &mut tets)?;
                }
            }
        }
        let mesh = TetMesh { nodes, tets };
        mesh.validate()?;
        Ok(RevolvedTetMesh {
            mesh,
            n_theta,
            n_layers,
            z_stations: stations.iter().map(|s| s.0).collect(),
        })
    }

    /// Mid-surface shell mesh of flat triangles: nodes on r_mid = (r_in + r_out)/2,
    /// `n_theta` divisions around, axial divisions from `target_size` (m); each triangle
    /// carries the normal wall thickness (r_out − r_in)·cos(slope) at its mid-height,
    /// slope being the inclination of the mid-surface meridian to the axis.
    pub fn shell_mesh(&self, n_theta: usize, target_size: f64) -> Result<TriMesh> {
        self.validate()?;
        check_positive("target_size", target_size)?;
        if n_theta < 3 {
            return Err(DemfemError::invalid("n_theta", n_theta as f64, ">= 3"));
        }
        let stations = self.axial_stations(target_size);
        let mut nodes = Vec::with_capacity(stations.len() * n_theta);
        for &(z, ri, ro) in &stations {
            let r = 0.5 * (ri + ro);
            for i in 0..n_theta {
                let th = 2.0 * std::f64::consts::PI * i as f64 / n_theta as f64;
                nodes.push([r * th.cos(), r * th.sin(), z]);
            }
        }
        let idx = |i: usize, k: usize| k * n_theta + (i % n_theta);
        let mut triangles = Vec::new();
        let mut thickness = Vec::new();
        for k in 0..stations.len() - 1 {
            let (z0, ri0, ro0) = stations[k];
            let (z1, ri1, ro1) = stations[k + 1];
            let dr_mid = 0.5 * (ri1 + ro1) - 0.5 * (ri0 + ro0);
            let cos_slope = (z1 - z0) / ((z1 - z0).powi(2) + dr_mid.powi(2)).sqrt();
            let t = 0.5 * ((ro0 - ri0) + (ro1 - ri1)) * cos_slope;
            for i in 0..n_theta {
                // Alternate the diagonal so the mesh has no preferred helical direction.
                let (a, b, c, d) = (idx(i, k), idx(i + 1, k), idx(i + 1, k + 1), idx(i, k + 1));
                if (i + k) % 2 == 0 {
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                } else {
                    triangles.push([a, b, d]);
                    triangles.push([b, c, d]);
                }
                thickness.push(t);
                thickness.push(t);
            }
        }
        let m = TriMesh {
            nodes,
            triangles,
            thickness,
        };
        m.validate()?;
        Ok(m)
    }
}

/// Split one structured hexahedral cell into six positively oriented tetrahedra along its
/// (0,0,0)–(1,1,1) index diagonal. `corner` maps an index offset to a node index.
fn kuhn_split(
    corner: &dyn Fn([usize; 3]) -> usize,
    nodes: &[[f64; 3]],
    tets: &mut Vec<[usize; 4]>,
) -> Result<()> {
    const PERMS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    for p in PERMS {
        let mut c = [0usize; 3];
        let mut t = [corner(c); 4];
        for (q, &axis) in p.iter().enumerate() {
            c[axis] = 1;
            t[q + 1] = corner(c);
        }
        let v = signed_volume(nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]);
        if v < 0.0 {
            t.swap(2, 3);
        } else if v == 0.0 || !v.is_finite() {
            return Err(DemfemError::Numerical(format!(
                "degenerate cell while meshing (tet volume {v:e} m³)"
            )));
        }
        tets.push(t);
    }
    Ok(())
}

/// Structured box mesh [0, lx]×[0, ly]×[0, lz] (m) with `nx`×`ny`×`nz` cells, each split
/// into six tets. Node (i, j, k) has index `(k·(ny+1) + j)·(nx+1) + i`.
pub fn box_tet_mesh(lx: f64, ly: f64, lz: f64, nx: usize, ny: usize, nz: usize) -> Result<TetMesh> {
    check_positive("lx", lx)?;
    check_positive("ly", ly)?;
    check_positive("lz", lz)?;
    if nx == 0 || ny == 0 || nz == 0 {
        return Err(DemfemError::invalid(
            "nx*ny*nz",
            (nx * ny * nz) as f64,
            "every division >= 1",
        ));
    }
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                nodes.push([
                    lx * i as f64 / nx as f64,
                    ly * j as f64 / ny as f64,
                    lz * k as f64 / nz as f64,
                ]);
            }
        }
    }
    let idx = |i: usize, j: usize, k: usize| (k * (ny + 1) + j) * (nx + 1) + i;
    let mut tets = Vec::with_capacity(nx * ny * nz * 6);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let corner = |c: [usize; 3]| idx(i + c[0], j + c[1], k + c[2]);
                kuhn_split(&corner, &nodes, &mut tets)?;
            }
        }
    }
    let mesh = TetMesh { nodes, tets };
    mesh.validate()?;
    Ok(mesh)
}
