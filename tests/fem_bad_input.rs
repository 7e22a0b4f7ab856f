//! Bad FEM input is refused with an error naming the field (issue 30): a target size so
//! small the mesh would exhaust memory, sliver or near-degenerate elements in the explicit
//! solver, and two different prescriptions of one degree of freedom.

use demfem::fem::mesh::{
    ball_tet_mesh, box_tet_mesh, AxisymmetricProfile, TetMesh, MAX_TET_ELEMENTS,
};
use demfem::fem::{
    ExplicitConfig, ExplicitSolver, LinearElastic, LoadHistory, Prescribed, PrescribedKind,
};
use demfem::DemfemError;

fn glass() -> LinearElastic {
    LinearElastic::new(63e9, 0.22, 2230.0).unwrap()
}

#[test]
fn tiny_target_size_is_refused_before_meshing() {
    let p = AxisymmetricProfile::default_cartridge();
    let t = std::time::Instant::now();
    let err = p.tet_mesh(48, 2, 1e-9).unwrap_err();
    assert!(
        t.elapsed().as_secs_f64() < 1.0,
        "refused only after {:?}",
        t.elapsed()
    );
    assert!(matches!(err, DemfemError::InvalidParameter { .. }));
    let msg = err.to_string();
    assert!(
        msg.contains("target_size") && msg.contains("max_elements"),
        "{msg}"
    );
    // the estimate is exact for a mesh that is built
    let rm = p.tet_mesh(24, 1, 1e-3).unwrap();
    assert_eq!(
        p.tet_mesh_element_count(24, 1, 1e-3),
        rm.mesh.n_elements() as f64
    );
    // a custom limit just below the count refuses, at the count accepts
    let n = rm.mesh.n_elements();
    assert!(p.tet_mesh_limited(24, 1, 1e-3, n - 1).is_err());
    assert!(p.tet_mesh_limited(24, 1, 1e-3, n).is_ok());
    assert!(MAX_TET_ELEMENTS >= 1_000_000);
}

#[test]
fn sliver_element_is_refused_by_the_explicit_solver() {
    // a flattened tet: positive volume, dihedral angles near 0°, stable step ~1e-16 s
    let mesh = TetMesh {
        nodes: vec![
            [0.0, 0.0, 0.0],
            [1e-3, 0.0, 0.0],
            [0.0, 1e-3, 0.0],
            [0.5e-3, 0.5e-3, 1e-12],
        ],
        tets: vec![[0, 1, 2, 3]],
    };
    mesh.validate().unwrap();
    let err = ExplicitSolver::new(&mesh, ExplicitConfig::new(glass())).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, DemfemError::InvalidParameter { .. }), "{msg}");
    assert!(
        msg.contains("mesh") && msg.contains("element 0") && msg.contains("dihedral"),
        "{msg}"
    );
}

#[test]
fn near_degenerate_volume_is_refused_by_the_explicit_solver() {
    // a good box mesh with one node pulled almost into the plane of a face is a sliver;
    // a tiny but well-shaped element among large ones is refused by volume
    let mut mesh = box_tet_mesh(1.0, 1.0, 1.0, 1, 1, 1).unwrap();
    let base = mesh.nodes.len();
    let s = 1e-5; // volume ~1e-16 of the others
    mesh.nodes.extend([
        [2.0, 0.0, 0.0],
        [2.0 + s, 0.0, 0.0],
        [2.0, s, 0.0],
        [2.0, 0.0, s],
    ]);
    mesh.tets.push([base, base + 1, base + 2, base + 3]);
    mesh.validate().unwrap();
    let err = ExplicitSolver::new(&mesh, ExplicitConfig::new(glass())).unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("mesh") && msg.contains("volume"), "{msg}");
    assert!(
        msg.contains(&format!("element {}", mesh.tets.len() - 1)),
        "{msg}"
    );
}

#[test]
fn usual_meshes_are_still_accepted() {
    let p = AxisymmetricProfile::default_cartridge();
    let rm = p.tet_mesh(24, 1, 1e-3).unwrap();
    ExplicitSolver::new(&rm.mesh, ExplicitConfig::new(glass())).unwrap();
    // the mapped-cube ball has its worst elements at the cube corners
    let ball = ball_tet_mesh(0.01, 4).unwrap();
    println!("ball min dihedral {:.2}°", ball.quality().min_dihedral_deg);
    let mut cfg = ExplicitConfig::new(glass());
    cfg.mass_scaling_dt = Some(0.8e-6);
    ExplicitSolver::new(&ball, cfg).unwrap();
}

#[test]
fn two_prescriptions_of_one_dof_are_refused() {
    let mesh = box_tet_mesh(1.0, 1.0, 1.0, 1, 1, 1).unwrap();
    let mut s = ExplicitSolver::new(&mesh, ExplicitConfig::new(glass())).unwrap();
    let d = |node, component, v| Prescribed {
        node,
        component,
        kind: PrescribedKind::Displacement(v),
    };
    // the same prescription twice is harmless
    s.set_prescribed(&[d(0, 2, 0.0), d(0, 2, 0.0)], LoadHistory::Constant)
        .unwrap();
    let err = s
        .set_prescribed(
            &[d(0, 2, 0.0), d(1, 0, 0.0), d(0, 2, 1e-3)],
            LoadHistory::Constant,
        )
        .unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, DemfemError::InvalidParameter { .. }), "{msg}");
    assert!(
        msg.contains("prescribed") && msg.contains("node 0 component 2"),
        "{msg}"
    );
    let v = Prescribed {
        node: 3,
        component: 1,
        kind: PrescribedKind::Velocity(0.0),
    };
    let err = s
        .set_prescribed(&[d(3, 1, 0.0), v], LoadHistory::Constant)
        .unwrap_err();
    assert!(err.to_string().contains("node 3 component 1"), "{err}");
}
