//! End-to-end reconstruction through the safe API: the sample bunny (watertight, outward,
//! per-point normals vs the ground truth), input variants (f32, strided, input normals) and
//! mesh/point-file round trips.
mod common;

use common::*;
use gmpu::{Mesh, Param, Points, Stat, Surface};

/// Resolution used where a test only needs a closed mesh quickly.
const FAST_RESOLUTION: f64 = 40.0;

fn fitted(points: &[[f64; 3]]) -> Surface {
    let mut s = Surface::new().unwrap();
    s.set_param(Param::Threads, 2.0).unwrap();
    s.set_points(points).unwrap();
    s.fit().unwrap();
    s.orient().unwrap();
    s
}

#[test]
fn bunny_sample_is_watertight_outward_and_correctly_oriented() {
    let cloud = Points::read(sample()).unwrap();
    assert_eq!(cloud.len(), 35_000);
    assert!(cloud.normals().is_none());
    let mut s = fitted(cloud.positions());
    assert_eq!(s.point_count(), 35_000);
    assert_eq!(s.stat(Stat::Points).unwrap(), 35_000.0);
    assert!(s.stat(Stat::Leaves).unwrap() > 100.0);

    // Per-point normals against the ground truth of the same points (bunny_clean).
    let gt = Points::read(test_data().join("clouds/bunny_clean_gt.ply")).unwrap();
    assert_eq!(gt.positions(), cloud.positions(), "bunny.ply is bunny_clean.ply");
    let normals = s.normals().unwrap();
    assert_eq!(normals.len(), 35_000);
    for n in &normals {
        assert!((dot(*n, *n) - 1.0).abs() < 1e-5, "not unit: {n:?}");
    }
    let acc = orientation_accuracy(&normals, gt.normals().unwrap());
    eprintln!("bunny_clean orientation accuracy {:.4}%", 100.0 * acc);
    assert!(acc >= 0.995, "orientation accuracy {:.4} < 0.995", acc);

    // The mesh at the default (automatic) resolution.
    let mesh = s.polygonize().unwrap();
    check_watertight(mesh.vertices(), mesh.triangles()).unwrap();
    eprintln!("bunny mesh {} vertices, {} triangles, watertight", mesh.vertex_count(), mesh.triangle_count());
    assert!(signed_volume(mesh.vertices(), mesh.triangles()) > 0.0, "mesh is inside out");
    assert!(mesh.triangle_count() > 10_000);
    assert_eq!(mesh.normals().unwrap().len(), mesh.vertex_count());
    assert!(s.stat(Stat::Resolution).unwrap() >= 8.0);

    // f vanishes on the mesh and is negative far outside.
    let diag = s.stat(Stat::BboxDiagonal).unwrap();
    let sample: Vec<[f64; 3]> = mesh.vertices().iter().step_by(97).copied().collect();
    let f = s.evaluate(&sample).unwrap();
    let worst = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(worst < 0.01 * diag, "|f| on the mesh up to {worst} (diagonal {diag})");
    let far = s.evaluate(&[[10.0 * diag, 0.0, 0.0]]).unwrap();
    assert!(far[0] < 0.0, "f far outside is {}", far[0]);
}

#[test]
fn sphere_sign_gradient_and_normals() {
    let pts = sphere(3000, [1.0, -2.0, 0.5], 2.0);
    let mut s = fitted(&pts);
    let (f, g) = s.evaluate_with_gradients(&[[1.0, -2.0, 0.5], [1.0, -2.0, 4.0], [3.0, -2.0, 0.5]]).unwrap();
    assert!(f[0] > 1.5 && f[1] < -1.0 && f[2].abs() < 0.01, "{f:?}");
    // ∇f points inward (f grows inside), so −∇f is the outward normal: +x at (3, -2, 0.5).
    assert!(g[2][0] < -0.5, "{:?}", g[2]);
    assert_eq!(s.gradients(&[[3.0, -2.0, 0.5]]).unwrap()[0], g[2]);
    for (p, n) in pts.iter().zip(s.normals().unwrap()) {
        let radial = [(p[0] - 1.0) / 2.0, (p[1] + 2.0) / 2.0, (p[2] - 0.5) / 2.0];
        assert!(dot(n, radial) > 0.95, "normal {n:?} at {p:?}");
    }
    let mut values = vec![0.0; 2];
    s.evaluate_into(&[[1.0, -2.0, 0.5], [9.0, 9.0, 9.0]], Some(&mut values), None).unwrap();
    assert_eq!(values[0], f[0]);
    assert!(s.evaluate(&[]).unwrap().is_empty());

    s.set_param(Param::Resolution, FAST_RESOLUTION).unwrap();
    let mesh = s.polygonize().unwrap();
    check_watertight(mesh.vertices(), mesh.triangles()).unwrap();
    let v = signed_volume(mesh.vertices(), mesh.triangles());
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
    assert!((v - exact).abs() < 0.05 * exact, "volume {v}, sphere {exact}");
    assert_eq!(s.stat(Stat::Resolution).unwrap(), FAST_RESOLUTION);
}

