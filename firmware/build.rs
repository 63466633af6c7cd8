//! Links the firmware images with the workspace's root `memory.x` (the STM32F411CE map, which
//! QEMU's netduinoplus2 shares), and defmt's linker script for the Black Pill image.
use std::path::PathBuf;

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").unwrap()).join("..");
    let root = root.canonicalize().unwrap_or(root);
    let target = std::env::var("TARGET").unwrap_or_default();
    println!("cargo:rerun-if-changed={}", root.join("memory.x").display());
    if !target.starts_with("thumb") {
        return; // host build of the library (unit tests): no linker scripts
    }
    println!("cargo:rustc-link-search={}", root.display());
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    if std::env::var_os("CARGO_FEATURE_BLACKPILL").is_some() {
        println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    }
}
