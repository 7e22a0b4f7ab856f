//! Contact for the explicit solver: penalty node-to-surface contact between any number of
//! tetrahedral bodies, rigid surfaces (the belt plane, spheres, cylinders), Coulomb
//! friction, and no-tension springs to ghost points.
//!
//! **Normal.** Symmetric (two-pass): every surface node of every body is tested against the
//! faces of the other bodies, so neither side is master only. A node behind a face's plane
//! by d (0 < d ≤ half the height 3V/A of the element under the face, so a node outside a
//! thin wall is never caught by the faces of its far side) whose projection falls on the
//! face gets F = k_f d along the face's normal, k_f = s·K·A²/V (OpenRadioss TYPE7
//! `Istf = 0`, s the penalty scale, [`ContactSettings::penalty_scale`]); the face's nodes
//! take −F in the proportions of the projection's barycentric weights, so the pair's
//! forces sum to zero (linear momentum is conserved to round-off). Against a rigid surface
//! a node gets F = k_node d with k_node = Σ k_f/3 over its faces.
//!
//! **Shells.** [`FemContact::new_shell`] builds the model on a shell mesh: every triangle
//! is a two-sided face, its contact surfaces half its thickness from the mid-surface, and
//! the gap of a node is its signed distance less half its own and half the face's
//! thickness, on the side it met the face (see `narrow`); k_f = s·E·t (see
//! `shell_surface`). Rigid surfaces meet a shell node half its thickness early.
//!
//! **Tangential.** An elastic stick spring of the normal stiffness with a Coulomb cap: the
//! trial force f_t − k v_t Δt (v_t the relative tangential velocity of the node against the
//! face or the surface material) is returned to μ f_n when it exceeds it. The dissipated
//! work summed in [`ContactEnergy::friction_work`] is what closes each slipping step's
//! bookkeeping: the work the bodies did on the stick spring (the mean of the old and the
//! new force times the tangential travel, the trapezoidal rule the solvers use for work;
//! plus half the change of force times v_s Δt against a moving rigid surface, whose work is
//! counted with the new force) less the change of the spring's energy. For steady sliding
//! it is μ f_n times the slip; when f_n changes from step to step it differs from
//! μ f_n (|f_trial| − μ f_n)/k, which leaked 0.45 % of the energy in the shell cluster.
//!
//! **Broad phase.** [`broad_phase::BroadPhase`], a cell grid over the faces, rebuilt when a
//! node has moved half the travel margin.
//!
//! **Stable step.** The contact springs stiffen the system. With mass-normalised
//! coordinates, a spring k between a node and a face adds at most k (1/√m_s + 1/√m_f,min)²
//! to a Gershgorin row; [`FemContact::eigenvalue_allowance`] is that bound for the stiffest
//! face times [`ContactSettings::contacts_per_node`], plus the rigid and spring terms. The
//! solver certifies its step for λ_K + allowance, and every step checks the Gershgorin
//! bound of the springs actually active against the allowance: a run never goes past its
//! certified step silently.
//!
//! **Output.** Per pair of parties (bodies, then rigid surfaces) and per region of the
//! lower-numbered party: the resultant normal and tangential force on that party (as
//! Abaqus's CFNM/CFSM), the contact area (the tributary areas of the nodes in contact, half
//! of both sides for body pairs) and the largest penetration, sampled every
//! `output_interval` steps.

//!
//! **Layout.** One step ([`FemContact::compute`]) runs, in this order: the broad phase
//! (`broad_phase`) and the face geometry (`narrow`); the contacts of the step, narrow phase
//! and friction against bodies (`hits`, `narrow`, `friction`) and rigid surfaces (`rigid`);
//! their forces and the contact memory (`forces`); the step allowance check (`allowance`);
//! the output sample (`output`); the springs (`springs`); the work and energies (`energy`).
//! `state` saves and restores it all.

mod allowance;
mod broad_phase;
mod energy;
mod forces;
mod friction;
mod hits;
mod narrow;
mod output;
mod rigid;
mod shell_surface;
mod springs;
mod state;
mod surface;
mod vec3;