/// The checks above must be able to fail.
#[test]
fn mesh_checks_reject_open_and_flipped_meshes() {
    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let closed = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    check_watertight(&v, &closed).unwrap();
    assert!(signed_volume(&v, &closed) > 0.0);
    assert!(check_watertight(&v, &closed[..3]).is_err(), "open mesh passed");
    let mut flipped_one = closed;
    flipped_one[0] = [0, 1, 2];
    assert!(check_watertight(&v, &flipped_one).is_err(), "inconsistent winding passed");
    let inside_out: Vec<[u32; 3]> = closed.iter().map(|t| [t[0], t[2], t[1]]).collect();
    assert!(signed_volume(&v, &inside_out) < 0.0);
    let n = [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]];
    assert_eq!(orientation_accuracy(&n, &[[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), 0.5);
}

#[test]
fn f32_strided_and_packed_inputs_agree() {
    let pts = sphere(1500, [0.0, 0.0, 0.0], 1.0);
    let pts32: Vec<[f32; 3]> = pts.iter().map(|p| p.map(|c| c as f32)).collect();
    let exact: Vec<[f64; 3]> = pts32.iter().map(|p| p.map(f64::from)).collect();
    let reference = fitted(&exact).normals().unwrap();

    let mut s = Surface::new().unwrap();
    s.set_param(Param::Threads, 2.0).unwrap();
    s.set_points(&pts32).unwrap();
    s.fit().unwrap();
    s.orient().unwrap();
    assert_eq!(s.normals().unwrap(), reference, "f32 input differs from the same values as f64");

    // Interleaved x y z nx ny nz records (normals garbage here), f64 and f32.
    let records: Vec<f64> = exact.iter().flat_map(|p| [p[0], p[1], p[2], 7.0, 8.0, 9.0]).collect();
    s.set_points_strided(&records, 6).unwrap();
    assert_eq!(s.point_count(), 1500);
    s.fit().unwrap();
    s.orient().unwrap();
    assert_eq!(s.normals().unwrap(), reference, "strided f64 input");
    s.set_points_strided(&records[..records.len() - 3], 6).unwrap(); // last record without its tail
    assert_eq!(s.point_count(), 1500);
    let records32: Vec<f32> = records.iter().map(|&c| c as f32).collect();
    s.set_points_strided(&records32, 6).unwrap();
    s.fit().unwrap();
    s.orient().unwrap();
    assert_eq!(s.normals().unwrap(), reference, "strided f32 input");
}

#[test]
fn input_normals_drive_the_orientation() {
    let cloud = Points::read(test_data().join("clouds/elephant_sparse5k_gt.ply")).unwrap();
    let truth = cloud.normals().unwrap();
    let mut s = Surface::new().unwrap();
    s.set_param(Param::Threads, 2.0).unwrap();
    s.set_points(cloud.positions()).unwrap();
    // Inward normals: the surface must follow them and come out inside out.
    let inward: Vec<[f64; 3]> = truth.iter().map(|n| n.map(|c| -3.0 * c)).collect();
    s.set_normals(&inward).unwrap();
    s.fit().unwrap();
    s.orient().unwrap();
    assert!(orientation_accuracy(&s.normals().unwrap(), truth) < 0.01);
    // Outward normals through the strided path (records of x y z nx ny nz, as f32).
    let records: Vec<f32> = cloud
        .positions()
        .iter()
        .zip(truth)
        .flat_map(|(p, n)| [p[0], p[1], p[2], n[0], n[1], n[2]].map(|c| c as f32))
        .collect();
    s.set_normals_strided(&records[3..], 6).unwrap();
    s.orient().unwrap();
    assert!(orientation_accuracy(&s.normals().unwrap(), truth) > 0.99);
}

#[test]
fn files_round_trip() {
    let pts = sphere(800, [0.0, 0.0, 0.0], 1.0);
    let mut s = fitted(&pts);
    s.set_param(Param::Resolution, 16.0).unwrap();
    let mesh = s.polygonize().unwrap();
    for ext in ["ply", "obj", "off"] {
        let path = temp_path("files_round_trip", &format!("mesh.{ext}"));
        mesh.write(&path).unwrap();
        let back = Points::read(&path).unwrap();
        assert_eq!(back.len(), mesh.vertex_count(), "{ext}");
        if ext == "ply" {
            assert_eq!(back.positions(), mesh.vertices(), "binary PLY keeps doubles exactly");
        }
    }
    // Mesh::new copies caller arrays; it has no normals.
    let copy = Mesh::new(mesh.vertices(), mesh.triangles()).unwrap();
    assert_eq!(copy.vertices(), mesh.vertices());
    assert_eq!(copy.triangles(), mesh.triangles());
    assert!(copy.normals().is_none());
    let empty = Mesh::new(&[], &[]).unwrap();
    assert_eq!((empty.vertices().len(), empty.triangles().len()), (0, 0));

    // Points with normals through .ply and .xyz.
    let normals = s.normals().unwrap();
    let oriented = Points::new(&pts, Some(&normals)).unwrap();
    for ext in ["ply", "xyz"] {
        let path = temp_path("files_round_trip", &format!("points.{ext}"));
        oriented.write(&path).unwrap();
        let back = Points::read(&path).unwrap();
        assert_eq!(back.len(), pts.len());
        let n = back.normals().expect("normals written");
        assert!(n.iter().zip(&normals).all(|(a, b)| dot(*a, *b) > 0.999), "{ext}");
    }
    remove_temp_dir("files_round_trip");
}

#[test]
fn reconstruct_convenience_and_version() {
    let mesh =
        gmpu::reconstruct(&sphere(1000, [0.0; 3], 1.0), &[(Param::Resolution, 16.0), (Param::Threads, 1.0)]).unwrap();
    check_watertight(mesh.vertices(), mesh.triangles()).unwrap();
    assert_eq!(gmpu::abi_version(), gmpu::sys::GMPU_ABI_VERSION);
    assert_eq!(gmpu::version_number(), gmpu::sys::GMPU_VERSION_NUMBER);
    let s = gmpu::sys::GMPU_VERSION_NUMBER;
    assert_eq!(gmpu::version(), format!("{}.{}.{}", s / 10000, s / 100 % 100, s % 100));
}
