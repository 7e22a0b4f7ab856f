//! Linear tetrahedra as an [`ElementSet`] of the explicit integrator (3 translations per
//! node, m): internal forces from the coloured kernel [`TetForceKernel`], lumped masses
//! ρV/4 per node with optional mass scaling, and the step bound of [`StepBound`] (the
//! element eigenvalue bound, or the certified global one). Slivers are refused first: their
//! stable step would be orders of magnitude below their neighbours'.

use crate::error::{DemfemError, Result};
use crate::fem::assembly::lumped_mass;
use crate::fem::element_set::{Clock, ElementSet, LumpedMass};
use crate::fem::material::LinearElastic;
use crate::fem::mesh::{tet_quality, TetMesh};
use crate::fem::reduce::NODE_CHUNK;
use crate::fem::stable_step::{
    certified_eigenvalue_bound, mass_scaling_factors, EigenvalueBound, StepBound,
};
use crate::fem::tet_forces::TetForceKernel;

/// Smallest dihedral angle, degrees, of an element the explicit solver accepts: a sliver
/// below it has a critical step orders of magnitude below its neighbours' (1e-16 s for a
/// flattened tet) and would make the whole run take forever.
pub const MIN_ELEMENT_DIHEDRAL_DEG: f64 = 0.5;

/// Smallest element volume the explicit solver accepts, as a fraction of the mean.
pub const MIN_ELEMENT_VOLUME_FRACTION: f64 = 1e-12;

/// Refuse sliver elements (a dihedral angle below [`MIN_ELEMENT_DIHEDRAL_DEG`]) and
/// near-degenerate ones (volume below [`MIN_ELEMENT_VOLUME_FRACTION`] × the mean), naming
/// the element. Inverted elements and bad indices are left to [`TetMesh::validate`].
fn check_element_shapes(mesh: &TetMesh) -> Result<()> {
    mesh.validate()?;
    let mean = mesh.volume() / mesh.tets.len() as f64;
    for (e, t) in mesh.tets.iter().enumerate() {
        let q = tet_quality(t.map(|i| mesh.nodes[i]));
        if !(q.min_dihedral_deg >= MIN_ELEMENT_DIHEDRAL_DEG) {
            return Err(DemfemError::InvalidParameter {
                field: "mesh".into(),
                value: format!(
                    "element {e} is a sliver: min dihedral angle {:.3e}°",
                    q.min_dihedral_deg
                ),
                allowed: format!(
                    "elements with every dihedral angle >= {MIN_ELEMENT_DIHEDRAL_DEG}° \
                     (a sliver's stable step is far below its neighbours')"
                ),
            });
        }
        if !(q.volume >= MIN_ELEMENT_VOLUME_FRACTION * mean) {
            return Err(DemfemError::InvalidParameter {
                field: "mesh".into(),
                value: format!(
                    "element {e} has volume {:e} m³ (mean {mean:e} m³)",
                    q.volume
                ),
                allowed: format!(
                    "elements of volume >= {MIN_ELEMENT_VOLUME_FRACTION:e} × the mean"
                ),
            });
        }
    }
    Ok(())
}

/// The tetrahedra of a mesh with their material and mass scaling.
#[derive(Debug, Clone)]
pub struct TetElements {
    mesh: TetMesh,
    material: LinearElastic,
    kernel: TetForceKernel,
    mass_factor: Option<Vec<f64>>,
    added_mass: f64,
}

impl TetElements {
    /// Check the mesh (validity, no slivers) and precompute the elements; with
    /// `mass_scaling_dt` (s), raise element masses so that every element's own stable step
    /// is at least that.
    pub fn new(
        mesh: &TetMesh,
        material: LinearElastic,
        mass_scaling_dt: Option<f64>,
    ) -> Result<Self> {
        check_element_shapes(mesh)?;
        let (lambda, mu) = material.lame();
        let kernel = TetForceKernel::new(mesh, lambda, mu)?;
        let (mass_factor, added_mass) = match mass_scaling_dt {
            Some(target) => {
                let (f, a) =
                    mass_scaling_factors(kernel.tets(), lambda, mu, material.density, target)?;
                (Some(f), a)
            }
            None => (None, 0.0),
        };
        Ok(Self {
            mesh: mesh.clone(),
            material,
            kernel,
            mass_factor,
            added_mass,
        })
    }

    /// Mass added by mass scaling, kg.
    pub fn added_mass(&self) -> f64 {
        self.added_mass
    }

    /// The element-force kernel (for K·x products, e.g. eigenvalue estimates).
    pub fn kernel_mut(&mut self) -> &mut TetForceKernel {
        &mut self.kernel
    }
}

impl ElementSet<3> for TetElements {
    const NAME: &'static str = "tet";
    const CLOCK: Clock = Clock::Summed;
    const NODE_CHUNK: usize = NODE_CHUNK;
    const SHELL: bool = false;

    fn n_nodes(&self) -> usize {
        self.mesh.nodes.len()
    }

    fn lumped_mass(&self) -> Result<LumpedMass> {
        Ok(LumpedMass {
            translation: lumped_mass(
                &self.mesh,
                self.kernel.tets(),
                self.material.density,
                self.mass_factor.as_deref(),
            )?,
            rotation: Vec::new(),
        })
    }

    fn eigenvalue_bound(&mut self, mass: &LumpedMass, how: StepBound) -> Result<EigenvalueBound> {
        certified_eigenvalue_bound(
            &self.mesh,
            &mut self.kernel,
            &mass.translation,
            &self.material,
            self.mass_factor.as_deref(),
            how,
        )
    }

    #[inline]
    fn internal_forces(&mut self, u: &[[f64; 3]], f: &mut [[f64; 3]]) {
        self.kernel.apply(u, f);
    }

    #[inline]
    fn translations<'a>(u: &'a [[f64; 3]], _scratch: &'a mut Vec<[f64; 3]>) -> &'a [[f64; 3]] {
        u
    }
}
