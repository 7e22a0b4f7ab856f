//! The explicit problem of `benches/fem_vs_calculix.py`, on demfem's side.
//!
//! A glass tube (r_in 4.7 mm, r_out 5.8 mm, 64 mm long; E = 45 GPa, ν = 0.22,
//! ρ = 2230 kg/m³) meshed by the revolved-tet mesher, the end z = 0 clamped, and an
//! impact-like kick: every outer-surface node within `PATCH` of (r_out, 0, 32 mm) starts
//! with velocity (−v0, 0, 0); all other nodes start at rest, no loads, no damping.
//!
//! `--mesh-out FILE` writes the mesh and node sets (one-based ids are the caller's job):
//!   line 1: n_nodes n_tets ; n_nodes lines "x y z" ; n_tets lines "a b c d" (0-based) ;
//!   then "kick k" + k node ids, "fixed f" + f node ids, "probe p" (0-based).
//! `--steps N --dt DT --threads T` runs N central-difference steps at the fixed step DT
//! (0 = 0.9 × the certified bound) on T rayon threads, and prints one `key value` per line:
//! set-up and stepping wall times, element-steps/s, the probe displacement and the strain
//! energy ½ uᵀK u and kinetic energy at the end.
//!
//! Run: `cargo run --release --example fem_explicit_run -- --n-theta 52 --layers 2 --h 0.55e-3 --steps 200`.
use demfem::fem::stable_step::StepBound;
use demfem::fem::{AxisymmetricProfile, ExplicitConfig, ExplicitSolver, LinearElastic, Prescribed};
use std::io::Write;
use std::time::Instant;

const R_IN: f64 = 4.7e-3;
const R_OUT: f64 = 5.8e-3;
const LENGTH: f64 = 64e-3;
const Z0: f64 = 32e-3;

fn arg<T: std::str::FromStr>(args: &[String], name: &str, default: T) -> T {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .map(|v| v.parse().unwrap_or_else(|_| panic!("bad value for {name}")))
        .unwrap_or(default)
}

/// CPU time (user + system, all threads) of this process, s, from /proc/self/stat
/// (clock ticks of 10 ms on Linux); NaN where unavailable.
fn process_cpu_time() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    let Some(rest) = stat.rsplit_once(')').map(|p| p.1) else {
        return f64::NAN;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    match (
        f.get(11).and_then(|v| v.parse::<f64>().ok()),
        f.get(12).and_then(|v| v.parse::<f64>().ok()),
    ) {
        (Some(u), Some(s)) => (u + s) / 100.0,
        _ => f64::NAN,
    }
}

