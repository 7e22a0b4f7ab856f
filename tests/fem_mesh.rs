//! Meshes of the cartridge: exact volume, conformity, quality, sliver refusal, shell mesh,
//! and VTK output.

use demfem::fem::io::vtk::{write_vtu, DataArray, PvdSeries};
use demfem::fem::mesh::{AxisymmetricProfile, TetMesh};
use demfem::DemfemError;

/// Volume of the faceted body of revolution: at each height the section is the annulus
/// between two regular n-gons of circumradius r_in(z), r_out(z), area
/// (n/2) sin(2π/n)(r_out² − r_in²); with radii linear in z, ∫ r² dz = L(r0² + r0 r1 + r1²)/3.
fn faceted_volume(p: &AxisymmetricProfile, n: usize) -> f64 {
    let c = 0.5 * n as f64 * (2.0 * std::f64::consts::PI / n as f64).sin();
    let mut v = 0.0;
    for k in 0..p.z.len() - 1 {
        let l = p.z[k + 1] - p.z[k];
        let sq = |a: &[f64]| l * (a[k] * a[k] + a[k] * a[k + 1] + a[k + 1] * a[k + 1]) / 3.0;
        v += c * (sq(&p.r_out) - sq(&p.r_in));
    }
    v
}

#[test]
fn cartridge_tet_mesh_is_exact_conforming_and_sound() {
    let p = AxisymmetricProfile::default_cartridge();
    for (n_theta, layers, h) in [(24, 1, 1.0e-3), (48, 2, 0.55e-3), (64, 3, 0.4e-3)] {
        let rm = p.tet_mesh(n_theta, layers, h).unwrap();
        let m = &rm.mesh;
        // The tets fill the faceted solid exactly (planar trapezoidal facets): round-off only.
        let v_exact = faceted_volume(&p, n_theta);
        assert!(
            (m.volume() - v_exact).abs() < 1e-10 * v_exact,
            "volume {} vs {}",
            m.volume(),
            v_exact
        );
        // Conforming: every interior face is shared by exactly two tets, so the faces seen
        // once are exactly the triangulated inner, outer and two end surfaces.
        let n_ax = rm.z_stations.len() - 1;
        let expected = 2 * (2 * n_theta * n_ax) + 2 * (2 * n_theta * layers);
        assert_eq!(m.boundary_faces().len(), expected);
        let q = m.check_quality(5.0).unwrap();
        println!(
            "cartridge n_theta {n_theta}, layers {layers}, h {h:e}: {} nodes, {} tets, min dihedral {:.1}°, max dihedral {:.1}°, aspect max {:.2} mean {:.2}",
            m.n_nodes(), m.n_elements(), q.min_dihedral_deg, q.max_dihedral_deg, q.max_aspect_ratio, q.mean_aspect_ratio
        );
        // Glass mass near the design's ≈ 5 g class (ρ = 2230 kg/m³).
        let mass = 2230.0 * m.volume();
        assert!(mass > 2e-3 && mass < 6e-3, "mass {mass}");
    }
}

#[test]
fn sliver_and_bad_input_are_refused() {
    // Four almost coplanar points: dihedral angles near 0° and 180°.
    let mesh = TetMesh {
        nodes: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.5, 1e-4],
        ],
        tets: vec![[0, 1, 2, 3]],
    };
    mesh.validate().unwrap();
    assert!(matches!(
        mesh.check_quality(5.0),
        Err(DemfemError::InvalidParameter { .. })
    ));
    // Inverted element.
    let mut inv = TetMesh {
        nodes: mesh.nodes.clone(),
        tets: vec![[0, 2, 1, 3]],
    };
    assert!(inv.validate().is_err());
    assert_eq!(inv.orient(), 1);
    inv.validate().unwrap();
    // Profiles: r_out <= r_in, decreasing z, mismatched lengths.
    assert!(AxisymmetricProfile::new(vec![0.0, 1.0], vec![2.0, 2.0], vec![1.0, 3.0]).is_err());
    assert!(AxisymmetricProfile::new(vec![1.0, 0.0], vec![1.0, 1.0], vec![2.0, 2.0]).is_err());
    assert!(AxisymmetricProfile::new(vec![0.0, 1.0], vec![1.0], vec![2.0, 2.0]).is_err());
    let p = AxisymmetricProfile::default_cartridge();
    assert!(p.tet_mesh(2, 2, 1e-3).is_err());
    assert!(p.tet_mesh(16, 0, 1e-3).is_err());
    assert!(p.tet_mesh(16, 2, f64::NAN).is_err());
}

