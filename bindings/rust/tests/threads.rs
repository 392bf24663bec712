//! The header's thread-safety contract as types, and concurrent evaluation after orient
//! giving exactly the single-threaded results.
mod common;

use common::*;
use gmpu::{Mesh, Param, Points, Stat, Surface};

fn assert_send<T: Send>() {}
fn assert_sync<T: Sync>() {}

/// Compiles only if `T` is NOT Sync (two candidate impls become ambiguous otherwise).
macro_rules! assert_not_sync {
    ($t:ty) => {{
        trait AmbiguousIfSync<A> {
            fn check() {}
        }
        impl<T: ?Sized> AmbiguousIfSync<()> for T {}
        #[allow(dead_code)]
        struct IsSync;
        impl<T: ?Sized + Sync> AmbiguousIfSync<IsSync> for T {}
        <$t as AmbiguousIfSync<_>>::check()
    }};
}

#[test]
fn marker_traits_follow_the_header() {
    assert_send::<Surface>();
    assert_sync::<Surface>();
    assert_send::<Mesh>();
    assert_send::<Points>();
    assert_send::<gmpu::Error>();
    assert_sync::<gmpu::Error>();
    assert_not_sync!(Mesh);
    assert_not_sync!(Points);
    assert_not_sync!(gmpu::sys::gmpu_surface);
}

#[test]
fn concurrent_evaluate_equals_single_threaded() {
    let cloud = Points::read(sample()).unwrap();
    // A surface is Send: build it on another thread and bring it back.
    let positions = cloud.positions().to_vec();
    let s = std::thread::spawn(move || {
        let mut s = Surface::new().unwrap();
        s.set_param(Param::Threads, 2.0).unwrap();
        s.set_points(&positions).unwrap();
        s.fit().unwrap();
        s.orient().unwrap();
        s
    })
    .join()
    .unwrap();

    // Queries: a 16³ grid over the padded bounding box and the input points themselves.
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in cloud.positions() {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let n = 16;
    let mut queries = Vec::new();
    for i in 0..n * n * n {
        let t = [i % n, i / n % n, i / (n * n)].map(|k| (k as f64 + 0.5) / n as f64 * 1.2 - 0.1);
        queries.push([0, 1, 2].map(|d| lo[d] + t[d] * (hi[d] - lo[d])));
    }
    queries.extend(cloud.positions().iter().step_by(7));

    let (values, gradients) = s.evaluate_with_gradients(&queries).unwrap();
    let normals = s.normals().unwrap();
    assert!(values.iter().any(|&v| v > 0.0) && values.iter().any(|&v| v < 0.0), "grid straddles the surface");

    let s = &s; // &Surface is shared by the scoped threads: Sync
    std::thread::scope(|scope| {
        let workers: Vec<_> = (0..4)
            .map(|w| {
                let queries = &queries;
                scope.spawn(move || {
                    // Whole batch, per-point calls on a stride, and the other const calls.
                    let mut out = Vec::new();
                    for _ in 0..2 {
                        out.push(s.evaluate_with_gradients(queries).unwrap());
                    }
                    let singles: Vec<(usize, f64)> = (w..queries.len())
                        .step_by(37)
                        .map(|i| (i, s.evaluate(&queries[i..i + 1]).unwrap()[0]))
                        .collect();
                    let normals = s.normals().unwrap();
                    let stat = s.stat(Stat::Leaves).unwrap();
                    let param = s.param(Param::Threads).unwrap();
                    (out, singles, normals, stat, param, s.point_count())
                })
            })
            .collect();
        for worker in workers {
            let (out, singles, n, stat, param, count) = worker.join().unwrap();
            for (v, g) in out {
                assert!(v == values, "concurrent values differ from single-threaded");
                assert!(g == gradients, "concurrent gradients differ from single-threaded");
            }
            for (i, v) in singles {
                assert_eq!(v, values[i], "query {i}");
            }
            assert!(n == normals);
            assert_eq!(stat, s.stat(Stat::Leaves).unwrap());
            assert_eq!(param, 2.0);
            assert_eq!(count, 35_000);
        }
    });
}
