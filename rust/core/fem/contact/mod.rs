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
//! **Shells.** [`ContactModel::new_shell`] builds the model on a shell mesh: every triangle
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
//! to a Gershgorin row; [`ContactModel::eigenvalue_allowance`] is that bound for the stiffest
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

mod broad_phase;
mod friction;
mod narrow;
mod rigid;
mod shell_surface;
mod springs;
mod state;
mod surface;
mod vec3;

pub use broad_phase::BroadPhase;
pub use rigid::{RigidShape, RigidSurface};
pub use springs::NoTensionSpring;
pub use surface::{Surface, SurfaceFace};

use rayon::prelude::*;

use crate::error::{check_non_negative, check_positive, DemfemError, Result};
use crate::fem::material::LinearElastic;
use crate::fem::mesh::TetMesh;

use friction::friction_update;
use vec3::{add, dot, norm, scale, sub};

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

/// Energies of the contact model, J.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactEnergy {
    /// Elastic energy now stored in the normal and stick springs, J.
    pub elastic: f64,
    /// Energy now stored in the no-tension springs, J.
    pub springs: f64,
    /// Work dissipated by friction slip so far, J.
    pub friction_work: f64,
    /// Work done on the bodies by the moving rigid surfaces through contact so far, J.
    pub rigid_work: f64,
    /// Work done by all contact and spring forces on the nodes so far (trapezoidal rule in
    /// displacement, as the solver counts external work), J.
    pub contact_work: f64,
}

impl ContactEnergy {
    /// Closure of the contact bookkeeping: contact_work + rigid_work... rearranged as
    /// |W_c + E_el + E_springs + W_fric − W_rigid| (0 for exact time integration), J.
    pub fn bookkeeping_error(&self) -> f64 {
        (self.contact_work + self.elastic + self.springs + self.friction_work - self.rigid_work)
            .abs()
    }
}

/// One contact found in a step (internal).
#[derive(Debug, Clone, Copy)]
struct Hit {
    slave: u32,
    /// Face index, or the index of the rigid surface when `rigid`.
    partner: u32,
    rigid: bool,
    weights: [f64; 3],
    normal_force: [f64; 3],
    tangential_force: [f64; 3],
    stiffness: f64,
    penetration: f64,
    /// Depth subtracted from `penetration` in the force (see `ContactModel::offset`), m.
    offset: f64,
    /// Side of a shell face (±1; 1 for solids and rigid surfaces).
    side: f64,
    elastic: f64,
    dissipated: f64,
    rigid_work: f64,
}

/// Contact output of one channel at one sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ChannelSample {
    /// |Σ normal force on the lower-numbered party|, N.
    pub normal_force: f64,
    /// |Σ tangential force on the lower-numbered party|, N.
    pub tangential_force: f64,
    /// Contact area, m².
    pub area: f64,
    /// Largest penetration, m.
    pub max_penetration: f64,
}

/// Contact between the bodies of one mesh and with rigid surfaces, plus ghost springs.
#[derive(Debug, Clone)]
pub struct ContactModel {
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

fn pair_index(a: usize, b: usize, parties: usize) -> usize {
    // a < b; row-major upper triangle.
    a * parties - a * (a + 1) / 2 + (b - a - 1)
}

impl ContactModel {
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
        let bulk = material.youngs_modulus / (3.0 * (1.0 - 2.0 * nu));
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

