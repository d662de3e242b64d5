//! The integration tests, one module per file of `tests/`, built as one test binary: 31
//! binaries linked the library and instantiated its generic maths 31 times over, which was
//! most of a clean `cargo test` build's time. `cargo test --test integration reach::` (or
//! `cargo nextest run -E 'test(/^reach::/)'`) runs one file's tests.

mod machine_support;
mod support;

mod axis_steps;
mod budget;
mod catmull_clark;
mod cli;
mod compare;
mod foundation;
mod geometry;
mod isfc;
mod isfc_layer;
mod isoplanar;
mod layout;
mod machine_cli;
mod machine_kinematics;
mod machine_reader;
mod machine_roundtrip;
mod machine_rs274;
mod machining_time;
mod max_tilt;
mod no_outside_paths;
mod obj_tags;
mod planner;
mod reach;
mod readers;
mod refine;
mod setup;
mod tessellation;
mod tmesh_cusp;
mod tsm;
mod verify;
mod verify_cli;
mod watershed;
