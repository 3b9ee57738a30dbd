//! The generated sources included by `benches/generated.rs` are up to date with the generator.
//! Regenerate with `ROBODYN_BLESS=1 cargo test --release -p robodyn --test all -- codegen_bench_sources::`.

mod robots {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/generated/robots.rs"
    ));
}

#[test]
fn bench_sources_are_current() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/generated");
    use robodyn::codegen::ModelKind;
    for (file, desc, name, model) in [
        (
            "sr400_idm.rs",
            robots::sr400_description(),
            "sr400_idm",
            ModelKind::Idm,
        ),
        (
            "rx90_idm.rs",
            robots::rx90_description(),
            "rx90_idm",
            ModelKind::Idm,
        ),
        (
            "fivebar_closed.rs",
            robots::fivebar_description(),
            "fivebar_closed",
            ModelKind::Closed,
        ),
    ] {
        let fresh = robots::bench_source(&desc, name, model);
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
            "{} is stale: regenerate with ROBODYN_BLESS=1 cargo test --release -p robodyn --test all -- codegen_bench_sources::",
            path.display()
        );
    }
}
