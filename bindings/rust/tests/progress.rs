//! Progress reports, cancellation, and panics in the progress closure.
mod common;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use common::*;
use gmpu::{ControlFlow, Param, Points, Stage, Stat, Status, Surface};

fn bunny_surface() -> Surface {
    let cloud = Points::read(sample()).unwrap();
    let mut s = Surface::new().unwrap();
    s.set_param(Param::Threads, 2.0).unwrap();
    s.set_points(cloud.positions()).unwrap();
    s
}

#[test]
fn reports_every_stage_from_0_to_1_on_the_calling_thread() {
    let mut s = bunny_surface();
    s.set_param(Param::Resolution, 40.0).unwrap();
    let log = Arc::new(Mutex::new(Vec::new()));
    let sink = Arc::clone(&log);
    s.set_progress(move |stage, fraction| {
        sink.lock().unwrap().push((stage, fraction, std::thread::current().id()));
        ControlFlow::Continue(())
    })
    .unwrap();
    s.fit().unwrap();
    s.orient().unwrap();
    s.polygonize().unwrap();

    let log = log.lock().unwrap();
    let me = std::thread::current().id();
    assert!(log.iter().all(|(_, _, t)| *t == me), "a report came from another thread");
    let mut order = Vec::new();
    for (stage, _, _) in log.iter() {
        if order.last() != Some(stage) {
            order.push(*stage);
        }
    }
    assert_eq!(order, [Stage::Fit, Stage::Orient, Stage::Polygonize]);
    for stage in order {
        let f: Vec<f64> = log.iter().filter(|r| r.0 == stage).map(|r| r.1).collect();
        assert_eq!(f.first(), Some(&0.0), "{stage:?} starts at 0: {f:?}");
        assert_eq!(f.last(), Some(&1.0), "{stage:?} ends at 1: {f:?}");
        assert!(f.windows(2).all(|w| w[0] <= w[1]), "{stage:?} not monotonic: {f:?}");
        assert!(f.iter().all(|x| (0.0..=1.0).contains(x)), "{f:?}");
    }
}

#[test]
fn cancelling_each_stage_keeps_the_stages_before() {
    let mut s = bunny_surface();
    s.set_param(Param::Resolution, 40.0).unwrap();
    let cancel_in = |stage: Stage| {
        move |st: Stage, fraction: f64| {
            if st == stage && fraction > 0.0 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        }
    };
    s.set_progress(cancel_in(Stage::Fit)).unwrap();
    let e = s.fit().unwrap_err();
    assert_eq!(e.status(), Status::Cancelled, "{e}");
    assert_eq!(s.point_count(), 35_000);
    assert_eq!(s.orient().unwrap_err().status(), Status::WrongOrder, "a cancelled fit is no fit");

    s.set_progress(cancel_in(Stage::Orient)).unwrap();
    s.fit().unwrap();
    let cells = s.stat(Stat::Cells).unwrap();
    let fit_seconds = s.stat(Stat::FitSeconds).unwrap();
    assert_eq!(s.orient().unwrap_err().status(), Status::Cancelled);
    assert_eq!(s.evaluate(&[[0.0; 3]]).unwrap_err().status(), Status::WrongOrder);

    s.set_progress(cancel_in(Stage::Polygonize)).unwrap();
    s.orient().unwrap(); // on the kept fit: not refitted
    assert_eq!(s.stat(Stat::Cells).unwrap(), cells);
    assert_eq!(s.stat(Stat::FitSeconds).unwrap(), fit_seconds);
    assert_eq!(s.polygonize().unwrap_err().status(), Status::Cancelled);
    assert!(s.evaluate(&[[0.0; 3]]).is_ok(), "orientation kept after a cancelled polygonize");

    s.clear_progress().unwrap();
    let mesh = s.polygonize().unwrap();
    check_watertight(mesh.vertices(), mesh.triangles()).unwrap();
}

