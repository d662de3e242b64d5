//! Built-in sample models, made by the project's own code and handed out in the project's
//! JSON format. Each sample documents its construction and size.

use super::Model;
use crate::error::{Error, Result};
use crate::geom::{Point3, Vector4};
use crate::io;
use crate::tmesh::{ControlPoint, Scheme, TMesh};

/// A named sample and what it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleInfo {
    pub name: &'static str,
    pub description: &'static str,
}

/// All built-in samples.
pub const SAMPLES: &[SampleInfo] = &[SampleInfo {
    name: "dome",
    description: "a piece of a sphere of radius 40 mm, one rational bicubic patch (90° × 90°), apex up, lowest corners at z = 0",
}];

/// Radius of the `dome` sample's sphere (mm).
pub const DOME_RADIUS_MM: f64 = 40.0;

/// The T-mesh of a sample.
pub fn sample_mesh(name: &str) -> Result<TMesh> {
    match name {
        "dome" => dome(DOME_RADIUS_MM),
        _ => Err(Error::UnknownSample(name.to_string())),
    }
}

/// A sample as a JSON model file (the project's own format).
pub fn sample_json(name: &str) -> Result<String> {
    Ok(io::json::write(&sample_mesh(name)?, name))
}

/// A sample, loaded through the JSON reader exactly as a user's file would be.
pub fn load_sample(name: &str) -> Result<Model> {
    io::load(sample_json(name)?.as_bytes(), name)
}

/// Quadratic rational arc from angle `-a` to `a` on the unit circle: control points and
/// weights.
fn arc(a: f64) -> [([f64; 2], f64); 3] {
    [
        ([a.cos(), -a.sin()], 1.0),
        ([1.0 / a.cos(), 0.0], a.cos()),
        ([a.cos(), a.sin()], 1.0),
    ]
}

/// Degree elevation of a homogeneous quadratic to a cubic.
fn elevate(h: [Vector4; 3]) -> [Vector4; 4] {
    [
        h[0],
        (h[0] + h[1] * 2.0) / 3.0,
        (h[1] * 2.0 + h[2]) / 3.0,
        h[2],
    ]
}

/// Rational bicubic patch exactly on a sphere of radius `r`: longitude and latitude each span
/// 90°, centred on the +Z axis, then lifted so the lowest corners sit at z = 0
/// (sphere centre at `(0, 0, -r/2)`).
pub fn dome(r: f64) -> Result<TMesh> {
    let a = std::f64::consts::FRAC_PI_4;
    let lon = arc(a);
    let lat = arc(a);
    // Biquadratic homogeneous net, then elevate rows and columns.
    let mut quad = [[Vector4::zeros(); 3]; 3];
    for (j, &([pr, pz], wj)) in lat.iter().enumerate() {
        for (i, &([cx, cy], wi)) in lon.iter().enumerate() {
            // Sphere of revolution about z before orientation: (r·pr·cx, r·pr·cy, r·pz).
            let (x, y, z) = (r * pr * cx, r * pr * cy, r * pz);
            // Rotate about y by -90°: (x, y, z) -> (-z, y, x); then lift by -r/2.
            let p = [-z, y, x - 0.5 * r];
            let w = wi * wj;
            quad[j][i] = Vector4::new(w * p[0], w * p[1], w * p[2], w);
        }
    }
    let rows: Vec<[Vector4; 4]> = quad.iter().map(|row| elevate(*row)).collect();
    let mut points = vec![
        ControlPoint {
            point: Point3::origin(),
            weight: 1.0
        };
        16
    ];
    for i in 0..4 {
        let col = elevate([rows[0][i], rows[1][i], rows[2][i]]);
        for (j, h) in col.iter().enumerate() {
            points[j * 4 + i] = ControlPoint {
                point: Point3::new(h.x / h.w, h.y / h.w, h.z / h.w),
                weight: h.w,
            };
        }
    }
    // One Bézier patch: clamped knots [0,0,0,0,1,1,1,1] give intervals 0, 1, 0.
    TMesh::from_grid(
        points,
        4,
        4,
        &[0.0, 1.0, 0.0],
        &[0.0, 1.0, 0.0],
        Scheme::TSpline,
    )
}