/// Shell mid-surface: the body triangles carry the 1.1 mm wall; the shoulder triangles the
/// wall measured normal to the sloped mid-surface; the shell volume Σ A·t matches the
/// solid volume to within the thin-shell approximation (mid-surface area × normal
/// thickness is exact for a cylinder, and off by O(t/R) on the cone).
#[test]
fn cartridge_shell_mesh() {
    let p = AxisymmetricProfile::default_cartridge();
    let n = 64;
    let s = p.shell_mesh(n, 0.5e-3).unwrap();
    assert!(s.min_angle_deg() > 20.0);
    let body_t = s.thickness[0];
    assert!((body_t - 1.1e-3).abs() < 1e-12);
    // Shoulder: mid radius 5.25 → 2.45 mm over 4 mm: cos(atan(2.8/4)).
    let cos_s = 4.0 / (4.0f64 * 4.0 + 2.8 * 2.8).sqrt();
    assert!(s
        .thickness
        .iter()
        .any(|&t| (t - 1.1e-3 * cos_s).abs() < 1e-12));
    let solid = faceted_volume(&p, n);
    let rel = (s.volume() - solid).abs() / solid;
    println!(
        "shell: {} nodes, {} triangles, volume {:e} vs solid {:e} (rel {rel:.3e})",
        s.nodes.len(),
        s.triangles.len(),
        s.volume(),
        solid
    );
    assert!(rel < 0.03);
}

#[test]
fn vtk_files_are_written_atomically() {
    let rm = AxisymmetricProfile::tube(4.7e-3, 5.8e-3, 2e-3)
        .unwrap()
        .tet_mesh(12, 1, 1e-3)
        .unwrap();
    let m = &rm.mesh;
    let dir = std::env::temp_dir().join(format!("demfem_vtk_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let disp: Vec<f64> = m
        .nodes
        .iter()
        .flat_map(|x| [x[0] * 1e-3, x[1] * 1e-3, 0.0])
        .collect();
    let s1: Vec<f64> = (0..m.n_elements()).map(|e| e as f64).collect();
    let stress: Vec<f64> = (0..m.n_elements() * 6).map(|e| e as f64).collect();
    let mut series = PvdSeries::default();
    for step in 0..2 {
        let name = format!("tube_{step:04}.vtu");
        write_vtu(
            &dir.join(&name),
            &m.nodes,
            &m.tets,
            &[DataArray {
                name: "displacement",
                n_components: 3,
                values: &disp,
            }],
            &[
                DataArray {
                    name: "sigma1",
                    n_components: 1,
                    values: &s1,
                },
                DataArray {
                    name: "stress",
                    n_components: 6,
                    values: &stress,
                },
            ],
        )
        .unwrap();
        series.push(step as f64 * 1e-6, name);
    }
    series.write(&dir.join("tube.pvd")).unwrap();
    let text = std::fs::read_to_string(dir.join("tube_0001.vtu")).unwrap();
    assert!(text.contains(&format!(
        "NumberOfPoints=\"{}\" NumberOfCells=\"{}\"",
        m.n_nodes(),
        m.n_elements()
    )));
    assert!(text.trim_end().ends_with("</VTKFile>"));
    let pvd = std::fs::read_to_string(dir.join("tube.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 2);
    assert!(std::fs::read_dir(&dir).unwrap().all(|e| !e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .ends_with(".tmp")));
    // Wrong array length is an error, not a panic.
    let bad = write_vtu(
        &dir.join("bad.vtu"),
        &m.nodes,
        &m.tets,
        &[DataArray {
            name: "x",
            n_components: 3,
            values: &s1,
        }],
        &[],
    );
    assert!(matches!(bad, Err(DemfemError::ShapeMismatch { .. })));
    // Shell mid-surface as VTK triangles (cell type 5).
    let sm = AxisymmetricProfile::default_cartridge()
        .shell_mesh(12, 2e-3)
        .unwrap();
    let th: Vec<f64> = sm.thickness.clone();
    demfem::fem::io::vtk::write_vtu_triangles(
        &dir.join("shell.vtu"),
        &sm.nodes,
        &sm.triangles,
        &[],
        &[DataArray {
            name: "thickness",
            n_components: 1,
            values: &th,
        }],
    )
    .unwrap();
    let st = std::fs::read_to_string(dir.join("shell.vtu")).unwrap();
    assert_eq!(st.matches("          5\n").count(), sm.triangles.len());
    std::fs::remove_dir_all(&dir).unwrap();
}
