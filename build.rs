//! Generates the PETSc bindings at build time against the system PETSc (see README, "Native stack").
//! MPI handle types are not generated: they come from rsmpi (`mpi::ffi`) so one communicator type
//! serves rsmpi, PETSc and HDF5.

use std::env;
use std::path::PathBuf;

#[path = "build/scene_reference.rs"]
mod scene_reference;

fn main() {
    println!("cargo:rerun-if-changed=src/petsc/wrapper.h");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=build/scene_reference.rs");
    let out_dir = PathBuf::from(env::var("OUT_DIR").expect("OUT_DIR"));
    let sources: Vec<String> = scene_reference::SOURCES
        .iter()
        .map(|p| {
            println!("cargo:rerun-if-changed={p}");
            std::fs::read_to_string(p).unwrap_or_else(|e| panic!("cannot read {p}: {e}"))
        })
        .collect();
    let reference = scene_reference::generate(&sources)
        .unwrap_or_else(|e| panic!("scene reference: the schema does not parse: {e}"));
    std::fs::write(out_dir.join("scene_reference.md"), reference)
        .expect("could not write the scene reference");
    let petsc = pkg_config::Config::new().probe("PETSc").expect(
        "PETSc not found by pkg-config: install the native stack (README, `.ci/install-native`)",
    );
    let mpi = pkg_config::Config::new()
        .cargo_metadata(false)
        .probe("ompi-c")
        .expect("OpenMPI (ompi-c) not found by pkg-config: install the native stack");
    let mut builder = bindgen::Builder::default()
        .header("src/petsc/wrapper.h")
        .allowlist_function("(Petsc|Vec|Mat|KSP|PC|SNES|IS)[A-Za-z_]*")
        .allowlist_var("PETSC_COMM_WORLD|PETSC_DECIDE|PETSC_DETERMINE|PETSC_DEFAULT")
        .allowlist_type("(Petsc|Vec|Mat|KSP|PC|SNES|IS|Insert)[A-Za-z_]*")
        .blocklist_type("MPI_.*|ompi_.*")
        .blocklist_function("MPI_.*|ompi_.*")
        .layout_tests(false)
        .derive_default(false)
        .generate_comments(false)
        .default_enum_style(bindgen::EnumVariation::Consts)
        .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()));
    for p in petsc.include_paths.iter().chain(mpi.include_paths.iter()) {
        builder = builder.clang_arg(format!("-I{}", p.display()));
    }
    let bindings = builder
        .generate()
        .expect("bindgen failed on the PETSc headers");
    let out = PathBuf::from(env::var("OUT_DIR").expect("OUT_DIR")).join("petsc_bindings.rs");
    bindings
        .write_to_file(out)
        .expect("could not write the PETSc bindings");
}
