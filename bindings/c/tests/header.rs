//! include/obbtree.h is what cbindgen makes of src/lib.rs now: a change to the API that is
//! not regenerated into the committed header fails here. Regenerate with
//! `OBBTREE_C_BLESS=1 cargo test --release -p obbtree-c --test header`.

use std::path::Path;

#[test]
fn the_committed_header_is_current() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config =
        cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).expect("cbindgen.toml reads");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut generated);
    let generated = String::from_utf8(generated).expect("UTF-8 header");
    let path = crate_dir.join("include/obbtree.h");
    if std::env::var_os("OBBTREE_C_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("header written");
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is stale: regenerate it with OBBTREE_C_BLESS=1 cargo test --release -p obbtree-c --test header",
        path.display()
    );
    // Every entry point of the source is declared.
    let source = std::fs::read_to_string(crate_dir.join("src/lib.rs")).expect("source");
    for line in source.lines() {
        if let Some(rest) = line.split("extern \"C\" fn ").nth(1) {
            let name = rest.split('(').next().unwrap_or_default();
            assert!(
                generated.contains(&format!("{name}(")),
                "{name} missing from the header"
            );
        }
    }
}
