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
