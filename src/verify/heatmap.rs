//! Per-vertex values of a tessellation from the dense samples, for the page's heat map.
//!
//! Each sample goes to the nearest tessellation vertex on the same side of the surface (its
//! normal within 90° of the sample's); a vertex shows the worst of its samples: the deepest gouge if any (negative, mm), else the most material
//! left (mm), `+∞` where the tool never came near. Vertices that received no sample (a
//! tessellation finer than the sampling) are measured directly by the caller.

use crate::geom::{Point3, Vector3};
use crate::surface::tessellate::Tessellation;

/// Most cells of the vertex grid.
const MAX_CELLS: usize = 1 << 21;

/// The accumulating heat map.
#[derive(Debug, Clone)]
pub struct HeatMap {
    positions: Vec<Point3>,
    normals: Vec<Vector3>,
    origin: Point3,
    cell: f64,
    dims: [usize; 3],
    starts: Vec<u32>,
    items: Vec<u32>,
    values: Vec<f32>,
}

/// The worse of two heat values: gouges first, then the larger.
pub fn worse(a: f32, b: f32) -> f32 {
    if a.is_nan() {
        b
    } else if b.is_nan() {
        a
    } else if a < 0.0 || b < 0.0 {
        a.min(b)
    } else {
        a.max(b)
    }
}

impl HeatMap {
    /// An empty heat map over the vertices of `mesh`.
    pub fn new(mesh: &Tessellation) -> Self {
        let nv = mesh.positions.len() / 3;
        let positions: Vec<Point3> = (0..nv)
            .map(|i| {
                Point3::new(
                    mesh.positions[3 * i] as f64,
                    mesh.positions[3 * i + 1] as f64,
                    mesh.positions[3 * i + 2] as f64,
                )
            })
            .collect();
        let normals: Vec<Vector3> = (0..nv)
            .map(|i| {
                let n = Vector3::new(
                    mesh.normals.get(3 * i).copied().unwrap_or(0.0) as f64,
                    mesh.normals.get(3 * i + 1).copied().unwrap_or(0.0) as f64,
                    mesh.normals.get(3 * i + 2).copied().unwrap_or(1.0) as f64,
                );
                n.try_normalize(0.0).unwrap_or_else(Vector3::z)
            })
            .collect();
        let mut edge_sum = 0.0;
        let mut edges = 0usize;
        for tri in mesh.indices.chunks_exact(3) {
            for k in 0..3 {
                let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
                if a < nv && b < nv {
                    edge_sum += (positions[a] - positions[b]).norm();
                    edges += 1;
                }
            }
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let mut cell = if edges > 0 {
            (edge_sum / edges as f64).max(f64::MIN_POSITIVE)
        } else {
            1.0
        };
        let count = |c: f64| [0, 1, 2].map(|k| (((hi[k] - lo[k]) / c).floor() as usize + 1).max(1));
        while nv > 0 && count(cell).iter().product::<usize>() > MAX_CELLS {
            cell *= 1.25;
        }
        let dims = if nv > 0 { count(cell) } else { [1, 1, 1] };
        let origin = if nv > 0 {
            Point3::new(lo[0], lo[1], lo[2])
        } else {
            Point3::origin()
        };
        let mut map = HeatMap {
            positions,
            normals,
            origin,
            cell,
            dims,
            starts: Vec::new(),
            items: Vec::new(),
            values: vec![f32::NAN; nv],
        };
        let ncells = dims[0] * dims[1] * dims[2];
        let mut counts = vec![0u32; ncells + 1];
        let cells: Vec<usize> = map.positions.iter().map(|p| map.cell_of(p)).collect();
        for &c in &cells {
            counts[c + 1] += 1;
        }
        for k in 0..ncells {
            counts[k + 1] += counts[k];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; nv];
        for (i, &c) in cells.iter().enumerate() {
            items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        map.starts = counts;
        map.items = items;
        map
    }

    fn coords(&self, p: &Point3) -> [usize; 3] {
        [0, 1, 2].map(|k| {
            let c = ((p[k] - self.origin[k]) / self.cell).floor();
            (c.max(0.0) as usize).min(self.dims[k] - 1)
        })
    }

    fn cell_of(&self, p: &Point3) -> usize {
        let c = self.coords(p);
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// The nearest vertex to `p` whose normal is within 90° of `n`, within two cells.
    fn nearest(&self, p: &Point3, n: &Vector3) -> Option<usize> {
        let c = self.coords(p);
        let mut best: Option<(f64, usize)> = None;
        for ring in 1..=2usize {
            let lo = c.map(|x| x.saturating_sub(ring));
            let hi = [0, 1, 2].map(|k| (c[k] + ring).min(self.dims[k] - 1));
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        let cell = (z * self.dims[1] + y) * self.dims[0] + x;
                        let (s, e) = (self.starts[cell] as usize, self.starts[cell + 1] as usize);
                        for &v in &self.items[s..e] {
                            let v = v as usize;
                            if self.normals[v].dot(n) > 0.0 {
                                let d = (self.positions[v] - p).norm_squared();
                                if best.is_none_or(|(bd, bv)| d < bd || (d == bd && v < bv)) {
                                    best = Some((d, v));
                                }
                            }
                        }
                    }
                }
            }
            if best.is_some() {
                break;
            }
        }
        best.map(|(_, v)| v)
    }

    /// Records a sample's value at `p`, where the surface normal (`S_u × S_v`) is `n`.
    pub fn add(&mut self, p: &Point3, n: &Vector3, value: f32) {
        if let Some(v) = self.nearest(p, n) {
            self.values[v] = worse(self.values[v], value);
        }
    }

    /// Vertices no sample reached: index, position and unit normal (as tessellated).
    pub fn unfilled(&self) -> Vec<(usize, Point3, Vector3)> {
        (0..self.values.len())
            .filter(|&i| self.values[i].is_nan())
            .map(|i| (i, self.positions[i], self.normals[i]))
            .collect()
    }

    /// Sets the value of vertex `i`.
    pub fn set(&mut self, i: usize, value: f32) {
        self.values[i] = value;
    }

    /// Folds another map over the same mesh into this one (order does not matter).
    pub fn merge(&mut self, other: &HeatMap) {
        for (a, &b) in self.values.iter_mut().zip(&other.values) {
            *a = worse(*a, b);
        }
    }

    /// The values, one per tessellation vertex.
    pub fn into_values(self) -> Vec<f32> {
        self.values
    }
}