pub use broad_phase::BroadPhase;
pub use energy::ContactEnergy;
pub use output::ChannelSample;
pub use rigid::{RigidShape, RigidSurface};
pub use springs::NoTensionSpring;
pub use surface::{Surface, SurfaceFace};

use rayon::prelude::*;

use crate::error::{check_non_negative, check_positive, DemfemError, Result};
use crate::fem::material::LinearElastic;
use crate::fem::mesh::TetMesh;

use vec3::add;

/// Surface nodes per parallel work item (fixed, so results do not depend on the threads).
const NODE_CHUNK: usize = 512;
/// Steps after a contact within which a node may return to a face at any depth.
const RECENT_STEPS: u64 = 2;

/// Settings of the contact model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSettings {
    /// Penalty scale s in k_f = s·K·A²/V (> 0). OpenRadioss's default for TYPE7 is 1.
    pub penalty_scale: f64,
    /// Coulomb friction coefficient between bodies (≥ 0).
    pub friction: f64,
    /// Travel margin of the broad phase, m (`None`: half the mean surface edge).
    pub margin: Option<f64>,
    /// Contacts a node may carry at full stiffness within the certified step (≥ 1).
    pub contacts_per_node: f64,
    /// Penetration already present at the start that is accepted, m.
    pub initial_overlap_tolerance: f64,
    /// Record the contact output every this many steps (≥ 1).
    pub output_interval: usize,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            penalty_scale: 1.0,
            friction: 0.2,
            margin: None,
            contacts_per_node: 1.0,
            initial_overlap_tolerance: 1e-9,
            output_interval: 10,
        }
    }
}

impl ContactSettings {
    fn validate(&self) -> Result<()> {
        check_positive("penalty_scale", self.penalty_scale)?;
        check_non_negative("friction", self.friction)?;
        if let Some(m) = self.margin {
            check_positive("margin", m)?;
        }
        if !(self.contacts_per_node >= 1.0) || !self.contacts_per_node.is_finite() {
            return Err(DemfemError::invalid(
                "contacts_per_node",
                self.contacts_per_node,
                "finite and >= 1",
            ));
        }
        check_non_negative("initial_overlap_tolerance", self.initial_overlap_tolerance)?;
        if self.output_interval == 0 {
            return Err(DemfemError::invalid("output_interval", 0.0, ">= 1"));
        }
        Ok(())
    }
}

/// Contact between the bodies of one mesh and with rigid surfaces, plus ghost springs.
#[derive(Debug, Clone)]
pub struct FemContact {
    settings: ContactSettings,
    surface: Surface,
    broad: BroadPhase,
    reference: Vec<[f64; 3]>,
    n_bodies: usize,
    region: Vec<u32>,
    n_regions: usize,
    rigid: Vec<RigidSurface>,
    springs: Vec<NoTensionSpring>,
    // Per surface node: stick force against bodies, and against each rigid surface.
    stick: Vec<[f64; 3]>,
    stick_rigid: Vec<[f64; 3]>,
    last_face: Vec<u32>,
    last_contact: Vec<u64>,
    // Per surface node: the face of its last contact with a body, the depth the force used
    // there (penetration less offset), and the offset. A node that moves onto another face
    // of a faceted surface can be deeper behind the new face's plane than it was behind the
    // old one; taking the new depth at once would store energy the contact never received
    // as work (a kick). The offset keeps the force's depth continuous across the switch, so
    // the contact stays conservative; it only shrinks (as the node comes out), and it is
    // zero except after such a switch.
    contact_face: Vec<u32>,
    // Per surface node: the side (±1, along the face normal) of the shell face of its last
    // contact, decided at first contact and kept (always 1 for solids).
    side: Vec<f64>,
    last_depth: Vec<f64>,
    offset: Vec<f64>,
    x: Vec<[f64; 3]>,
    // Per face, this step: unit normal, area ×2 and a bounding sphere (see `narrow`).
    face_geom: Vec<narrow::FaceGeom>,
    f_prev: Vec<[f64; 3]>,
    u_prev: Vec<[f64; 3]>,
    normal_load: Vec<f64>,
    energy: ContactEnergy,
    history: Vec<f64>,
    sample: Vec<ChannelSample>,
    allowance: f64,
    mass: Vec<f64>,
    gershgorin: Vec<f64>,
    failure: Option<DemfemError>,
    steps: u64,
    active: usize,
    max_gershgorin: f64,
}

