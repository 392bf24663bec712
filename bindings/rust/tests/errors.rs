//! Error paths: each returns the right Status with the C message, and leaves the surface
//! usable with its previous state.
mod common;

use common::*;
use gmpu::{Mesh, Param, Points, Stat, Status, Surface};

fn expect_err<T: std::fmt::Debug>(r: gmpu::Result<T>, status: Status, needle: &str) -> gmpu::Error {
    let e = r.expect_err("expected an error");
    eprintln!("{:?}: {}", e.status(), e.message());
    assert_eq!(e.status(), status, "message: {}", e.message());
    assert!(e.message().starts_with(status.name()), "message {:?} does not start with {}", e.message(), status.name());
    assert!(e.message().contains(needle), "message {:?} does not mention {needle:?}", e.message());
    assert_eq!(e.to_string(), e.message());
    e
}

#[test]
fn nan_coordinate_reports_its_index_and_keeps_previous_points() {
    let mut s = Surface::new().unwrap();
    let good = sphere(200, [0.0; 3], 1.0);
    s.set_points(&good).unwrap();
    let mut bad = sphere(300, [0.0; 3], 1.0);
    bad[137][1] = f64::NAN;
    let e = expect_err(s.set_points(&bad), Status::InvalidInput, "137");
    assert!(!e.message().contains("136") && !e.message().contains("138"), "{}", e.message());
    assert_eq!(s.point_count(), 200, "the previous points are kept");
    assert_eq!(s.last_error(), e.message(), "surface last_error");

    let mut bad32: Vec<[f32; 3]> = bad.iter().map(|p| p.map(|c| c as f32)).collect();
    bad32[137][1] = 0.0;
    bad32[251][2] = f32::INFINITY;
    expect_err(s.set_points(&bad32), Status::InvalidInput, "251");
    let mut flat: Vec<f64> = good.iter().flat_map(|p| [p[0], p[1], p[2], 0.0]).collect();
    flat[4 * 42] = f64::NEG_INFINITY;
    expect_err(s.set_points_strided(&flat, 4), Status::InvalidInput, "42");
    assert_eq!(s.point_count(), 200);
    s.fit().unwrap();
    s.orient().unwrap();
}

#[test]
fn too_few_and_degenerate_points() {
    let mut s = Surface::new().unwrap();
    let five = sphere(5, [0.0; 3], 1.0);
    expect_err(s.set_points(&five), Status::InvalidInput, "at least 15");
    expect_err(s.set_points::<f64>(&[]), Status::InvalidInput, "at least 15");
    // The minimum follows GMPU_PARAM_MIN_POINTS.
    s.set_param(Param::MinPoints, 6.0).unwrap();
    s.set_points(&sphere(6, [0.0; 3], 1.0)).unwrap();
    s.set_param(Param::MinPoints, 40.0).unwrap();
    expect_err(s.set_points(&sphere(39, [0.0; 3], 1.0)), Status::InvalidInput, "at least 40");

    let plane: Vec<[f64; 3]> = (0..400).map(|i| [(i % 20) as f64, (i / 20) as f64, 0.0]).collect();
    expect_err(s.set_points(&plane), Status::DegenerateInput, "coplanar");
    let same = vec![[1.0, 2.0, 3.0]; 100];
    expect_err(s.set_points(&same), Status::DegenerateInput, "identical");
}

#[test]
fn stages_in_the_wrong_order() {
    let mut s = Surface::new().unwrap();
    expect_err(s.fit(), Status::WrongOrder, "gmpu_surface_fit");
    expect_err(s.orient(), Status::WrongOrder, "gmpu_surface_orient");
    expect_err(s.polygonize(), Status::WrongOrder, "gmpu_surface_polygonize");
    expect_err(s.evaluate(&[[0.0; 3]]), Status::WrongOrder, "gmpu_surface_evaluate");
    expect_err(s.normals(), Status::WrongOrder, "");
    expect_err(s.set_normals(&[[1.0, 0.0, 0.0]]), Status::WrongOrder, "");
    s.set_points(&sphere(500, [0.0; 3], 1.0)).unwrap();
    expect_err(s.orient(), Status::WrongOrder, "gmpu_surface_fit");
    s.fit().unwrap();
    expect_err(s.evaluate(&[[0.0; 3]]), Status::WrongOrder, "orient");
    expect_err(s.polygonize(), Status::WrongOrder, "orient");
    expect_err(s.normals_at(&[0]), Status::WrongOrder, "gmpu_surface_copy_normals_at");
    s.orient().unwrap();
    assert!(s.evaluate(&[[0.0; 3]]).unwrap()[0] > 0.0);
    // The normals of chosen points are rows of every point's; a bad index is named.
    let all = s.normals().unwrap();
    assert_eq!(s.normals_at(&[499, 0, 7, 7]).unwrap(), vec![all[499], all[0], all[7], all[7]]);
    assert!(s.normals_at(&[]).unwrap().is_empty());
    expect_err(s.normals_at(&[1, 500]), Status::InvalidArgument, "indices[1] = 500 is not a point");
    expect_err(s.normals_at(&[usize::MAX]), Status::InvalidArgument, "indices[0] = -1");
    // Changing a fit parameter discards the fit (and so the orientation).
    s.set_param(Param::Error, 0.004).unwrap();
    expect_err(s.evaluate(&[[0.0; 3]]), Status::WrongOrder, "");
    // A stat before its stage is 0, not an error.
    assert_eq!(Surface::new().unwrap().stat(Stat::Cells).unwrap(), 0.0);
}

