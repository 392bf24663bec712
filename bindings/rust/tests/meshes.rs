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
