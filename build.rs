//! Link scripts for the firmware image; the host build (the simulator) needs none.

fn main() {
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
        // memory.x sits in the package root, which is on the linker's search path as the
        // build script's output directory is not: copy it there for link.x to include.
        let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
        std::fs::copy("memory.x", out.join("memory.x")).expect("memory.x is readable");
        println!("cargo:rustc-link-search={}", out.display());
        println!("cargo:rustc-link-arg-bins=--nmagic");
        // Identical functions (generic copies that compile to the same code) are kept once. No
        // code here compares function addresses.
        println!("cargo:rustc-link-arg-bins=--icf=all");
        println!("cargo:rustc-link-arg-bins=-Tlink.x");
        println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    }
}
