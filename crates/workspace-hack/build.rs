//! Empty: a package needs a build script for cargo to resolve its
//! `[build-dependencies]`, which unify the features of the host's proc-macro
//! dependencies (see src/lib.rs).
fn main() {}
