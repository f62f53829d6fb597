//! Placeholder, replaced once the target crate builds.
fn main() {}
