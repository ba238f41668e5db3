//! Empty: it only lets `[build-dependencies]` in Cargo.toml name the
//! features the workspace's proc-macros share (see the comment there).
fn main() {}
