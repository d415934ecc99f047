//! internal: use tricept-ident. No library: `tests/seven_steps.rs` is a downstream program written only
//! from `tricept-ident`'s documentation (the README, the crate docs and
//! `cargo doc`), run by `cargo test --workspace` so that the documented
//! way to use the door keeps working. It uses door paths only
//! (`tricept_ident::...`) and no internal crate.
