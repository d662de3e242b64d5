//! The wasm tests, run in headless Node by wasm-bindgen-test-runner:
//! `cargo test --release --target wasm32-unknown-unknown --test wasm` (see scripts/test).
//! One binary: each wasm test binary is a whole-program optimised build of the library, and
//! two of them took twice the build time.
#![cfg(target_arch = "wasm32")]

mod wasm_api;
mod wasm_verify;