fn main() -> demfem::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let n_theta: usize = arg(&args, "--n-theta", 52);
    let layers: usize = arg(&args, "--layers", 2);
    let h: f64 = arg(&args, "--h", 0.55e-3);
    let steps: u64 = arg(&args, "--steps", 200);
    let dt_arg: f64 = arg(&args, "--dt", 0.0);
    let threads: usize = arg(&args, "--threads", 1);
    let v0: f64 = arg(&args, "--v0", 1.0);
    let patch: f64 = arg(&args, "--patch", 2e-3);
    let mesh_out: String = arg(&args, "--mesh-out", String::new());
    let bound: String = arg(&args, "--bound", "certified".to_string());

    let t0 = Instant::now();
    let rm = AxisymmetricProfile::tube(R_IN, R_OUT, LENGTH)?.tet_mesh(n_theta, layers, h)?;
    let mesh = &rm.mesh;
    let n = mesh.n_nodes();
    let kick: Vec<usize> = (0..n)
        .filter(|&i| {
            let x = mesh.nodes[i];
            let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
            (r - R_OUT).abs() < 1e-9
                && ((x[0] - R_OUT).powi(2) + x[1].powi(2) + (x[2] - Z0).powi(2)).sqrt() < patch
        })
        .collect();
    let fixed: Vec<usize> = (0..n).filter(|&i| mesh.nodes[i][2] < 1e-9).collect();
    let k_mid = rm
        .z_stations
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1 - Z0).abs().total_cmp(&(b.1 - Z0).abs()))
        .unwrap()
        .0;
    let probe = rm.node_index(0, layers, k_mid);
    let mesh_time = t0.elapsed().as_secs_f64();

    if !mesh_out.is_empty() {
        let mut f = std::io::BufWriter::new(
            std::fs::File::create(&mesh_out).expect("cannot create mesh file"),
        );
        let w = |f: &mut std::io::BufWriter<std::fs::File>, s: String| {
            f.write_all(s.as_bytes()).expect("write")
        };
        w(&mut f, format!("{} {}\n", n, mesh.n_elements()));
        for x in &mesh.nodes {
            w(
                &mut f,
                format!("{:.17e} {:.17e} {:.17e}\n", x[0], x[1], x[2]),
            );
        }
        for t in &mesh.tets {
            w(&mut f, format!("{} {} {} {}\n", t[0], t[1], t[2], t[3]));
        }
        w(&mut f, format!("kick {}\n", kick.len()));
        for &i in &kick {
            w(&mut f, format!("{i}\n"));
        }
        w(&mut f, format!("fixed {}\n", fixed.len()));
        for &i in &fixed {
            w(&mut f, format!("{i}\n"));
        }
        w(&mut f, format!("probe {probe}\n"));
        println!("mesh_file {mesh_out}");
        if steps == 0 {
            println!("nodes {n}\ntets {}", mesh.n_elements());
            return Ok(());
        }
    }

    let glass = LinearElastic::new(45e9, 0.22, 2230.0)?;
    let mut cfg = ExplicitConfig::new(glass);
    cfg.energy_interval = 0;
    cfg.step_bound = match bound.as_str() {
        "element" => StepBound::ElementEigenvalue,
        _ => StepBound::CertifiedGlobal {
            margin: 0.01,
            iterations: 400,
        },
    };
    if dt_arg > 0.0 {
        cfg.dt = Some(dt_arg);
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| -> demfem::Result<()> {
        let t1 = Instant::now();
        let mut solver = ExplicitSolver::new(mesh, cfg)?;
        let bcs: Vec<Prescribed> = fixed
            .iter()
            .flat_map(|&i| Prescribed::fix_node(i))
            .collect();
        solver.set_prescribed(&bcs, demfem::fem::LoadHistory::Constant)?;
        let mut v = vec![[0.0; 3]; n];
        for &i in &kick {
            v[i] = [-v0, 0.0, 0.0];
        }
        solver.set_initial_velocity(&v)?;
        let setup_time = t1.elapsed().as_secs_f64();
        let c2 = process_cpu_time();
        let t2 = Instant::now();
        solver.run(steps)?;
        let step_time = t2.elapsed().as_secs_f64();
        let step_cpu = process_cpu_time() - c2;
        let u = solver.displacement().to_vec();
        let mut f = vec![[0.0; 3]; n];
        solver.kernel_mut().apply(&u, &mut f);
        let strain_energy: f64 = 0.5
            * u.iter()
                .zip(&f)
                .map(|(a, b)| a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
                .sum::<f64>();
        // Kinetic energy with the last half-step velocity (the one that moved u to t^N).
        let kinetic: f64 = 0.5
            * solver
                .mass()
                .iter()
                .zip(solver.velocity())
                .map(|(m, v)| m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]))
                .sum::<f64>();
        println!(
            "nodes {n}\ntets {}\nkick_nodes {}\nfixed_nodes {}\nprobe {probe}",
            mesh.n_elements(),
            kick.len(),
            fixed.len()
        );
        println!(
            "threads {threads}\ndt {:.6e}\ndt_limit {:.6e}\nsteps {steps}\ntime {:.6e}",
            solver.dt(),
            solver.dt_limit(),
            solver.time()
        );
        println!("mesh_time {mesh_time:.4}\nsetup_time {setup_time:.4}\nstep_time {step_time:.4}");
        println!("step_cpu {step_cpu:.4}");
        println!(
            "element_steps_per_s {:.6e}",
            mesh.n_elements() as f64 * steps as f64 / step_time
        );
        println!(
            "element_steps_per_cpu_s {:.6e}",
            mesh.n_elements() as f64 * steps as f64 / step_cpu
        );
        println!(
            "probe_u {:.9e} {:.9e} {:.9e}",
            u[probe][0], u[probe][1], u[probe][2]
        );
        println!("strain_energy {strain_energy:.9e}\nkinetic_energy {kinetic:.9e}");
        println!(
            "initial_kinetic {:.9e}",
            0.5 * kick.iter().map(|&i| solver.mass()[i]).sum::<f64>() * v0 * v0
        );
        Ok(())
    })
}