#[test]
fn cancellation_is_prompt() {
    let mut s = bunny_surface();
    s.fit().unwrap();
    s.orient().unwrap();
    s.set_param(Param::Resolution, 160.0).unwrap(); // seconds of work
    let asked = Arc::new(Mutex::new(None::<Instant>));
    let at = Arc::clone(&asked);
    s.set_progress(move |_, fraction| {
        if fraction > 0.0 {
            at.lock().unwrap().get_or_insert_with(Instant::now);
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    let start = Instant::now();
    assert_eq!(s.polygonize().unwrap_err().status(), Status::Cancelled);
    let asked = asked.lock().unwrap().expect("the callback was never called with a fraction > 0");
    let latency = asked.elapsed();
    // The header promises 100 ms; allow for a loaded 2-core machine.
    assert!(latency < Duration::from_millis(1000), "stopped {latency:?} after the cancel");
    assert!(asked - start < Duration::from_secs(5), "first report after {:?}", asked - start);
}

#[test]
fn a_panic_in_the_closure_cancels_and_is_resumed_after_the_call() {
    let mut s = bunny_surface();
    s.fit().unwrap();
    let calls = Arc::new(AtomicUsize::new(0));
    let counter = Arc::clone(&calls);
    s.set_progress(move |stage, _| {
        counter.fetch_add(1, Ordering::SeqCst);
        if stage == Stage::Orient {
            panic!("progress closure exploded");
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    let payload = catch_unwind(AssertUnwindSafe(|| s.orient())).expect_err("the panic was swallowed");
    let text = payload.downcast_ref::<&str>().copied().unwrap_or_default();
    assert_eq!(text, "progress closure exploded");
    assert_eq!(calls.load(Ordering::SeqCst), 1, "the closure was called again after it panicked");
    assert!(s.last_error().contains("GMPU_ERROR_CANCELLED"), "C saw a cancel: {:?}", s.last_error());
    assert_eq!(s.evaluate(&[[0.0; 3]]).unwrap_err().status(), Status::WrongOrder);

    // The surface is intact: with a well-behaved closure, orient works on the kept fit.
    s.set_progress(|_, _| ControlFlow::Continue(())).unwrap();
    s.orient().unwrap();
    assert!(s.evaluate(&[[0.0; 3]]).is_ok());

    // A panic during fit, then the surface is dropped while holding the panicked state.
    let mut t = bunny_surface();
    t.set_progress(|_, _| panic!("again")).unwrap();
    assert!(catch_unwind(AssertUnwindSafe(|| t.fit())).is_err());
    drop(t);
}

/// The closure is dropped when replaced, cleared, or with the surface, exactly once.
#[test]
fn closures_are_dropped_once() {
    struct Guard(Arc<AtomicUsize>);
    impl Drop for Guard {
        fn drop(&mut self) {
            self.0.fetch_add(1, Ordering::SeqCst);
        }
    }
    let drops = Arc::new(AtomicUsize::new(0));
    let closure = |d: &Arc<AtomicUsize>| {
        let g = Guard(Arc::clone(d));
        move |_: Stage, _: f64| {
            let _ = &g;
            ControlFlow::Continue(())
        }
    };
    let mut s = Surface::new().unwrap();
    s.set_progress(closure(&drops)).unwrap();
    assert_eq!(drops.load(Ordering::SeqCst), 0);
    s.set_progress(closure(&drops)).unwrap();
    assert_eq!(drops.load(Ordering::SeqCst), 1, "replaced closure dropped");
    s.clear_progress().unwrap();
    assert_eq!(drops.load(Ordering::SeqCst), 2, "cleared closure dropped");
    s.clear_progress().unwrap();
    s.set_progress(closure(&drops)).unwrap();
    drop(s);
    assert_eq!(drops.load(Ordering::SeqCst), 3, "closure dropped with the surface");
}

/// A cancel (or a panic) on the final report, fraction 1, still cancels the stage.
#[test]
fn the_final_report_can_cancel() {
    let mut s = Surface::new().unwrap();
    s.set_param(Param::Threads, 2.0).unwrap();
    s.set_param(Param::Resolution, 24.0).unwrap();
    s.set_points(&sphere(2000, [0.0; 3], 1.0)).unwrap();
    let at_end = |stage: Stage| {
        move |st: Stage, fraction: f64| {
            if st == stage && fraction >= 1.0 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        }
    };
    s.set_progress(at_end(Stage::Fit)).unwrap();
    assert_eq!(s.fit().unwrap_err().status(), Status::Cancelled);
    assert_eq!(s.stat(Stat::Cells).unwrap(), 0.0, "a cancelled fit keeps no octree");
    s.set_progress(at_end(Stage::Orient)).unwrap();
    s.fit().unwrap();
    assert_eq!(s.orient().unwrap_err().status(), Status::Cancelled);
    assert_eq!(s.evaluate(&[[0.0; 3]]).unwrap_err().status(), Status::WrongOrder);
    s.set_progress(at_end(Stage::Polygonize)).unwrap();
    s.orient().unwrap();
    assert_eq!(s.polygonize().unwrap_err().status(), Status::Cancelled);

    s.set_progress(|stage, fraction| {
        if stage == Stage::Polygonize && fraction >= 1.0 {
            panic!("at the very end");
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    assert!(catch_unwind(AssertUnwindSafe(|| s.polygonize())).is_err(), "the panic was swallowed");
    assert!(s.last_error().contains("GMPU_ERROR_CANCELLED"), "{:?}", s.last_error());
}
