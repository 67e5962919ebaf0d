//! The checked-in C header is what cbindgen makes of src/lib.rs today.

#[test]
fn header_is_current() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let config = cbindgen::Config::from_file(format!("{dir}/cbindgen.toml")).unwrap();
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(dir)
        .with_config(config)
        .generate()
        .expect("cbindgen")
        .write(&mut generated);
    let path = format!("{dir}/include/verne_kins.h");
    if std::env::var_os("VERNE_UPDATE_HEADER").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let current = std::fs::read(&path).unwrap_or_default();
    assert!(
        current == generated,
        "include/verne_kins.h is not what cbindgen makes of src/lib.rs: run \
         VERNE_UPDATE_HEADER=1 cargo test -p verne-kins --test header"
    );
}
