use demfem::rigid::revolution::features::*;
use demfem::rigid::{RevolutionProfile, RevolutionShape};
use nalgebra::{UnitQuaternion, Vector3, Quaternion};
type V3 = Vector3<f64>;
fn placed<'a>(shape: &'a RevolutionShape, x: &V3, q: &UnitQuaternion<f64>) -> Placed<'a> {
    Placed { shape, origin: *x, axis: q * V3::z(), x: q * V3::x(), y: q * V3::y() }
}
fn tube(radius: f64, length: f64) -> RevolutionShape {
    let profile = RevolutionProfile::new(vec![0.0, length], vec![0.5 * radius, 0.5 * radius], vec![radius, radius]).unwrap();
    RevolutionShape::from_profile(&profile, 0.5 * length).unwrap()
}
fn q(x: f64, y: f64, z: f64, w: f64) -> UnitQuaternion<f64> { UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)) }
#[test]
fn debug_tube() {
    let (a_shape, b_shape) = (tube(5.8e-3, 0.0545), tube(3.65e-3, 0.0127));
    let xa = V3::new(-0.004106103114348934, -0.0043626374041118065, -0.0020597830454808386);
    let qa = q(0.5051576215533893, 0.4582172447076564, -0.044138550414895006, -0.7300030975320023);
    let xb = V3::new(0.01558888173059646, -0.030367591311178277, -0.009545005935728813);
    let qb = q(-0.34450500216459506, 0.534151959639141, -0.30315444662556307, -0.7099967387167259);
    let (a, b) = (placed(&a_shape, &xa, &qa), placed(&b_shape, &xb, &qb));
    println!("ss {:?}", side_side(&a, 0, &b, 0));
    for k in 0..2 { println!("cs A{k} {:?}", circle_side(&a, k, &b, 0)); println!("cs B{k} {:?}", circle_side(&b, k, &a, 0)); }
    for k in 0..2 { for l in 0..2 { println!("cc {k}{l} {:?}", circle_circle(&a, k, &b, l)); } }
    for f in 0..2 { for l in 0..2 { println!("fc A{f}B{l} {:?}", face_circle(&a, f, &b, l)); println!("fc B{f}A{l} {:?}", face_circle(&b, f, &a, l)); } }
    // brute force circle-circle 0,0
    let ca = a.at(a_shape.circles[0].z); let cb = b.at(b_shape.circles[0].z);
    let mut best = (f64::INFINITY, 0.0, 0.0);
    for i in 0..4000 { for j in 0..4000 { let t = i as f64 * 6.283185307179586/4000.0; let s = j as f64 * 6.283185307179586/4000.0;
        let p = ca + (a.x * t.cos() + a.y * t.sin()) * 5.8e-3; let r = cb + (b.x * s.cos() + b.y*s.sin())*3.65e-3; let d = (p-r).norm(); if d < best.0 { best = (d, t, s);} } }
    println!("brute cc00 {:?}", best);
}
fn cartridge() -> RevolutionShape {
    let profile = RevolutionProfile::default_cartridge();
    let com = profile.mass_properties(2230.0).unwrap().center_of_mass.z;
    RevolutionShape::from_profile(&profile, com).unwrap()
}
#[test]
fn debug_cart() {
    let s = cartridge();
    let xa = V3::new(0.003763248215799884, -0.007206658540030104, -0.005471387672207449);
    let qa = q(0.9206025429127597, -0.16741120095280004, -0.21365581849797724, -0.2807412313858819);
    let xb = V3::new(-0.0015517580122866152, 0.02466680575987074, -0.024933462622504884);
    let qb = q(-0.4682533617786581, -0.44384829122498815, -0.12881187510875206, 0.7530902896669234);
    let (a, b) = (placed(&s, &xa, &qa), placed(&s, &xb, &qb));
    for i in 0..5 { for j in 0..5 { if let Some(f) = piece_pair(&a, i, &b, j) { println!("{i}{j} {:.6e} {:?} {:?}", f.distance, f.feature_a, f.feature_b); } } }
    // brute force: sample surfaces
    let mut best = f64::INFINITY; let mut arg = (0.0,0.0,0.0,0.0);
    let pts = |p: &Placed, n: usize| -> Vec<(V3, f64, f64)> { let mut v = Vec::new(); let zs = &p.shape.outline; 
        for k in 0..zs.len()-1 { let (a0, b0) = (zs[k], zs[k+1]); for i in 0..=40 { let t = i as f64/40.0; let z = a0.0 + t*(b0.0-a0.0); let r = a0.1 + t*(b0.1-a0.1);
            for j in 0..n { let th = j as f64 * 6.283185307179586/n as f64; v.push((p.at(z) + (p.x*th.cos()+p.y*th.sin())*r, z, th)); } } } v };
    let pa = pts(&a, 360); let pb = pts(&b, 360);
    for x in &pa { for y in &pb { let d = (x.0-y.0).norm(); if d < best { best = d; arg = (x.1, x.2, y.1, y.2);} } }
    println!("brute {best:.6e} {arg:?}");
}
#[test]
fn debug_cart2() {
    let s = cartridge();
    let xa = V3::new(0.003763248215799884, -0.007206658540030104, -0.005471387672207449);
    let qa = q(0.9206025429127597, -0.16741120095280004, -0.21365581849797724, -0.2807412313858819);
    let xb = V3::new(-0.0015517580122866152, 0.02466680575987074, -0.024933462622504884);
    let qb = q(-0.4682533617786581, -0.44384829122498815, -0.12881187510875206, 0.7530902896669234);
    let (a, b) = (placed(&s, &xa, &qa), placed(&s, &xb, &qb));
    let (sa, sb) = (Sweep::of_piece(&a, 0), Sweep::of_piece(&b, 0));
    println!("{:?}\n{:?}", sa, sb);
    let p0 = sa.origin + sa.axis * sa.s[0]; let q0 = sb.origin + sb.axis * sb.s[0];
    println!("{:?}", segment_parameters(&p0, &(sa.axis * (sa.s[1]-sa.s[0])), &q0, &(sb.axis*(sb.s[1]-sb.s[0]))));
    println!("{:?}", sweep_closest(&sa, &sb));
    println!("{:?}", side_side(&a, 0, &b, 0));
}
#[test]
fn debug_cart3() {
    let s = cartridge();
    let xa = V3::new(0.003763248215799884, -0.007206658540030104, -0.005471387672207449);
    let qa = q(0.9206025429127597, -0.16741120095280004, -0.21365581849797724, -0.2807412313858819);
    let xb = V3::new(-0.0015517580122866152, 0.02466680575987074, -0.024933462622504884);
    let qb = q(-0.4682533617786581, -0.44384829122498815, -0.12881187510875206, 0.7530902896669234);
    let (a, b) = (placed(&s, &xa, &qa), placed(&s, &xb, &qb));
    println!("{:?}", s.circles[1]);
    // scan theta for circle 1 of a vs side 0 of b
    let c = a.at(s.circles[1].z);
    for i in 0..36 { let th = i as f64 * 10f64.to_radians(); let p = c + (a.x*th.cos()+a.y*th.sin())*s.circles[1].r;
       let (z, _, rho) = b.meridian(&p); println!("{i} z {z:.5} rho-r {:.6e}", rho - 5.8e-3); }
    println!("{:?}", circle_side(&a, 1, &b, 0));
    println!("{:?}", circle_side(&a, 1, &b, 1));
    println!("{:?}", piece_pair(&a, 1, &b, 0));
}
fn lcg_next(s: &mut u64) -> f64 { *s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407); (*s >> 11) as f64 / (1u64 << 53) as f64 }
#[test]
fn debug_compound() {
    use demfem::rigid::ExactShape;
    use parry3d_f64::math::{Pose, Rotation, Vector};
    let profile = RevolutionProfile::default_cartridge();
    let com = profile.mass_properties(2230.0).unwrap().center_of_mass.z;
    let shape = RevolutionShape::from_profile(&profile, com).unwrap();
    let exact = ExactShape::from_profile(&profile, com).unwrap();
    let pose_of = |x: &V3, q: &UnitQuaternion<f64>| { let c = q.coords; Pose::from_parts(Vector::new(x.x,x.y,x.z), Rotation::from_xyzw(c[0], c[1], c[2], c[3])) };
    let mut s = 99u64;
    let mut worst = 0.0f64;
    for _ in 0..20000 {
        let rot = |s: &mut u64| { let (u1,u2,u3) = (lcg_next(s), lcg_next(s), lcg_next(s)); let tau = 6.283185307179586; let (a,b) = ((1.0-u1).sqrt(), u1.sqrt());
            UnitQuaternion::from_quaternion(Quaternion::new(b*(tau*u3).cos(), a*(tau*u2).sin(), a*(tau*u2).cos(), b*(tau*u3).sin())) };
        let qa = rot(&mut s); let qb = rot(&mut s);
        let xa = V3::zeros(); let xb = V3::new(lcg_next(&mut s)-0.5, lcg_next(&mut s)-0.5, lcg_next(&mut s)-0.5) * 0.1;
        let (a, b) = (placed(&shape, &xa, &qa), placed(&shape, &xb, &qb));
        let mut best = f64::INFINITY; 
        for i in 0..5 { for j in 0..5 { if let Some(f) = piece_pair_within(&a, i, &b, j, 1.0) { best = best.min(f.distance); } } }
        if !(best > 1e-6 && best < 3e-3) { continue; }
        let d = parry3d_f64::query::distance(&pose_of(&xa, &qa), &exact.compound, &pose_of(&xb, &qb), &exact.compound).unwrap();
        // manual min over pieces
        let mut manual = f64::INFINITY;
        for (pa, sa) in exact.compound.shapes() { for (pb, sb) in exact.compound.shapes() {
            let dd = parry3d_f64::query::distance(&(pose_of(&xa,&qa) * *pa), sa.as_ref(), &(pose_of(&xb,&qb) * *pb), sb.as_ref()).unwrap().distance; manual = manual.min(dd); } }
        if (best - d.distance).abs() > worst { worst = (best - d.distance).abs(); println!("mine {best:.6e} parry {:.6e} manual {manual:.6e} sub {:?} {:?}", d.distance, d.subshape1, d.subshape2); }
    }
}
#[test]
fn debug_compound2() {
    use demfem::rigid::ExactShape;
    use parry3d_f64::math::{Pose, Rotation, Vector};
    let profile = RevolutionProfile::default_cartridge();
    let com = profile.mass_properties(2230.0).unwrap().center_of_mass.z;
    let shape = RevolutionShape::from_profile(&profile, com).unwrap();
    let exact = ExactShape::from_profile(&profile, com).unwrap();
    let pose_of = |x: &V3, q: &UnitQuaternion<f64>| { let c = q.coords; Pose::from_parts(Vector::new(x.x,x.y,x.z), Rotation::from_xyzw(c[0], c[1], c[2], c[3])) };
    let xa = V3::new(-0.0023351391720302784, 0.0038575136411487755, -0.004821422995933112);
    let qa = q(0.3889531750333598, -0.6464569420666209, -0.16515534268372642, 0.6352421290093748);
    let xb = V3::new(-0.04435908270080261, -0.009408299629076147, 0.008380714950619622);
    let qb = q(-0.08755186478935023, 0.5306965140792897, -0.27130126835455665, -0.7981801192119523);
    let (a, b) = (placed(&shape, &xa, &qa), placed(&shape, &xb, &qb));
    for i in 0..5 { for j in 0..5 { let f = piece_pair_within(&a, i, &b, j, 1.0); 
        let (pa, sa) = &exact.compound.shapes()[i]; let (pb, sb) = &exact.compound.shapes()[j];
        let dd = parry3d_f64::query::distance(&(pose_of(&xa,&qa) * *pa), sa.as_ref(), &(pose_of(&xb,&qb) * *pb), sb.as_ref()).unwrap().distance;
        let cc = parry3d_f64::query::contact(&(pose_of(&xa,&qa) * *pa), sa.as_ref(), &(pose_of(&xb,&qb) * *pb), sb.as_ref(), 0.0).unwrap().map(|c| c.dist);
        println!("{i}{j} mine {:?} parry {dd:.6e} {cc:?}", f.map(|f| (f.distance, f.feature_a, f.feature_b))); } }
    let d = parry3d_f64::query::distance(&pose_of(&xa, &qa), &exact.compound, &pose_of(&xb, &qb), &exact.compound).unwrap();
    println!("{d:?}");
}
#[path = "rigid_common/mod.rs"]
mod rigid_common;
#[test]
fn debug_pile() {
    use demfem::rigid::{Plane, RigidScene, RigidSceneConfig};
    let half = 0.072;
    let mut planes = vec![RigidSceneConfig::belt(Vector3::zeros()).unwrap()];
    for (point, normal) in [(V3::new(-half, 0.0, 0.0), V3::x()), (V3::new(half, 0.0, 0.0), -V3::x()), (V3::new(0.0, -half, 0.0), V3::y()), (V3::new(0.0, half, 0.0), -V3::y())] {
        planes.push(Plane::new(point, normal, V3::zeros()).unwrap());
    }
    let glass = demfem::rigid::ContactMaterial { young_modulus: 45e7, poisson_ratio: 0.22 };
    let config = RigidSceneConfig { planes, body_material: glass, plane_material: glass, restitution: 0.5, friction: 0.3, max_expected_speed: 2.0, ..Default::default() };
    let (shape, mass) = rigid_common::cartridge("revolution");
    let mut scene = RigidScene::new(config).unwrap();
    let id = scene.add_shape(shape, mass).unwrap();
    let mut s = 7u64;
    for k in 0..12 {
        let (layer, cell) = (k / 4, k % 4);
        let x = -0.036 + 0.072 * (cell % 2) as f64 + 0.001 * (lcg_next(&mut s) - 0.5);
        let y = -0.036 + 0.072 * (cell / 2) as f64 + 0.001 * (lcg_next(&mut s) - 0.5);
        let z = 0.036 + 0.075 * layer as f64;
        let axis = V3::new(lcg_next(&mut s) - 0.5, lcg_next(&mut s) - 0.5, lcg_next(&mut s) - 0.5);
        let q = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), std::f64::consts::PI * lcg_next(&mut s));
        let omega = V3::new(lcg_next(&mut s) - 0.5, lcg_next(&mut s) - 0.5, lcg_next(&mut s) - 0.5) * 20.0;
        scene.add_body(id, V3::new(x, y, z), q, V3::zeros(), omega).unwrap();
    }
    let energy = |s: &RigidScene| -> f64 { (0..s.bodies.len()).map(|i| s.bodies.kinetic_energy(i) + s.bodies.mass[i] * 9.81 * s.bodies.position[i].z).sum::<f64>() + s.elastic_energy_last_step() };
    let target = 0.19811205549748553;
    while scene.time() < target - 1e-12 { scene.run(20).unwrap(); }
    let (shape_r, _) = rigid_common::cartridge_revolution();
    let mut e_prev = energy(&scene);
    for _ in 0..25 {
        let before: Vec<(V3, UnitQuaternion<f64>)> = (0..12).map(|i| (scene.bodies.position[i], scene.bodies.orientation[i])).collect();
        let ke0: Vec<f64> = (0..12).map(|i| scene.bodies.kinetic_energy(i)).collect();
        let pe0: Vec<f64> = (0..12).map(|i| scene.bodies.mass[i] * 9.81 * scene.bodies.position[i].z).collect();
        scene.run(1).unwrap();
        for i in 0..12usize { println!("  body {i}: dKE {:+.3e} dPE {:+.3e} v {:?} w {:?}", scene.bodies.kinetic_energy(i) - ke0[i], scene.bodies.mass[i] * 9.81 * scene.bodies.position[i].z - pe0[i], scene.bodies.velocity[i], scene.bodies.angular_velocity_world(i)); }
        let e = energy(&scene);
        println!("t {:.8} dE {:+.3e} coord {:?} walls {:?} contacts {} maxov {:.3e}", scene.time(), e - e_prev, scene.coordination(), scene.wall_contacts(), scene.contacts_last_step(), scene.max_overlap_last_step());
        // contacts of touching pairs
        for a in 0..12 { for b in a+1..12 {
            let pa = placed(&shape_r, &scene.bodies.position[a], &scene.bodies.orientation[a]);
            let pb = placed(&shape_r, &scene.bodies.position[b], &scene.bodies.orientation[b]);
            let mut sc = demfem::rigid::revolution::contacts::PairScratch::default(); let mut out = vec![]; let mut w = vec![];
            demfem::rigid::revolution::contacts::pair_contacts(&pa, &pb, &mut sc, &mut out, &mut w);
            for (c, w) in out.iter().zip(&w) { println!("   pair {a}-{b}: ov {:.4e} w {w:.3} f {} {} r {:.4e} {:.4e}", c.overlap, c.feature_first, c.feature_second, c.radius_first, c.radius_second); }
        } }
        let _ = before;
        e_prev = e;
    }
    let rises: Vec<(f64, f64, Vec<u32>, Vec<u32>)> = vec![];
    for r in rises.iter().take(15) { println!("{:e} at t {} coord {:?} walls {:?}", r.0, r.1, r.2, r.3); }
}
#[test]
fn debug_pair13() {
    use demfem::rigid::revolution::contacts::*;
    let (s, _) = rigid_common::cartridge_revolution();
    let xa = V3::new(0.015970390250541595, -0.022182732567300092, 0.0057987837134577);
    let qa = q(0.6518725872989525, -0.2739682338543751, -0.4388249154055839, -0.5544693232146989);
    let xb = V3::new(0.03234768875815457, 0.02957887593023559, 0.005798984802133476);
    let qb = q(0.6439412178659566, -0.29213226972397227, -0.413079851438699, 0.5739019787861087);
    let (a, b) = (placed(&s, &xa, &qa), placed(&s, &xb, &qb));
    println!("axes {:?} {:?}", a.axis, b.axis);
    let mut sc = PairScratch::default(); let mut out = vec![]; let mut w = vec![];
    pair_contacts(&a, &b, &mut sc, &mut out, &mut w);
    for (c, w) in out.iter().zip(&w) { println!("{c:?} w {w}"); }
    for i in 0..5 { for j in 0..5 { if let Some(f) = piece_pair_within(&a, i, &b, j, 0.0) { if f.distance < 1e-4 { println!("{i}{j} {:?}", f); } } } }
}
#[test]
fn debug_minimizer() {
    let s = cartridge();
    let mut seed = 5u64;
    let mut worst = 0.0f64; let mut count = 0;
    for _ in 0..200000 {
        let rot = |s: &mut u64| { let (u1,u2,u3) = (lcg_next(s), lcg_next(s), lcg_next(s)); let tau = 6.283185307179586; let (a,b) = ((1.0-u1).sqrt(), u1.sqrt());
            UnitQuaternion::from_quaternion(Quaternion::new(b*(tau*u3).cos(), a*(tau*u2).sin(), a*(tau*u2).cos(), b*(tau*u3).sin())) };
        let qa = rot(&mut seed); let qb = rot(&mut seed);
        let xb = V3::new(lcg_next(&mut seed)-0.5, lcg_next(&mut seed)-0.5, lcg_next(&mut seed)-0.5) * 0.08;
        let (a, b) = (placed(&s, &V3::zeros(), &qa), placed(&s, &xb, &qb));
        for k in [0usize, 1, 4, 5] { for j in 0..5 {
            // brute force min over theta of the signed distance to side j of b (ignoring validity)
            let c = a.at(s.circles[k].z); let f = s.frustums[j];
            let mut best = f64::INFINITY;
            for t in 0..20000 { let th = t as f64 * 6.283185307179586 / 20000.0; let p = c + (a.x*th.cos() + a.y*th.sin()) * s.circles[k].r;
                let (z, _, rho) = b.meridian(&p); let d = (rho - f.r[0] - f.slope * (z - f.z[0])) * f.cos; best = best.min(d); }
            // our minimizer (raw): replicate via circle_side ignoring validity is not possible; compare when valid
            if let Some(fp) = circle_side(&a, k, &b, j) { count += 1; if fp.distance - best > worst { worst = fp.distance - best; if worst > 1e-9 { println!("k {k} j {j} mine {} brute {best} qa {:?} qb {:?} xb {:?}", fp.distance, qa.coords, qb.coords, xb); } } }
        } }
        if count > 3000 { break; }
    }
    println!("compared {count}, worst excess {worst:e}");
}
