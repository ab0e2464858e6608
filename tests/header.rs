//! The committed C header `include/fricont.h` must be what cbindgen (the version pinned in
//! `Cargo.toml`) generates from `src/ffi/` with `cbindgen.toml`. A stale header fails this
//! test; `UPDATE_HEADER=1 cargo test --release --test header` (or `scripts/gen-header.sh`)
//! rewrites it.

use std::path::Path;

fn generate() -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml"))
        .expect("cbindgen.toml is readable and valid");
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/ffi/mod.rs"))
        .generate()
        .expect("cbindgen generates the header from src/ffi/");
    let mut out = Vec::new();
    bindings.write(&mut out);
    String::from_utf8(out).expect("the header is UTF-8")
}

#[test]
fn committed_header_is_fresh() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("include/fricont.h");
    let fresh = generate();
    if std::env::var_os("UPDATE_HEADER").is_some_and(|v| v == "1") {
        std::fs::write(&path, &fresh).expect("write include/fricont.h");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != fresh {
        let first = committed
            .lines()
            .zip(fresh.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| committed.lines().count().min(fresh.lines().count()));
        panic!(
            "include/fricont.h is stale (first difference at line {}): run scripts/gen-header.sh \
             (UPDATE_HEADER=1 cargo test --release --test header) and commit the result",
            first + 1
        );
    }
}

#[test]
fn header_declares_the_versions_of_cargo_toml() {
    let fresh = generate();
    for (name, value) in [
        ("FRICONT_VERSION_MAJOR", env!("CARGO_PKG_VERSION_MAJOR")),
        ("FRICONT_VERSION_MINOR", env!("CARGO_PKG_VERSION_MINOR")),
        ("FRICONT_VERSION_PATCH", env!("CARGO_PKG_VERSION_PATCH")),
    ] {
        let line = format!("#define {name} {value}");
        assert!(
            fresh.lines().any(|l| l.trim() == line),
            "the header lacks `{line}`: update src/ffi/status.rs to the version in Cargo.toml"
        );
    }
}
