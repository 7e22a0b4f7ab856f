//! Conversion of the Python contact description (numpy arrays and tuples) into the core's
//! [`FemContact`], and of its outputs back into numpy arrays and dicts.

use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use demfem::fem::contact::{FemContact, NoTensionSpring, RigidShape, RigidSurface};
use demfem::DemfemError;

use crate::error::core_err as err;

fn vec3(t: [f64; 3]) -> [f64; 3] {
    t
}

/// A rigid surface as Python passes it: ("plane", point, normal, surface_velocity, μ),
/// ("sphere", centre, radius, velocity, μ) or ("cylinder", point, axis, radius, μ).
#[derive(FromPyObject)]
pub enum PyRigid {
    /// kind, point, normal, surface velocity, friction
    Plane(String, [f64; 3], [f64; 3], [f64; 3], f64),
    /// kind, centre, radius, velocity, friction
    Sphere(String, [f64; 3], f64, [f64; 3], f64),
}

fn rigid(r: &PyRigid) -> PyResult<RigidSurface> {
    let bad = |k: &str| {
        err(DemfemError::InvalidParameter {
            field: "rigid surface kind".into(),
            value: k.into(),
            allowed: "'plane', 'sphere' or 'cylinder'".into(),
        })
    };
    Ok(match r {
        PyRigid::Plane(kind, p, n, v, mu) => match kind.as_str() {
            "plane" => RigidSurface {
                shape: RigidShape::Plane {
                    point: vec3(*p),
                    normal: vec3(*n),
                },
                surface_velocity: *v,
                friction: *mu,
            },
            other => return Err(bad(other)),
        },
        PyRigid::Sphere(kind, c, radius, v, mu) => match kind.as_str() {
            "sphere" => RigidSurface {
                shape: RigidShape::Sphere {
                    center: *c,
                    radius: *radius,
                    velocity: *v,
                },
                surface_velocity: *v,
                friction: *mu,
            },
            "cylinder" => RigidSurface {
                shape: RigidShape::Cylinder {
                    point: *c,
                    axis: *v,
                    radius: *radius,
                },
                surface_velocity: [0.0; 3],
                friction: *mu,
            },
            other => return Err(bad(other)),
        },
    })
}

/// Add the rigid surfaces and the no-tension springs, as Python passes them, to a contact
/// model.
pub fn add_surfaces_and_springs(
    mut c: FemContact,
    rigid_surfaces: Vec<PyRigid>,
    spring_nodes: Option<PyReadonlyArray1<'_, i64>>,
    spring_anchors: Option<PyReadonlyArray2<'_, f64>>,
    spring_stiffness: Option<PyReadonlyArray1<'_, f64>>,
    spring_rest_length: Option<PyReadonlyArray1<'_, f64>>,
) -> PyResult<FemContact> {
    for r in &rigid_surfaces {
        c.add_rigid(rigid(r)?).map_err(err)?;
    }
    match (
        spring_nodes,
        spring_anchors,
        spring_stiffness,
        spring_rest_length,
    ) {
        (None, None, None, None) => {}
        (Some(nodes), Some(anchors), Some(k), Some(l0)) => {
            let (nodes, anchors, k, l0) = (
                nodes.as_array(),
                anchors.as_array(),
                k.as_array(),
                l0.as_array(),
            );
            let m = nodes.len();
            if anchors.shape() != [m, 3] || k.len() != m || l0.len() != m {
                return Err(err(DemfemError::ShapeMismatch {
                    field: "springs".into(),
                    detail: format!(
                        "{m} nodes need anchors (m,3), stiffness (m,) and rest_length (m,); got {:?}, {}, {}",
                        anchors.shape(),
                        k.len(),
                        l0.len()
                    ),
                }));
            }
            let mut springs = Vec::with_capacity(m);
            for s in 0..m {
                let node = usize::try_from(nodes[s]).map_err(|_| {
                    err(DemfemError::invalid("spring node", nodes[s] as f64, ">= 0"))
                })?;
                springs.push(NoTensionSpring {
                    node,
                    anchor: [anchors[[s, 0]], anchors[[s, 1]], anchors[[s, 2]]],
                    stiffness: k[s],
                    rest_length: l0[s],
                });
            }
            c.add_springs(&springs).map_err(err)?;
        }
        _ => return Err(err(DemfemError::ShapeMismatch {
            field: "springs".into(),
            detail:
                "spring_nodes, spring_anchors, spring_stiffness and spring_rest_length go together"
                    .into(),
        })),
    }
    Ok(c)
}

/// The contact's counters as a dict.
pub fn info<'py>(py: Python<'py>, c: &FemContact, dt_free: f64) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let e = c.energy();
    d.set_item("elastic_energy", e.elastic)?;
    d.set_item("spring_energy", e.springs)?;
    d.set_item("friction_work", e.friction_work)?;
    d.set_item("rigid_work", e.rigid_work)?;
    d.set_item("contact_work", e.contact_work)?;
    d.set_item("bookkeeping_error", e.bookkeeping_error())?;
    d.set_item("active_contacts", c.active_contacts())?;
    d.set_item("broad_phase_builds", c.broad_phase_builds())?;
    d.set_item("eigenvalue_allowance", c.allowance())?;
    d.set_item("max_contact_eigenvalue", c.max_contact_eigenvalue())?;
    d.set_item("dt_limit_without_contact", dt_free)?;
    d.set_item("surface_nodes", c.surface().nodes.len())?;
    d.set_item("surface_faces", c.surface().faces.len())?;
    Ok(d)
}
