//! Walls from Python dicts: the shapes (plane, polygon, box, cuboid, triangle mesh), their
//! motion (fixed, constant velocity, harmonic, rotation), surface velocity and material;
//! every bad field is an error naming the wall and the field.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use demfem::geometry::{MeshWall, Vec3, Wall, WallMotion, WallShape};
use demfem::DemfemError;

use crate::convert::{as_float_array, as_int_array, float2, get_f64, int1, vec3s};
use crate::error::{invalid, shape_err, PyDemfemError};

fn get_vec3(d: &Bound<'_, PyDict>, key: &str, default: Option<Vec3>, what: &str) -> PyResult<Vec3> {
    match d.get_item(key)? {
        Some(v) => {
            let x: Vec<f64> = v
                .extract()
                .map_err(|_| invalid(&format!("{what}.{key}"), &v.to_string(), "3 numbers"))?;
            if x.len() != 3 {
                return Err(shape_err(
                    &format!("{what}.{key}"),
                    format!("expected 3 components, got {}", x.len()),
                ));
            }
            Ok(Vec3::new(x[0], x[1], x[2]))
        }
        None => default.ok_or_else(|| invalid(&format!("{what}.{key}"), "missing", "required")),
    }
}

pub(crate) fn parse_wall(d: &Bound<'_, PyDict>, k: usize) -> PyResult<Wall> {
    let w = format!("walls[{k}]");
    let kind: String = match d.get_item("type")? {
        Some(t) => t.extract()?,
        None => {
            return Err(invalid(
                &format!("{w}.type"),
                "missing",
                "'plane', 'polygon', 'strip', 'cuboid' or 'mesh'",
            ))
        }
    };
    let shape = match kind.as_str() {
        "mesh" => parse_mesh(d, &w),
        "plane" => WallShape::plane(
            get_vec3(d, "point", None, &w)?,
            get_vec3(d, "normal", None, &w)?,
        ),
        "polygon" => {
            let verts: Vec<Vec<f64>> = match d.get_item("vertices")? {
                Some(v) => v.extract()?,
                None => return Err(invalid(&format!("{w}.vertices"), "missing", "required")),
            };
            let mut out = Vec::with_capacity(verts.len());
            for v in verts {
                if v.len() != 3 {
                    return Err(shape_err(
                        &format!("{w}.vertices"),
                        format!("vertex with {} components", v.len()),
                    ));
                }
                out.push(Vec3::new(v[0], v[1], v[2]));
            }
            WallShape::polygon(out)
        }
        "strip" => WallShape::vertical_strip(
            get_f64(d, "x0", None, &w)?,
            get_f64(d, "y0", None, &w)?,
            get_f64(d, "x1", None, &w)?,
            get_f64(d, "y1", None, &w)?,
            get_f64(d, "z_bottom", None, &w)?,
            get_f64(d, "z_top", None, &w)?,
        ),
        "cuboid" => WallShape::cuboid(
            get_vec3(d, "center", None, &w)?,
            get_vec3(d, "half_extents", None, &w)?,
        ),
        other => {
            return Err(invalid(
                &format!("{w}.type"),
                other,
                "'plane', 'polygon', 'strip', 'cuboid' or 'mesh'",
            ))
        }
    }
    .map_err(PyDemfemError::from)?;
    let motion = match d.get_item("motion")? {
        None => WallMotion::Fixed,
        Some(m) if m.is_none() => WallMotion::Fixed,
        Some(m) => {
            let m = m
                .cast_into::<PyDict>()
                .map_err(|_| invalid(&format!("{w}.motion"), "not a dict", "a dict or None"))?;
            let mw = format!("{w}.motion");
            let t: String = match m.get_item("type")? {
                Some(t) => t.extract()?,
                None => {
                    return Err(invalid(
                        &format!("{mw}.type"),
                        "missing",
                        "'constant' or 'harmonic'",
                    ))
                }
            };
            match t.as_str() {
                "fixed" => WallMotion::Fixed,
                "constant" => WallMotion::ConstantVelocity {
                    velocity: get_vec3(&m, "velocity", None, &mw)?,
                },
                "harmonic" => WallMotion::harmonic(
                    get_vec3(&m, "direction", None, &mw)?,
                    get_f64(&m, "amplitude", None, &mw)?,
                    get_f64(&m, "period", None, &mw)?,
                    get_f64(&m, "phase", Some(0.0), &mw)?,
                )
                .map_err(PyDemfemError::from)?,
                "rotation" => WallMotion::rotation(
                    get_vec3(&m, "axis_point", None, &mw)?,
                    get_vec3(&m, "axis", None, &mw)?,
                    get_f64(&m, "angular_velocity", None, &mw)?,
                )
                .map_err(PyDemfemError::from)?,
                other => {
                    return Err(invalid(
                        &format!("{mw}.type"),
                        other,
                        "'fixed', 'constant', 'harmonic' or 'rotation'",
                    ))
                }
            }
        }
    };
    let material: i64 = match d.get_item("material")? {
        Some(m) => m.extract()?,
        None => 0,
    };
    if material < 0 {
        return Err(invalid(
            &format!("{w}.material"),
            &material.to_string(),
            ">= 0",
        ));
    }
    Ok(Wall {
        shape,
        motion,
        surface_velocity: get_vec3(d, "surface_velocity", Some(Vec3::ZERO), &w)?,
        material: material as usize,
    })
}

