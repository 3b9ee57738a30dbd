//! `--params base` without a grouping file: the symbolic method's grouping equals the
//! chapter's Table 10.2 grouping written by hand (tests/codegen_data/sr400_base.rs).

use robodyn::codegen::BaseParameters;
use robodyn::Expr;

mod sr400_base {
    include!("codegen_data/sr400_base.rs");
}

#[test]
fn sr400_symbolic_grouping_is_table_10_2() {
    let desc = robodyn::io::load_description(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/sr400.toml"
    )))
    .unwrap();
    let auto = BaseParameters::symbolic(&desc, true, false).unwrap();
    let hand = sr400_base::table_10_2();
    let mut names_auto: Vec<&str> = auto.grouped.iter().map(|g| g.name.as_str()).collect();
    let mut names_hand: Vec<&str> = hand.grouped.iter().map(|g| g.name.as_str()).collect();
    names_auto.sort();
    names_hand.sort();
    assert_eq!(names_auto, names_hand);
    for h in &hand.grouped {
        let a = auto.grouped.iter().find(|g| g.name == h.name).unwrap();
        assert_eq!(a.replaces, h.replaces, "{}", h.name);
        let diff = (a.expr.clone() - h.expr.clone()).expand();
        assert!(
            diff.is_zero(),
            "{}: {} vs {} (difference {diff})",
            h.name,
            a.expr,
            h.expr
        );
    }
    // every parameter the hand list sets to zero is zero here too; the automatic list also zeroes
    // the drive parameters that are not in the model (friction, rotors of passive joints)
    for z in &hand.zero {
        assert!(auto.zero.contains(z), "{z} should be zero");
    }
    for z in &auto.zero {
        assert!(
            hand.zero.contains(z)
                || z.starts_with("FS")
                || z.starts_with("FV")
                || z.starts_with("IA"),
            "{z} is zero only in the automatic list"
        );
    }
    // sanity: a grouped expression is not its own symbol
    assert!(auto
        .grouped
        .iter()
        .all(|g| g.expr != Expr::symbol(&g.replaces)));
}
