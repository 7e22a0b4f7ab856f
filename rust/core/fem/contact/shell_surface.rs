//! The contact surface of a shell mesh: every triangle is a two-sided face whose contact
//! surfaces lie half its thickness t/2 on either side of the mid-surface, and every node is
//! a surface node whose contact surfaces lie half its thickness on either side of it.
//!
//! **Penalty.** OpenRadioss TYPE7 (`Istf = 0`) gives a shell segment K₀ = ½·Stfac·E·t; the
//! solid form used for tetrahedra here is k_f = s·K·A²/V without the ½, so a shell face gets
//! k_f = s·E·t (s the penalty scale), with no area factor: E·t is already N/m (Pa × m), and
//! the segment's stiffness does not grow with its area. An area factor A/t² (that is, the
//! solid form K·A²/V with V = A·t) would make a contact spring on a thin shell stiffer than
//! the shell's own membrane element (E·t·A/t² ≫ E·t for A ≫ t²) and shrink the stable
//! step; E·t is of the order of the in-plane stiffness of a shell triangle itself. A node
//! gets k_node = Σ k_f / 3 over its triangles (against rigid surfaces).
//!
//! **Node thickness.** A node's thickness is the area-weighted mean of its triangles'.

use crate::error::{check_positive, DemfemError, Result};
use crate::fem::mesh::TriMesh;

use super::surface::{Surface, SurfaceFace};
use super::vec3::{cross, norm, sub};

impl Surface {
    /// The two-sided surface of shell mesh `mesh`: `body_of_node[i]` names the body of node
    /// i (every triangle in one body); `young_modulus` E (Pa) and `penalty_scale` s give the
    /// face stiffnesses s·E·t.
    pub fn from_shell(
        mesh: &TriMesh,
        body_of_node: &[u32],
        young_modulus: f64,
        penalty_scale: f64,
    ) -> Result<Self> {
        check_positive("young_modulus", young_modulus)?;
        check_positive("penalty_scale", penalty_scale)?;
        for (e, &t) in mesh.thickness.iter().enumerate() {
            if !(t > 0.0) || !t.is_finite() {
                return Err(DemfemError::InvalidParameter {
                    field: "shell thickness".into(),
                    value: format!("{t:e} m at triangle {e}"),
                    allowed: "finite and > 0".into(),
                });
            }
        }
        mesh.validate()?;
        let n = mesh.nodes.len();
        if body_of_node.len() != n {
            return Err(DemfemError::ShapeMismatch {
                field: "body_of_node".into(),
                detail: format!("{} entries for {n} nodes", body_of_node.len()),
            });
        }
        let t_max = mesh.thickness.iter().cloned().fold(0.0f64, f64::max);
        let mut faces = Vec::with_capacity(mesh.triangles.len());
        for (e, (tri, &t)) in mesh.triangles.iter().zip(&mesh.thickness).enumerate() {
            let b = body_of_node[tri[0]];
            if tri.iter().any(|&i| body_of_node[i] != b) {
                return Err(DemfemError::ShapeMismatch {
                    field: "body_of_node".into(),
                    detail: format!("triangle {e} has nodes in more than one body"),
                });
            }
            let [a, bb, c] = tri.map(|i| mesh.nodes[i]);
            let area = 0.5 * norm(cross(sub(bb, a), sub(c, a)));
            faces.push(SurfaceFace {
                nodes: *tri,
                element: e,
                body: b,
                stiffness: penalty_scale * young_modulus * t,
                // The reach of the face: its own half thickness plus that of the thickest
                // node that can meet it, on either side (the broad phase inflates by it).
                depth: 0.5 * (t + t_max),
                area,
                half_thickness: 0.5 * t,
            });
        }
        Ok(Self::from_faces(faces, &mesh.nodes, body_of_node))
    }
}

impl super::FemContact {
    /// Contact among the shell bodies of `mesh` (two-sided faces offset by half the
    /// thickness, penalty s·E·t): `body_of_node[i]` numbers the body of node i (0, 1, …),
    /// `region_of_node[i]` its output region. `material` gives E.
    pub fn new_shell(
        mesh: &TriMesh,
        body_of_node: &[u32],
        region_of_node: &[u32],
        material: &crate::fem::material::LinearElastic,
        settings: super::ContactSettings,
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
        let surface = Surface::from_shell(
            mesh,
            body_of_node,
            material.young_modulus,
            settings.penalty_scale,
        )?;
        Self::from_surface(surface, &mesh.nodes, body_of_node, region_of_node, settings)
    }
}