/// A `{"type": "mesh", "vertices": (N, 3) m, "triangles": (M, 3) int, "closed": bool,
/// "triangle_velocities": (M, 3) m/s or None}` wall:
/// the core's checks (finite vertices, indices in range, no degenerate triangle, closed when
/// asked), errors naming `w` instead of "mesh".
fn parse_mesh(d: &Bound<'_, PyDict>, w: &str) -> Result<WallShape, DemfemError> {
    let py_err = |e: PyErr| DemfemError::InvalidParameter {
        field: w.to_string(),
        value: e.to_string(),
        allowed: "a mesh: vertices (N, 3) floats, triangles (M, 3) integers".into(),
    };
    let (vf, tf) = (format!("{w}.vertices"), format!("{w}.triangles"));
    let required = |f: &str| DemfemError::InvalidParameter {
        field: f.to_string(),
        value: "missing".into(),
        allowed: "required".into(),
    };
    let v = d
        .get_item("vertices")
        .map_err(py_err)?
        .ok_or_else(|| required(&vf))?;
    let v = as_float_array(&v, &vf).map_err(py_err)?;
    let v = float2(&v, &vf).map_err(py_err)?;
    let vertices = vec3s(&vf, &v, None).map_err(py_err)?;
    let t = d
        .get_item("triangles")
        .map_err(py_err)?
        .ok_or_else(|| required(&tf))?;
    let t = as_int_array(&t, &tf).map_err(py_err)?;
    let shape: Vec<usize> = t
        .getattr("shape")
        .and_then(|s| s.extract())
        .map_err(py_err)?;
    if shape.len() != 2 || shape[1] != 3 {
        return Err(DemfemError::ShapeMismatch {
            field: tf,
            detail: format!("expected (M, 3), got {shape:?}"),
        });
    }
    let flat = t.call_method1("reshape", (-1,)).map_err(py_err)?;
    let flat = int1(&flat, &tf).map_err(py_err)?;
    let flat = flat.as_array();
    let mut triangles = Vec::with_capacity(shape[0]);
    for k in 0..shape[0] {
        let mut tri = [0u32; 3];
        for c in 0..3 {
            let i = flat[3 * k + c];
            tri[c] = u32::try_from(i).map_err(|_| DemfemError::InvalidParameter {
                field: format!("{tf}[{k}]"),
                value: i.to_string(),
                allowed: format!("vertex indices in 0..{}", vertices.len()),
            })?;
        }
        triangles.push(tri);
    }
    let closed: bool = match d.get_item("closed").map_err(py_err)? {
        Some(c) => c.extract().map_err(py_err)?,
        None => false,
    };
    let rename = |e: DemfemError| match e {
        DemfemError::InvalidParameter {
            field,
            value,
            allowed,
        } => DemfemError::InvalidParameter {
            field: field.replacen("mesh", w, 1),
            value,
            allowed,
        },
        DemfemError::ShapeMismatch { field, detail } => DemfemError::ShapeMismatch {
            field: field.replacen("mesh", w, 1),
            detail,
        },
        other => other,
    };
    let mesh = match d.get_item("triangle_velocities").map_err(py_err)? {
        Some(tv) if !tv.is_none() => {
            let f = format!("{w}.triangle_velocities");
            let tv = as_float_array(&tv, &f).map_err(py_err)?;
            let tv = float2(&tv, &f).map_err(py_err)?;
            let tv = vec3s(&f, &tv, Some(triangles.len())).map_err(py_err)?;
            MeshWall::with_triangle_velocities(vertices, triangles, tv)
        }
        _ => MeshWall::new(vertices, triangles),
    }
    .map_err(rename)?;
    if closed {
        mesh.require_closed(&format!("{w}.closed"))?;
    }
    Ok(WallShape::Mesh(mesh))
}