#[test]
fn bad_parameters_arguments_and_queries() {
    let mut s = Surface::new().unwrap();
    expect_err(s.set_param(Param::Error, 0.0), Status::InvalidArgument, "GMPU_PARAM_ERROR");
    expect_err(s.set_param(Param::MaxDepth, 17.0), Status::InvalidArgument, "GMPU_PARAM_MAX_DEPTH");
    expect_err(s.set_param(Param::MaxDepth, 2.5), Status::InvalidArgument, "");
    expect_err(s.set_param(Param::Resolution, 4.0), Status::InvalidArgument, "GMPU_PARAM_RESOLUTION");
    expect_err(s.set_param(Param::SupportScale, f64::NAN), Status::InvalidArgument, "");
    assert_eq!(s.param(Param::MaxDepth).unwrap(), 10.0, "a rejected value changes nothing");
    assert_eq!(s.param(Param::Error).unwrap(), 0.002);
    s.set_param(Param::Resolution, 64.0).unwrap();
    assert_eq!(s.param(Param::Resolution).unwrap(), 64.0);
    expect_err(s.set_params(&[(Param::Level, 3.0), (Param::Level, -1.0)]), Status::InvalidArgument, "");
    assert_eq!(s.param(Param::Level).unwrap(), 3.0);

    // Binding-side checks: strides and slice lengths Rust can see.
    let pts = sphere(300, [0.0; 3], 1.0);
    let flat: Vec<f64> = pts.iter().flatten().copied().collect();
    expect_err(s.set_points_strided(&flat, 2), Status::InvalidArgument, "stride");
    expect_err(s.set_points_strided(&flat, 0), Status::InvalidArgument, "stride");
    expect_err(s.set_points_strided(&flat[..flat.len() - 1], 3), Status::InvalidArgument, "whole number");
    s.set_points_strided(&flat, 3).unwrap();
    expect_err(s.set_normals(&pts[..299]), Status::InvalidInput, "299");
    let mut normals = pts.clone();
    normals[77] = [0.0; 3];
    expect_err(s.set_normals(&normals), Status::InvalidInput, "77");
    s.fit().unwrap();
    s.orient().unwrap();
    let mut queries = vec![[0.5; 3]; 10];
    queries[6][0] = f64::NAN;
    let mut values = vec![-7.0; 10];
    expect_err(s.evaluate_into(&queries, Some(&mut values), None), Status::InvalidInput, "6");
    assert!(values.iter().all(|&v| v == -7.0), "outputs untouched on failure");
    expect_err(s.evaluate_into(&queries[..2], None, None), Status::InvalidArgument, "");
    expect_err(s.evaluate_into(&queries, Some(&mut values[..3]), None), Status::InvalidArgument, "");
    expect_err(s.set_param(Param::MaxTriangles, 10.0).and_then(|_| s.polygonize()), Status::LimitExceeded, "");
}

#[test]
fn files_and_meshes() {
    expect_err(Points::read("/nonexistent/cloud.ply"), Status::Io, "/nonexistent/cloud.ply");
    expect_err(Points::read(sample().with_extension("stl")), Status::Unsupported, "");
    let garbage = temp_path("files_and_meshes", "garbage.ply");
    std::fs::write(&garbage, "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nend_header\n1\n").unwrap();
    expect_err(Points::read(&garbage), Status::Parse, "");
    expect_err(Points::read("nul\0byte.ply"), Status::InvalidArgument, "NUL");
    expect_err(Points::new(&[[0.0; 3]; 3], Some(&[[1.0, 0.0, 0.0]; 2])), Status::InvalidInput, "2 normals");

    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    expect_err(Mesh::new(&v, &[[0, 1, 3]]), Status::InvalidInput, "3");
    expect_err(Mesh::new(&[[0.0, f64::NAN, 0.0]], &[]), Status::InvalidInput, "");
    let mesh = Mesh::new(&v, &[[0, 1, 2]]).unwrap();
    expect_err(mesh.write(garbage.with_extension("wrl")), Status::Unsupported, "");
    expect_err(mesh.write("/nonexistent/dir/mesh.ply"), Status::Io, "");
    remove_temp_dir("files_and_meshes");
}

#[test]
fn status_round_trips() {
    for s in Status::ALL {
        assert_eq!(Status::from_raw(s.to_raw()), Some(s));
        assert!(s.name().starts_with("GMPU_ERROR_"), "{}", s.name());
    }
    assert_eq!(Status::from_raw(gmpu::sys::GMPU_OK), None);
    assert_eq!(Status::from_raw(999), Some(Status::Unknown(999)));
    assert_eq!(Status::Unknown(999).name(), "GMPU_UNKNOWN_STATUS");
}