    /// Number of parties (bodies then rigid surfaces).
    pub fn parties(&self) -> usize {
        self.n_bodies + self.rigid.len()
    }
    /// Number of output regions.
    pub fn regions(&self) -> usize {
        self.n_regions
    }
    /// Output channels: (party a, party b, region of a) with a < b, in output order.
    pub fn channels(&self) -> Vec<(usize, usize, usize)> {
        let p = self.parties();
        let mut out = Vec::new();
        for a in 0..p {
            for b in a + 1..p {
                for r in 0..self.n_regions {
                    out.push((a, b, r));
                }
            }
        }
        out
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
    /// Largest Gershgorin bound of the active contact springs seen so far, 1/s².
    pub fn max_contact_eigenvalue(&self) -> f64 {
        self.max_gershgorin
    }
    /// The eigenvalue allowance certified into the step, 1/s².
    pub fn allowance(&self) -> f64 {
        self.allowance
    }

    /// Recorded output: rows of `1 + 4 × channels` values (time, then normal force, tangential
    /// force, area, largest penetration per channel).
    pub fn history(&self) -> &[f64] {
        &self.history
    }

    /// Contact pressure of each mesh node in the last step (normal force it carries over its
    /// tributary area), Pa; 0 off the surface.
    pub fn pressure(&self) -> Vec<f64> {
        let mut p = vec![0.0; self.reference.len()];
        for (k, &i) in self.surface.nodes.iter().enumerate() {
            p[i] = self.normal_load[k] / self.surface.node_area[k];
        }
        p
    }

    /// Bound on the contact's contribution to λ_max(M⁻¹K) for nodal masses `mass` (kg),
    /// 1/s²; also fixes the masses for the per-step check.
    pub fn eigenvalue_allowance(&mut self, mass: &[f64]) -> Result<f64> {
        if mass.len() != self.reference.len() {
            return Err(DemfemError::ShapeMismatch {
                field: "mass".into(),
                detail: format!("{} entries for {} nodes", mass.len(), self.reference.len()),
            });
        }
        let sf = &self.surface;
        // Lightest surface node of each body (the slaves a face can meet).
        let mut min_mass = vec![f64::INFINITY; self.n_bodies];
        for (k, &i) in sf.nodes.iter().enumerate() {
            let b = sf.node_body[k] as usize;
            min_mass[b] = min_mass[b].min(mass[i]);
        }
        let mut face_term: f64 = 0.0;
        for f in &sf.faces {
            let mf = f
                .nodes
                .iter()
                .map(|&i| mass[i])
                .fold(f64::INFINITY, f64::min);
            let ms = (0..self.n_bodies)
                .filter(|&b| b != f.body as usize)
                .map(|b| min_mass[b])
                .fold(f64::INFINITY, f64::min);
            if ms.is_finite() {
                let q = 1.0 / ms.sqrt() + 1.0 / mf.sqrt();
                face_term = face_term.max(f.stiffness * q * q);
            }
        }
        let mut rigid_term: f64 = 0.0;
        if !self.rigid.is_empty() {
            for (k, &i) in sf.nodes.iter().enumerate() {
                rigid_term = rigid_term.max(sf.node_stiffness[k] / mass[i]);
            }
            rigid_term *= self.rigid.len().min(2) as f64;
        }
        let mut spring_row = vec![0.0; mass.len()];
        for s in &self.springs {
            spring_row[s.node] += s.stiffness / mass[s.node];
        }
        let spring_term = spring_row.iter().fold(0.0f64, |a, &b| a.max(b));
        // A shell node is a slave and, at a ridge met head-on, the corner its own faces give
        // weight 1 to another body's slave: two full-stiffness springs per node.
        let face_term = if self.is_shell() {
            2.0 * face_term
        } else {
            face_term
        };
        let allowance = self.settings.contacts_per_node * face_term + rigid_term + spring_term;
        if !allowance.is_finite() {
            return Err(DemfemError::Numerical(
                "contact step allowance is not finite (a node of zero mass on the surface?)".into(),
            ));
        }
        self.allowance = allowance;
        self.mass = mass.to_vec();
        Ok(allowance)
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

    /// The velocity (m/s) of the point of `face` with barycentric weights `w`.
    fn face_velocity(&self, face: &SurfaceFace, w: [f64; 3], v: &[[f64; 3]]) -> [f64; 3] {
        add(
            add(scale(v[face.nodes[0]], w[0]), scale(v[face.nodes[1]], w[1])),
            scale(v[face.nodes[2]], w[2]),
        )
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
        let ns = self.surface.nodes.len();
        let nr = self.rigid.len();
        let mu = self.settings.friction;
        // Narrow phase and friction, in parallel over fixed chunks of surface nodes.
        let hits: Vec<Hit> = {
            let this = &*self;
            let stick = &this.stick;
            let stick_rigid = &this.stick_rigid;
            (0..ns.div_ceil(NODE_CHUNK))
                .into_par_iter()
                .flat_map_iter(|c| {
                    let k0 = c * NODE_CHUNK;
                    let k1 = (k0 + NODE_CHUNK).min(ns);
                    let mut out = Vec::new();
                    for k in k0..k1 {
                        let i = this.surface.nodes[k];
                        if let Some((f, d, w, side, n)) = this.closest_face(k, 0.5) {
                            let face = &this.surface.faces[f];
                            let vf = this.face_velocity(face, w, v);
                            let vrel = sub(v[i], vf);
                            // A node in contact within the last few steps may come back at
                            // any depth the face takes (it lost the face for a step at an
                            // edge); a fresh contact is only as deep as the node and the face
                            // closed in one step, with a margin. Deeper is not a touch (and
                            // a sudden deep spring would inject energy).
                            let last = this.last_contact[k];
                            let recent = last != u64::MAX && this.steps - last <= RECENT_STEPS;
                            let closing = 2.0 * (-dot(vrel, n)).max(0.0) * dt;
                            let margin = 1e-6 * face.depth;
                            let offset = if !recent {
                                (d <= closing + margin).then_some(0.0)
                            } else if this.contact_face[k] == f as u32 {
                                Some(this.offset[k].min(d))
                            } else {
                                // Onto another face: no deeper than the last contact plus
                                // what the node and the face closed since.
                                let since = (this.steps - last) as f64;
                                let allowed = this.last_depth[k] + since * closing + margin;
                                Some((d - allowed).max(0.0))
                            };
                            if let Some(offset) = offset {
                                let h = friction_update(
                                    stick[k],
                                    n,
                                    vrel,
                                    [0.0; 3],
                                    d - offset,
                                    face.stiffness,
                                    mu,
                                    dt,
                                );
                                out.push(Hit {
                                    slave: k as u32,
                                    partner: f as u32,
                                    rigid: false,
                                    weights: w,
                                    normal_force: h.0,
                                    tangential_force: h.1,
                                    stiffness: face.stiffness,
                                    penetration: d,
                                    offset,
                                    side,
                                    elastic: h.2,
                                    dissipated: h.3,
                                    rigid_work: 0.0,
                                });
                            }
                        }
                        for (r, s) in this.rigid.iter().enumerate() {
                            let hn = this.surface.node_half_thickness[k];
                            if let Some((d, n, vs)) = s.probe_offset(this.x[i], t, hn) {
                                let kn = this.surface.node_stiffness[k];
                                let vrel = sub(v[i], vs);
                                let h = friction_update(
                                    stick_rigid[k * nr + r],
                                    n,
                                    vrel,
                                    vs,
                                    d,
                                    kn,
                                    s.friction,
                                    dt,
                                );
                                // Power the moving surface puts into the body: F·v_s.
                                let work = dot(add(h.0, h.1), vs) * dt;
                                out.push(Hit {
                                    slave: k as u32,
                                    partner: r as u32,
                                    rigid: true,
                                    weights: [0.0; 3],
                                    normal_force: h.0,
                                    tangential_force: h.1,
                                    stiffness: kn,
                                    penetration: d,
                                    offset: 0.0,
                                    side: 1.0,
                                    elastic: h.2,
                                    dissipated: h.3,
                                    rigid_work: work,
                                });
                            }
                        }
                    }
                    out
                })
                .collect()
        };
        // Deterministic scatter, in node order. Only surface and spring nodes ever carry a
        // force.
        force
            .par_chunks_mut(NODE_CHUNK)
            .for_each(|c| c.fill([0.0; 3]));
        for s in self.stick.iter_mut() {
            *s = [0.0; 3];
        }
        for s in self.stick_rigid.iter_mut() {
            *s = [0.0; 3];
        }
        for l in self.normal_load.iter_mut() {
            *l = 0.0;
        }
        let parties = self.parties();
        let n_channels = parties * parties.saturating_sub(1) / 2 * self.n_regions;
        let record = self.steps % self.settings.output_interval as u64 == 0;
        let mut sums = vec![[[0.0f64; 3]; 2]; if record { n_channels } else { 0 }];
        let mut chan = vec![ChannelSample::default(); sums.len()];
        let mut elastic = 0.0;
        let check = !self.mass.is_empty();
        if check {
            self.gershgorin
                .par_chunks_mut(NODE_CHUNK)
                .for_each(|c| c.fill(0.0));
        }
        let mut new_last = vec![u32::MAX; ns];
        for h in &hits {
            let k = h.slave as usize;
            let i = self.surface.nodes[k];
            let total = add(h.normal_force, h.tangential_force);
            force[i] = add(force[i], total);
            let fnorm = norm(h.normal_force);
            self.normal_load[k] += fnorm;
            elastic += h.elastic;
            self.energy.friction_work += h.dissipated;
            self.energy.rigid_work += h.rigid_work;
            let body = self.surface.node_body[k] as usize;
            let (other, face_nodes) = if h.rigid {
                let r = h.partner as usize;
                self.stick_rigid[k * nr + r] = h.tangential_force;
                (self.n_bodies + r, None)
            } else {
                let face = self.surface.faces[h.partner as usize];
                self.stick[k] = h.tangential_force;
                new_last[k] = h.partner;
                self.last_contact[k] = self.steps;
                self.contact_face[k] = h.partner;
                self.side[k] = h.side;
                self.last_depth[k] = h.penetration - h.offset;
                self.offset[k] = h.offset;
                for (j, &node) in face.nodes.iter().enumerate() {
                    force[node] = sub(force[node], scale(total, h.weights[j]));
                    let sl = self.surface.slot[node] as usize;
                    self.normal_load[sl] += fnorm * h.weights[j];
                }
                (face.body as usize, Some(face))
            };
            if check {
                let mi = 1.0 / self.mass[i].sqrt();
                match face_nodes {
                    None => self.gershgorin[i] += h.stiffness * mi * mi,
                    Some(face) => {
                        let s: f64 = mi
                            + (0..3)
                                .map(|j| h.weights[j].abs() / self.mass[face.nodes[j]].sqrt())
                                .sum::<f64>();
                        self.gershgorin[i] += h.stiffness * mi * s;
                        for j in 0..3 {
                            let node = face.nodes[j];
                            self.gershgorin[node] +=
                                h.stiffness * h.weights[j].abs() / self.mass[node].sqrt() * s;
                        }
                    }
                }
            }
            if record {
                // Output on the lower-numbered party, in its region.
                let (a, b, sign, region) = if body < other {
                    (body, other, 1.0, self.region[i] as usize)
                } else {
                    let face = face_nodes.map(|f| {
                        let j = (0..3)
                            .max_by(|&x, &y| h.weights[x].total_cmp(&h.weights[y]))
                            .unwrap_or(0);
                        f.nodes[j]
                    });
                    (
                        other,
                        body,
                        -1.0,
                        face.map_or(0, |n| self.region[n] as usize),
                    )
                };
                let c = pair_index(a, b, parties) * self.n_regions + region;
                sums[c][0] = add(sums[c][0], scale(h.normal_force, sign));
                sums[c][1] = add(sums[c][1], scale(h.tangential_force, sign));
                let half = if face_nodes.is_some() { 0.5 } else { 1.0 };
                chan[c].area += half * self.surface.node_area[k];
                chan[c].max_penetration = chan[c].max_penetration.max(h.penetration);
            }
        }
        self.check_runaway(&new_last, t);
        self.last_face = new_last;
        // No-tension springs.
        let mut spring_energy = 0.0;
        for s in &self.springs {
            let (f, e) = s.force(self.x[s.node]);
            force[s.node] = add(force[s.node], f);
            spring_energy += e;
            if check && e > 0.0 {
                self.gershgorin[s.node] += s.stiffness / self.mass[s.node];
            }
        }
        if check {
            let g = self.gershgorin.par_iter().cloned().reduce(|| 0.0, f64::max);
            self.max_gershgorin = self.max_gershgorin.max(g);
            if g > self.allowance * (1.0 + 1e-12) && self.failure.is_none() {
                self.failure = Some(DemfemError::Numerical(format!(
                    "at t = {t:e} s the active contact springs need an eigenvalue allowance of {g:e} 1/s², above the {:e} 1/s² certified in the step; raise contacts_per_node or lower penalty_scale",
                    self.allowance
                )));
            }
        }
        // Work of all contact forces on the nodes, as the solver counts external work
        // (other nodes carry no force and add nothing), summed per fixed chunk.
        let partial: Vec<f64> = self
            .u_prev
            .par_chunks_mut(NODE_CHUNK)
            .zip(self.f_prev.par_chunks_mut(NODE_CHUNK))
            .zip(u.par_chunks(NODE_CHUNK))
            .zip(force.par_chunks(NODE_CHUNK))
            .map(|(((up, fp), u), f)| {
                let mut w = 0.0;
                for (((up, fp), u), f) in up.iter_mut().zip(fp.iter_mut()).zip(u).zip(f) {
                    for d in 0..3 {
                        w += 0.5 * (u[d] - up[d]) * (fp[d] + f[d]);
                    }
                    *up = *u;
                    *fp = *f;
                }
                w
            })
            .collect();
        let w: f64 = partial.iter().sum();
        if self.steps > 0 {
            self.energy.contact_work += w;
        }
        self.energy.elastic = elastic;
        self.energy.springs = spring_energy;
        self.active = hits.len();
        if record {
            self.history.push(t);
            for (c, s) in chan.iter_mut().enumerate() {
                s.normal_force = norm(sums[c][0]);
                s.tangential_force = norm(sums[c][1]);
                self.history.extend_from_slice(&[
                    s.normal_force,
                    s.tangential_force,
                    s.area,
                    s.max_penetration,
                ]);
            }
            self.sample = chan;
        }
        self.steps += 1;
    }

    /// The failure found by the last steps, if any (a runaway contact or an exceeded
    /// allowance); taking it clears it.
    pub fn take_failure(&mut self) -> Option<DemfemError> {
        self.failure.take()
    }

    /// The last recorded sample, one entry per channel.
    pub fn last_sample(&self) -> &[ChannelSample] {
        &self.sample
    }
}
