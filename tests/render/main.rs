//! Render tests: compiled programs executed by the runtime on a GPU adapter
//! (lavapipe in CI), with pixel values checked against the reference kernel
//! of the same program.
//!
//! With `CI=true` a missing adapter fails every test; elsewhere the tests say
//! loudly that they were skipped.

mod harness;

mod errors;
mod modes;
mod sponza;

pub use harness::*;