impl FemContact {
    /// Contact among the bodies of `mesh`: `body_of_node[i]` numbers the body of node i
    /// (0, 1, …), `region_of_node[i]` its output region (0, 1, …; e.g. top and bottom of a
    /// cartridge). `material` gives the bulk modulus of the penalty.
    pub fn new(
        mesh: &TetMesh,
        body_of_node: &[u32],
        region_of_node: &[u32],
        material: &LinearElastic,
        settings: ContactSettings,
    ) -> Result<Self> {
        settings.validate()?;
        material.validate()?;
        let n = mesh.nodes.len();
        if region_of_node.len() != n {
            return Err(DemfemError::ShapeMismatch {
                field: "region_of_node".into(),
                detail: format!("{} entries for {n} nodes", region_of_node.len()),
            });
        }
        let nu = material.poisson_ratio;
        let bulk = material.young_modulus / (3.0 * (1.0 - 2.0 * nu));
        let surface = Surface::new(mesh, body_of_node, bulk, settings.penalty_scale)?;
        Self::from_surface(surface, &mesh.nodes, body_of_node, region_of_node, settings)
    }

    /// The model on an extracted surface of a mesh with reference positions `nodes`.
    fn from_surface(
        surface: Surface,
        nodes: &[[f64; 3]],
        body_of_node: &[u32],
        region_of_node: &[u32],
        settings: ContactSettings,
    ) -> Result<Self> {
        let n = nodes.len();
        let n_bodies = body_of_node
            .iter()
            .map(|&b| b as usize + 1)
            .max()
            .unwrap_or(0);
        let n_regions = region_of_node
            .iter()
            .map(|&r| r as usize + 1)
            .max()
            .unwrap_or(1);
        if n_bodies > 4096 || n_regions > 64 {
            return Err(DemfemError::InvalidParameter {
                field: "body_of_node / region_of_node".into(),
                value: format!("{n_bodies} bodies, {n_regions} regions"),
                allowed: "at most 4096 bodies and 64 regions".into(),
            });
        }
        let margin = settings
            .margin
            .unwrap_or(0.5 * surface.mean_edge.max(1e-12));
        let ns = surface.nodes.len();
        Ok(Self {
            settings,
            broad: BroadPhase::new(margin),
            reference: nodes.to_vec(),
            n_bodies,
            region: region_of_node.to_vec(),
            n_regions,
            rigid: Vec::new(),
            springs: Vec::new(),
            stick: vec![[0.0; 3]; ns],
            stick_rigid: Vec::new(),
            last_face: vec![u32::MAX; ns],
            last_contact: vec![u64::MAX; ns],
            contact_face: vec![u32::MAX; ns],
            side: vec![1.0; ns],
            last_depth: vec![0.0; ns],
            offset: vec![0.0; ns],
            x: vec![[0.0; 3]; n],
            face_geom: Vec::new(),
            f_prev: vec![[0.0; 3]; n],
            u_prev: vec![[0.0; 3]; n],
            normal_load: vec![0.0; ns],
            energy: ContactEnergy::default(),
            history: Vec::new(),
            sample: Vec::new(),
            allowance: 0.0,
            mass: Vec::new(),
            gershgorin: vec![0.0; n],
            failure: None,
            steps: 0,
            active: 0,
            max_gershgorin: 0.0,
            surface,
        })
    }

    /// Add a rigid surface; returns its party index (bodies come first).
    pub fn add_rigid(&mut self, surface: RigidSurface) -> Result<usize> {
        let s = surface.validated()?;
        self.rigid.push(s);
        self.stick_rigid = vec![[0.0; 3]; self.surface.nodes.len() * self.rigid.len()];
        Ok(self.n_bodies + self.rigid.len() - 1)
    }

    /// Add no-tension springs to ghost points.
    pub fn add_springs(&mut self, springs: &[NoTensionSpring]) -> Result<()> {
        for s in springs {
            s.validate(self.reference.len())?;
        }
        self.springs.extend_from_slice(springs);
        Ok(())
    }

