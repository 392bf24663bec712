//! Mesh operations through the safe API: `Mesh::simplify` keeps a closed mesh of the same
//! topology within its triangle target; `Mesh::trim` needs a polygonized mesh's confidence.
mod common;

use common::*;
use gmpu::{Mesh, Status, Surface};

fn polygonized(points: &[[f64; 3]]) -> Mesh {
    let mut s = Surface::new().unwrap();
    s.set_points(points).unwrap();
    s.fit().unwrap();
    s.orient().unwrap();
    s.polygonize().unwrap()
}

fn euler_characteristic(m: &Mesh) -> i64 {
    let mut edges: Vec<(u32, u32)> = m
        .triangles()
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    m.vertex_count() as i64 - edges.len() as i64 + m.triangle_count() as i64
}

#[test]
fn simplify_keeps_a_closed_sphere_within_the_target() {
    let mesh = polygonized(&sphere(3000, [0.0, 0.0, 0.0], 1.0));
    assert_eq!(mesh.confidence().unwrap().len(), mesh.vertex_count());
    let target = mesh.triangle_count() / 10;
    let small = mesh.simplify(target, 0.02).unwrap();
    assert!(small.triangle_count() <= target);
    check_watertight(small.vertices(), small.triangles()).unwrap();
    assert_eq!(euler_characteristic(&small), 2);
    assert!(small.confidence().is_some());
    for n in small.normals().unwrap() {
        assert!((dot(*n, *n) - 1.0).abs() < 1e-9);
    }
}

#[test]
fn simplify_and_trim_refuse_bad_arguments() {
    let mesh = polygonized(&sphere(1500, [0.0, 0.0, 0.0], 1.0));
    assert_eq!(mesh.simplify(10, f64::NAN).unwrap_err().status(), Status::InvalidArgument);
    assert_eq!(mesh.trim(0.0).unwrap_err().status(), Status::InvalidArgument);
    let rebuilt = Mesh::new(mesh.vertices(), mesh.triangles()).unwrap();
    assert!(rebuilt.confidence().is_none());
    assert_eq!(rebuilt.trim(3.0).unwrap_err().status(), Status::InvalidArgument);
    // A closed sphere is fully supported: trimming keeps it whole.
    assert_eq!(mesh.trim(3.0).unwrap().triangle_count(), mesh.triangle_count());
}

#[test]
fn a_mesh_from_arrays_keeps_normals_confidence_and_colours_when_written() {
    let made = polygonized(&sphere(1500, [0.0; 3], 1.0));
    let colours: Vec<[u8; 3]> = made.vertices().iter().map(|v| if v[0] > 0.0 { [255, 0, 0] } else { [0, 0, 255] }).collect();
    let copy =
        Mesh::with_attributes(made.vertices(), made.triangles(), made.normals(), made.confidence(), Some(&colours)).unwrap();
    assert_eq!(copy.normals(), made.normals());
    assert_eq!(copy.colors(), Some(&colours[..]));
    let path = temp_path("mesh_attributes", "copy.ply");
    copy.write(&path).unwrap();
    let back = gmpu::Points::read(&path).unwrap();
    assert_eq!(back.normals(), made.normals());
    assert_eq!(back.colors(), Some(&colours[..]));
    // The colours of a mesh from the nearest coloured point.
    let plain = Mesh::new(made.vertices(), made.triangles()).unwrap();
    assert_eq!(plain.colors(), None);
    assert_eq!(plain.color_from(&back).unwrap().colors(), Some(&colours[..]));
    assert_eq!(plain.color_from(&gmpu::Points::new(made.vertices(), None).unwrap()).unwrap_err().status(), Status::InvalidArgument);
    let e = Mesh::with_attributes(made.vertices(), made.triangles(), None, Some(&[1.0]), None).unwrap_err();
    assert_eq!(e.status(), Status::InvalidInput);
    assert!(e.message().contains("1 confidence given"), "{}", e.message());
    remove_temp_dir("mesh_attributes");
}

#[test]
fn points_read_with_reports_progress_cancels_and_keeps_the_budget() {
    use gmpu::{ControlFlow, Points, Stage};
    use std::sync::{Arc, Mutex};
    let path = temp_path("points_read_with", "big.xyz");
    let text: String = sphere(30000, [0.0; 3], 1.0).iter().map(|p| format!("{} {} {}\n", p[0], p[1], p[2])).collect();
    std::fs::write(&path, text).unwrap();
    let seen = Arc::new(Mutex::new(Vec::new()));
    let log = Arc::clone(&seen);
    let points = Points::read_with(&path, 0.0, move |stage, f| {
        log.lock().unwrap().push((stage, f));
        ControlFlow::Continue(())
    })
    .unwrap();
    assert_eq!(points.len(), 30000);
    let seen = seen.lock().unwrap();
    assert!(seen.iter().all(|(stage, _)| *stage == Stage::Read) && seen.last().unwrap().1 == 1.0);
    let e = Points::read_with(&path, 0.0, |_, _| ControlFlow::Break(())).unwrap_err();
    assert_eq!(e.status(), Status::Cancelled);
    let e = Points::read_with(&path, 1e6, |_, _| ControlFlow::Continue(())).unwrap_err();
    assert_eq!(e.status(), Status::LimitExceeded);
    let caught = std::panic::catch_unwind(|| Points::read_with(&path, 0.0, |_, _| panic!("from the callback")));
    assert!(caught.is_err());
    remove_temp_dir("points_read_with");
}
