//! The binding's parameters are the library's: `Param` covers exactly the keys of
//! `gmpu_param_info`, under the library's names, and what `ParamInfo` says (default, range,
//! integer) is what a surface does.
mod common;
use gmpu::{param_count, param_table, Param, Surface};

#[test]
fn param_enum_is_the_librarys_table() {
    let table = param_table();
    assert_eq!(table.len() as u32, param_count());
    assert_eq!(table.iter().map(|p| p.key).collect::<Vec<_>>(), (1..=param_count()).collect::<Vec<_>>());
    assert_eq!(Param::ALL.len(), table.len(), "a library key has no Param variant (or the reverse)");
    for (p, info) in Param::ALL.iter().zip(&table) {
        assert_eq!(p.to_raw(), info.key, "{p:?}");
        assert_eq!(common::screaming(&format!("{p:?}")), info.name.to_uppercase(), "{p:?}");
        assert_eq!(Param::from_name(info.name), Some(*p));
        assert_eq!(Param::from_name(&format!("GMPU_PARAM_{}", info.name.to_uppercase())), Some(*p));
        assert!(info.doc.len() > 10 && info.min < info.max, "{info:?}");
    }
    assert_eq!(Param::from_name("no_such_parameter"), None);
    assert!(gmpu::param_info(0).is_err() && gmpu::param_info(param_count() + 1).is_err());
}

#[test]
fn info_is_what_a_surface_does() {
    for p in Param::ALL {
        let info = p.info();
        let mut s = Surface::new().unwrap();
        assert_eq!(s.param(*p).unwrap(), info.default, "{p:?}");
        assert_eq!(s.set_param(*p, info.min).is_ok(), !info.min_exclusive, "{p:?} min");
        assert_eq!(s.set_param(*p, info.max).is_ok(), !info.max_exclusive, "{p:?} max");
        assert!(s.set_param(*p, info.max * 2.0 + 1.0).is_err(), "{p:?} beyond max");
        if info.integer && info.max > 2.0 {
            assert!(s.set_param(*p, 1.5).is_err(), "{p:?} fraction");
        }
    }
}

#[test]
fn typed_builder_sets_every_parameter_and_is_checked_by_the_library_table() {
    use gmpu::{Params, Status};
    let all = Params::new()
        .error(0.003)
        .max_depth(8)
        .min_points(20)
        .support_scale(0.9)
        .sharp_features(true)
        .resolution(48)
        .level(3)
        .threads(2)
        .max_cells(1e6)
        .max_triangles(1e7)
        .noise_scale(1.5)
        .max_memory(1e9)
        .remove_outliers(false)
        .surface(1);
    let mut keys: Vec<u32> = all.iter().map(|(k, _)| k.to_raw()).collect();
    keys.sort_unstable();
    assert_eq!(keys, Param::ALL.iter().map(|p| p.to_raw()).collect::<Vec<_>>(), "a Param without a setter");
    let all = all.validated().unwrap();
    let mut s = Surface::new().unwrap();
    s.apply(&all).unwrap();
    for &(key, value) in all.iter() {
        assert_eq!(s.param(key).unwrap(), value, "{key:?}");
    }
    // A later value replaces an earlier one; a Params is the slice reconstruct takes.
    let p = Params::new().max_depth(6).max_depth(7).resolution(24);
    assert_eq!(&*p, &[(Param::MaxDepth, 7.0), (Param::Resolution, 24.0)]);
    let mesh = gmpu::reconstruct(&common::sphere(1500, [0.0; 3], 1.0), &p).unwrap();
    assert!(mesh.triangle_count() > 100);

    // Out of range, per the library's table: max_depth is 1..16, error is (0, 1), and
    // integer parameters take whole numbers only.
    for bad in [Params::new().max_depth(17), Params::new().error(0.0), Params::new().set(Param::Level, 2.5)] {
        let e = bad.validated().unwrap_err();
        assert_eq!(e.status(), Status::InvalidArgument);
        assert!(e.message().contains("out of range"), "{}", e.message());
    }
    let e = Params::new().max_depth(17).validated().unwrap_err();
    assert!(e.message().contains("max_depth = 17") && e.message().contains("[1, 16]"), "{}", e.message());
    let e = Params::new().error(1.0).validated().unwrap_err();
    assert!(e.message().contains("(0, 1)"), "{}", e.message());
}