    /// The extracted contact surface.
    pub fn surface(&self) -> &Surface {
        &self.surface
    }
    /// Contact energies so far.
    pub fn energy(&self) -> ContactEnergy {
        self.energy
    }
    /// Broad-phase rebuilds so far.
    pub fn broad_phase_builds(&self) -> u64 {
        self.broad.builds
    }
    /// Contacts active in the last step.
    pub fn active_contacts(&self) -> usize {
        self.active
    }

    /// Error for bodies that overlap at the start by more than the tolerance.
    pub fn check_initial_overlap(&mut self, u: &[[f64; 3]]) -> Result<()> {
        self.update_positions(u);
        self.broad.rebuild(&self.surface, &self.x, u);
        self.update_face_geometry();
        let tol = self.settings.initial_overlap_tolerance;
        for k in 0..self.surface.nodes.len() {
            // At the start the whole element's height counts, to catch overlaps.
            if let Some((f, d, _, _, _)) = self.closest_face(k, 1.0) {
                if d > tol {
                    let face = &self.surface.faces[f];
                    return Err(DemfemError::InvalidParameter {
                        field: "initial positions".into(),
                        value: format!(
                            "body {} overlaps body {} by {d:e} m at node {}",
                            self.surface.node_body[k], face.body, self.surface.nodes[k]
                        ),
                        allowed: format!("overlap at most {tol:e} m"),
                    });
                }
            }
            let i = self.surface.nodes[k];
            for (r, s) in self.rigid.iter().enumerate() {
                let hn = self.surface.node_half_thickness[k];
                if let Some((d, _, _)) = s.probe_offset(self.x[i], 0.0, hn) {
                    if d > tol {
                        return Err(DemfemError::InvalidParameter {
                            field: "initial positions".into(),
                            value: format!(
                                "body {} penetrates rigid surface {r} by {d:e} m at node {i}",
                                self.surface.node_body[k]
                            ),
                            allowed: format!("penetration at most {tol:e} m"),
                        });
                    }
                }
            }
        }
        Ok(())
    }

    /// Current positions x = X + u of every node (only surface and spring nodes are read).
    fn update_positions(&mut self, u: &[[f64; 3]]) {
        self.x
            .par_chunks_mut(NODE_CHUNK)
            .zip(self.reference.par_chunks(NODE_CHUNK))
            .zip(u.par_chunks(NODE_CHUNK))
            .for_each(|((x, r), u)| {
                for ((x, r), u) in x.iter_mut().zip(r).zip(u) {
                    *x = add(*r, *u);
                }
            });
    }

    /// Contact and spring forces (N, added into `force`, one per node) at displacement `u`
    /// (m) and velocity `v` (m/s) at time `t` (s), for a step `dt` (s). A contact that runs
    /// away or springs that exceed the certified allowance are kept for [`Self::take_failure`].
    pub fn compute(
        &mut self,
        u: &[[f64; 3]],
        v: &[[f64; 3]],
        t: f64,
        dt: f64,
        force: &mut [[f64; 3]],
    ) {
        self.update_positions(u);
        if self.broad.needs_rebuild(&self.surface, u) {
            self.broad.rebuild(&self.surface, &self.x, u);
        }
        self.update_face_geometry();
        let hits = self.find_hits(v, t, dt);
        let (new_last, elastic) = self.apply_hits(&hits, force);
        let check = !self.mass.is_empty();
        if check {
            self.gershgorin_of_hits(&hits);
        }
        let record = self.steps % self.settings.output_interval as u64 == 0;
        let sample = record.then(|| self.sample_hits(&hits));
        self.check_runaway(&new_last, t);
        self.last_face = new_last;
        let spring_energy = self.spring_forces(force, check);
        if check {
            self.check_allowance(t);
        }
        self.account_work(u, force);
        self.energy.elastic = elastic;
        self.energy.springs = spring_energy;
        self.active = hits.len();
        if let Some((sums, chan)) = sample {
            self.record_sample(t, &sums, chan);
        }
        self.steps += 1;
    }

    /// The failure found by the last steps, if any (a runaway contact or an exceeded
    /// allowance); taking it clears it.
    pub fn take_failure(&mut self) -> Option<DemfemError> {
        self.failure.take()
    }
}
