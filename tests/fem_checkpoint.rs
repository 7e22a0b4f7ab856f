//! Exact checkpoints of explicit runs with contact: a ball dropped on a rigid belt beside a
//! second ball it hits, with friction and a no-tension spring. The run saved part-way
//! through the contact and restored into a solver rebuilt from the same inputs ends
//! bitwise equal to the uninterrupted run (displacements, velocities, energies, contact
//! history); a state of another model is refused and leaves the solver unchanged.

use demfem::error::DemfemError;
use demfem::fem::contact::{
    ContactSettings, FemContact, NoTensionSpring, RigidShape, RigidSurface,
};
use demfem::fem::mesh::{ball_tet_mesh, place, union};
use demfem::fem::{ExplicitConfig, ExplicitSolver, LinearElastic};

const I3: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn build(n: usize) -> ExplicitSolver {
    let mat = LinearElastic::new(1e7, 0.3, 1000.0).unwrap();
    let r = 0.01;
    let ball = ball_tet_mesh(r, n).unwrap();
    let a = place(&ball, I3, [0.0, 0.0, r + 1e-6]).unwrap();
    let b = place(&ball, I3, [2.0 * r + 2e-5, 0.0, r + 1e-6]).unwrap();
    let (mesh, body) = union(&[a, b]);
    let mut cfg = ExplicitConfig::new(mat);
    cfg.mass_scaling_dt = Some(0.8e-6);
    let mut s = ExplicitSolver::new(&mesh, cfg).unwrap();
    let settings = ContactSettings {
        friction: 0.3,
        output_interval: 3,
        ..Default::default()
    };
    let region = vec![0; mesh.nodes.len()];
    let mut c = FemContact::new(&mesh, &body, &region, &mat, settings).unwrap();
    c.add_rigid(RigidSurface {
        shape: RigidShape::Plane {
            point: [0.0; 3],
            normal: [0.0, 0.0, 1.0],
        },
        surface_velocity: [0.2, 0.0, 0.0],
        friction: 0.3,
    })
    .unwrap();
    let far = (0..mesh.nodes.len())
        .filter(|&i| body[i] == 1)
        .max_by(|&i, &j| mesh.nodes[i][0].total_cmp(&mesh.nodes[j][0]))
        .unwrap();
    let p = mesh.nodes[far];
    c.add_springs(&[NoTensionSpring {
        node: far,
        anchor: [p[0] + 1e-3, p[1], p[2]],
        stiffness: 200.0,
        rest_length: 1e-3,
    }])
    .unwrap();
    let vel: Vec<[f64; 3]> = body
        .iter()
        .map(|&b| if b == 0 { [1.0, 0.0, -0.3] } else { [0.0; 3] })
        .collect();
    s.set_initial_velocity(&vel).unwrap();
    let gravity: Vec<[f64; 3]> = s.mass().iter().map(|m| [0.0, 0.0, -9.81 * m]).collect();
    s.set_extra_loads(&gravity).unwrap();
    s.set_contact(c).unwrap();
    s
}

fn bits(s: &ExplicitSolver) -> Vec<u64> {
    let mut out: Vec<u64> = s
        .displacement()
        .iter()
        .chain(s.velocity())
        .flat_map(|x| x.map(f64::to_bits))
        .collect();
    let c = s.contact().unwrap();
    out.extend(c.history().iter().map(|x| x.to_bits()));
    let e = s.contact_energy();
    out.extend([e.elastic, e.friction_work, e.rigid_work, e.contact_work].map(f64::to_bits));
    out.push(s.time().to_bits());
    out
}

#[test]
fn restored_run_is_bitwise_the_uninterrupted_one() {
    let (first, second) = (1500, 1500);
    let mut whole = build(3);
    whole.run(first + second).unwrap();
    assert!(
        whole.contact().unwrap().energy().friction_work > 0.0,
        "no sliding contact"
    );
    assert!(whole.contact().unwrap().broad_phase_builds() > 1);

    let mut part = build(3);
    part.run(first).unwrap();
    assert!(
        part.contact().unwrap().active_contacts() > 0,
        "save inside a contact"
    );
    let state = part.save_state();
    drop(part);
    let mut resumed = build(3);
    resumed.restore_state(&state).unwrap();
    resumed.run(second).unwrap();
    assert_eq!(resumed.steps(), whole.steps());
    assert!(bits(&resumed) == bits(&whole), "the restored run differs");
}

#[test]
fn a_state_of_another_model_is_refused_and_changes_nothing() {
    let mut a = build(3);
    a.run(10).unwrap();
    let state = a.save_state();
    let mut other = build(2);
    let before = bits(&other);
    match other.restore_state(&state) {
        Err(DemfemError::ShapeMismatch { detail, .. }) => assert!(detail.contains("entries")),
        r => panic!("expected a refusal, got {r:?}"),
    }
    assert!(bits(&other) == before);
    for bad in [&state[..20], &b"not a state at all"[..]] {
        assert!(build(3).restore_state(bad).is_err());
    }
    let mut longer = state.clone();
    longer.push(0);
    assert!(build(3).restore_state(&longer).is_err());
}

#[test]
fn a_dem_checkpoint_is_refused_by_its_kind() {
    use demfem::dem::{EffectSet, Material, ParticleInit, Scene, Simulation};
    use demfem::geometry::Vec3;

    let p = ParticleInit::at_rest(vec![Vec3::new(0.0, 0.0, 0.01)], vec![0.005]);
    let glass = Material::new(1e8, 0.22, 2230.0, 0.0, 1.0, 0.0);
    let mut scene = Scene::new(p, vec![glass], vec![], EffectSet::empty());
    scene.gravity = Vec3::ZERO;
    let mut dem = Simulation::new(&scene).unwrap();
    dem.step(3).unwrap();
    let mut s = build(2);
    let before = bits(&s);
    match s.restore_state(&dem.checkpoint_bytes()) {
        Err(DemfemError::ShapeMismatch { detail, .. }) => assert!(
            detail.contains("a DEM checkpoint") && detail.contains("not an FEM"),
            "{detail}"
        ),
        r => panic!("expected a refusal, got {r:?}"),
    }
    assert!(bits(&s) == before);
    // and the reverse: this solver's state into the DEM simulation
    match dem.restore_checkpoint_bytes(&s.save_state(), "fem.state") {
        Err(DemfemError::Io { detail, .. }) => {
            assert!(detail.contains("an FEM explicit-run state"), "{detail}")
        }
        r => panic!("expected a refusal, got {r:?}"),
    }
}
