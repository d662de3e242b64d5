//! # tspath
//!
//! Five-axis finishing tool paths planned directly on T-spline and subdivision surfaces.
//!
//! Data flows one way:
//! bytes → [`io`] → [`tmesh::TMesh`] → [`surface::Surface`] → [`plan`] → [`plan::Toolpath`]
//! → [`machine`] (G-code). Every stage is a plain function of its inputs; [`wasm`] holds
//! handles to these values for JavaScript and is the only module with `#[wasm_bindgen]`.
//!
//! Units are millimetres everywhere inside.

// `!(x > 0.0)` is how numeric code rejects NaN along with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Index loops read like the formulas they implement (control nets, basis sums).
#![allow(clippy::needless_range_loop)]

#[cfg(not(target_arch = "wasm32"))]
pub mod cli;
pub mod error;
pub mod geom;
pub mod io;
pub mod layout;
pub mod machine;
pub mod model;
pub mod plan;
mod sort;
pub mod surface;
#[cfg(test)]
mod testing;
pub mod tmesh;
pub mod verify;
pub mod wasm;

pub use error::{Error, Result};
pub use model::Model;
