//! The generated sources included by `benches/generated.rs` are up to date with the generator.
//! Regenerate with `ROBODYN_BLESS=1 cargo test -p robodyn --test codegen_bench_sources`.

mod robots {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/generated/robots.rs"
    ));
}

#[test]
fn bench_sources_are_current() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/generated");
    for (file, desc, name) in [
        ("sr400_idm.rs", robots::sr400_description(), "sr400_idm"),
        ("rx90_idm.rs", robots::rx90_description(), "rx90_idm"),
    ] {
        let fresh = robots::bench_source(&desc, name);
        let path = dir.join(file);
        if std::env::var_os("ROBODYN_BLESS").is_some() {
            std::fs::write(&path, &fresh).unwrap();
        }
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        if committed != fresh {
            std::fs::write(std::env::temp_dir().join(file), &fresh).unwrap();
        }
        assert!(
            committed == fresh,
            "{} is stale: regenerate with ROBODYN_BLESS=1 cargo test -p robodyn --test codegen_bench_sources",
            path.display()
        );
    }
}
