//! The regions of bodies that are not boxes, and the particles that fill them:
//! polygons and disks from a regular lattice over their bounding box (a cell's
//! centre inside the region keeps the cell), Gmsh physical surfaces from a
//! quadrature rule on each triangle. And whether a point lies in a body's region,
//! for the overlap check.

use crate::scene::limits::{read_bounded, MAX_MESH_FILE_BYTES, MAX_PARTICLES};
use crate::scene::{
    region_polygon, Body, BodyShape, ErrorKind, SceneError, DEFAULT_PER_TRIANGLE, MAX_SUBDIVIDE,
};
use psmpm_basis::mesh::generators::PolygonDomain;
use psmpm_basis::mesh::gmsh::parse_msh_with_surfaces;
use psmpm_basis::Vec2;
use std::path::Path;

/// A lattice extent is a whole number of cells when it is within this fraction of
/// one (so that a bounding box of exactly `n` cells gets `n`, not `n + 1`).
const WHOLE_CELLS: f64 = 1e-6;

/// Where a body's particles may lie.
pub(crate) enum Region {
    /// `min < x < max` on the first `dim` axes.
    Box {
        min: [f64; 2],
        max: [f64; 2],
        dim: usize,
    },
    /// Inside the outline, outside the holes.
    Polygon(PolygonDomain),
    /// `|x − centre| < radius`.
    Disk { centre: [f64; 2], radius: f64 },
    /// Inside one of the triangles.
    Triangles(TriangleSet),
}

impl Region {
    /// The region of a box, polygon or disk body (`None` for a Gmsh body, whose
    /// region comes with its particles).
    pub(crate) fn of(body: &Body, dim: usize) -> Option<Region> {
        match body.shape {
            BodyShape::Box => {
                let (min, max) = body.bounds()?;
                Some(Region::Box { min, max, dim })
            }
            BodyShape::Polygon => Some(Region::Polygon(region_polygon(body))),
            BodyShape::Disk => Some(Region::Disk {
                centre: body.centre?,
                radius: body.radius?,
            }),
            BodyShape::Gmsh => None,
        }
    }

    /// Whether `p` lies inside the region (a point exactly on the boundary may fall
    /// either way).
    pub(crate) fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Region::Box { min, max, dim } => (0..*dim).all(|k| min[k] < p[k] && p[k] < max[k]),
            Region::Polygon(domain) => domain.contains(Vec2::new(p[0], p[1])),
            Region::Disk { centre, radius } => (p[0] - centre[0]).hypot(p[1] - centre[1]) < *radius,
            Region::Triangles(set) => set.contains(p),
        }
    }
}

/// The particles of one body: positions, volumes, bounding box `(min, max)`.
pub(crate) struct Filled {
    pub positions: Vec<[f64; 2]>,
    pub volumes: Vec<f64>,
    pub bounds: ([f64; 2], [f64; 2]),
}

/// The particles of a polygon or disk body `b`: the cells of the lattice of spacing
/// `h` over the region's bounding box (centred on it, so that a disk's or a
/// symmetric polygon's particles are as symmetric as the region) whose centres lie
/// in `region`, each with the cell's area; `jitter(k)` gives the offset of each
/// kept particle along axis `k` in cells (drawn in the order particles are made).
/// `room` is how many particles the scene has left under [`MAX_PARTICLES`].
pub(crate) fn fill_lattice(
    b: usize,
    body: &Body,
    region: &Region,
    h: [f64; 2],
    room: usize,
    mut jitter: impl FnMut() -> f64,
) -> Result<Filled, SceneError> {
    let (lo, hi) = body
        .bounds()
        .ok_or_else(|| SceneError::new(format!("body[{b}]"), ErrorKind::Value, "has no region"))?;
    let cells = |k: usize| (((hi[k] - lo[k]) / h[k]) - WHOLE_CELLS).ceil().max(1.0);
    let (nx, ny) = (cells(0), cells(1));
    if nx * ny > MAX_PARTICLES as f64 {
        return Err(SceneError::new(
            lattice_field(b, body),
            ErrorKind::Value,
            format!("the lattice over the bounding box has {:.3e} cells, above the limit of {MAX_PARTICLES}", nx * ny),
        ));
    }
    let (nx, ny) = (nx as usize, ny as usize);
    // A cell wider than the body along an axis: centred, its one particle would
    // stand for a volume larger than the body's box.
    if let Some(k) = (0..2).find(|&k| h[k] > (hi[k] - lo[k]) * (1.0 + WHOLE_CELLS)) {
        return Err(SceneError::new(
            lattice_field(b, body),
            ErrorKind::Conflict,
            format!(
                "a lattice cell of size {} along axis {k} is wider than the body's {} ({}): the lattice is too coarse for it",
                crate::scene::limits::echo_number(h[k]),
                body.shape.name(),
                // Its extent's last digits are the subtraction's round-off
                // (0.0019999999999998908).
                crate::scene::limits::echo_significant(hi[k] - lo[k], 6)
            ),
        ));
    }
    let mut filled = Filled {
        positions: Vec::new(),
        volumes: Vec::new(),
        bounds: (lo, hi),
    };
    let volume = h[0] * h[1];
    // The lattice's overhang past the box, split between its two sides (none where
    // the box holds whole cells). Anchored at the lower corner, a disk of diameter
    // 0.6 sampled at 0.03125 (19.2 cells) had its particles 0.0125 off its centre
    // along both axes, and two such disks striking head-on parted 5.4° off their
    // line of centres.
    let start = |k: usize, n: usize| {
        let overhang = n as f64 * h[k] - (hi[k] - lo[k]);
        if overhang.abs() <= WHOLE_CELLS * h[k] * n as f64 {
            lo[k]
        } else {
            lo[k] - 0.5 * overhang
        }
    };
    let origin = [start(0, nx), start(1, ny)];
    for j in 0..ny {
        for i in 0..nx {
            let centre = [
                origin[0] + (i as f64 + 0.5) * h[0],
                origin[1] + (j as f64 + 0.5) * h[1],
            ];
            if !region.contains(centre) {
                continue;
            }
            if filled.positions.len() >= room {
                return Err(too_many(b, body));
            }
            let mut p = centre;
            if body.jitter > 0.0 {
                for k in 0..2 {
                    p[k] += body.jitter * jitter() * h[k];
                }
            }
            filled.positions.push(p);
            filled.volumes.push(volume);
        }
    }
    if filled.positions.is_empty() {
        return Err(SceneError::new(
            lattice_field(b, body),
            ErrorKind::Conflict,
            format!(
                "no lattice cell of size {} × {} has its centre inside the body's {}: the lattice is too coarse for it",
                crate::scene::limits::echo_number(h[0]),
                crate::scene::limits::echo_number(h[1]),
                body.shape.name()
            ),
        ));
    }
    Ok(filled)
}

/// The particles of Gmsh body `b`: `per_triangle` points of a quadrature rule in
/// every triangle of its physical surface (in each of its `4^subdivide` pieces
/// after `subdivide` splits at the edge midpoints), each with volume weight × area
/// (so the volumes sum to the surface's area), and the surface's triangles as its
/// region.
pub(crate) fn fill_surface(
    b: usize,
    body: &Body,
    room: usize,
) -> Result<(Filled, Region), SceneError> {
    let field = |f: &str| format!("body[{b}].{f}");
    let file = body.file.as_deref().unwrap_or_default();
    let bytes = read_bounded(Path::new(file), MAX_MESH_FILE_BYTES).map_err(|e| {
        SceneError::new(
            field("file"),
            ErrorKind::File,
            format!("{}: {e}", crate::scene::limits::echo(file)),
        )
    })?;
    let (mesh, surfaces) = parse_msh_with_surfaces(&String::from_utf8_lossy(&bytes), file)
        .map_err(|e| SceneError::new(field("file"), ErrorKind::File, e.to_string()))?;
    let name = body.surface.as_ref().map(|s| s.text()).unwrap_or_default();
    let tag = surfaces.find(&name).ok_or_else(|| {
        let listed = surfaces.listed();
        SceneError::new(
            field("surface"),
            ErrorKind::Unknown,
            format!(
                "{} has no physical surface `{}` with triangles (it has: {})",
                crate::scene::limits::echo(file),
                crate::scene::limits::echo(&name),
                if listed.is_empty() {
                    "none".to_string()
                } else {
                    listed
                        .iter()
                        .map(|name| crate::scene::limits::echo(name))
                        .collect::<Vec<_>>()
                        .join(", ")
                }
            ),
        )
    })?;
    let per = body.per_triangle.unwrap_or(DEFAULT_PER_TRIANGLE);
    // Degree-1 (centroid) or degree-2 (interior points) rule, equal weights.
    let rule: &[[f64; 3]] = if per == 1 {
        &[[1.0 / 3.0; 3]]
    } else {
        &[
            [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
            [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
            [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
        ]
    };
    let weight = 1.0 / rule.len() as f64;
    let chosen: Vec<usize> = (0..mesh.num_triangles())
        .filter(|&t| surfaces.of_triangle[t] == Some(tag))
        .collect();
    let splits = body.subdivide.unwrap_or(0).min(MAX_SUBDIVIDE);
    let count = chosen
        .len()
        .saturating_mul(rule.len())
        .saturating_mul(1usize << (2 * splits));
    if count > room {
        return Err(too_many(b, body));
    }
    let mut filled = Filled {
        positions: Vec::with_capacity(count),
        volumes: Vec::with_capacity(count),
        bounds: ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
    };
    let mut triangles = Vec::with_capacity(chosen.len());
    let mut pieces = Vec::new();
    for &t in &chosen {
        let corners = mesh.triangle_points(t);
        // The pieces of `splits` midpoint splits, depth first (the triangle itself
        // without splits).
        pieces.push((corners, splits));
        while let Some((c, depth)) = pieces.pop() {
            if depth > 0 {
                let m = [
                    (c[0] + c[1]) * 0.5,
                    (c[1] + c[2]) * 0.5,
                    (c[2] + c[0]) * 0.5,
                ];
                pieces.push(([m[0], m[1], m[2]], depth - 1));
                pieces.push(([m[2], m[1], c[2]], depth - 1));
                pieces.push(([m[0], c[1], m[1]], depth - 1));
                pieces.push(([c[0], m[0], m[2]], depth - 1));
                continue;
            }
            let area = if depth == splits {
                mesh.area(t)
            } else {
                psmpm_basis::mesh::signed_area(c[0], c[1], c[2]).abs()
            };
            for bary in rule {
                let p = c[0] * bary[0] + c[1] * bary[1] + c[2] * bary[2];
                filled.positions.push([p.x, p.y]);
                filled.volumes.push(weight * area);
            }
        }
        for c in &corners {
            let (lo, hi) = &mut filled.bounds;
            lo[0] = lo[0].min(c.x);
            lo[1] = lo[1].min(c.y);
            hi[0] = hi[0].max(c.x);
            hi[1] = hi[1].max(c.y);
        }
        triangles.push(corners.map(|c| [c.x, c.y]));
    }
    Ok((filled, Region::Triangles(TriangleSet::new(triangles))))
}

/// The field that sets a body's lattice (`per_block`, `count` or `spacing`).
fn lattice_field(b: usize, body: &Body) -> String {
    let name = if body.spacing.is_some() {
        "spacing"
    } else if body.count.is_some() {
        "count"
    } else {
        "per_block"
    };
    format!("body[{b}].{name}")
}

/// The field that sets the particle count of body `b` (its lattice's, or a Gmsh
/// body's `subdivide` where given, else its `per_triangle`).
pub(crate) fn count_field(b: usize, body: &Body) -> String {
    if body.shape == BodyShape::Gmsh {
        let name = if body.subdivide.is_some() {
            "subdivide"
        } else {
            "per_triangle"
        };
        format!("body[{b}].{name}")
    } else {
        lattice_field(b, body)
    }
}

/// The error of a body whose particles would pass [`MAX_PARTICLES`].
fn too_many(b: usize, body: &Body) -> SceneError {
    SceneError::new(
        count_field(b, body),
        ErrorKind::Value,
        format!("the bodies up to body[{b}] hold more than {MAX_PARTICLES} particles, the limit"),
    )
}

/// Triangles with a bucket grid over their bounding box, for point location.
pub(crate) struct TriangleSet {
    triangles: Vec<[[f64; 2]; 3]>,
    lo: [f64; 2],
    cell: [f64; 2],
    n: [usize; 2],
    /// Triangles overlapping each bucket (row by row).
    buckets: Vec<Vec<usize>>,
}

impl TriangleSet {
    fn new(triangles: Vec<[[f64; 2]; 3]>) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for t in &triangles {
            for c in t {
                for k in 0..2 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
        }
        // About one triangle per bucket.
        let side = (triangles.len() as f64).sqrt().ceil().max(1.0) as usize;
        let n = [side, side];
        let cell = [
            ((hi[0] - lo[0]) / side as f64).max(f64::MIN_POSITIVE),
            ((hi[1] - lo[1]) / side as f64).max(f64::MIN_POSITIVE),
        ];
        let mut set = TriangleSet {
            triangles,
            lo,
            cell,
            n,
            buckets: vec![Vec::new(); side * side],
        };
        for (t, tri) in set.triangles.iter().enumerate() {
            let (mut a, mut z) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for c in tri {
                for k in 0..2 {
                    a[k] = a[k].min(c[k]);
                    z[k] = z[k].max(c[k]);
                }
            }
            let (i0, j0) = (set.bucket(a, 0), set.bucket(a, 1));
            let (i1, j1) = (set.bucket(z, 0), set.bucket(z, 1));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    set.buckets[j * n[0] + i].push(t);
                }
            }
        }
        set
    }

    /// The bucket index of `p` along axis `k`, clamped to the grid.
    fn bucket(&self, p: [f64; 2], k: usize) -> usize {
        let i = ((p[k] - self.lo[k]) / self.cell[k]).floor();
        if i.is_nan() || i < 0.0 {
            0
        } else {
            (i as usize).min(self.n[k] - 1)
        }
    }

    /// Whether `p` lies strictly inside one of the triangles.
    fn contains(&self, p: [f64; 2]) -> bool {
        if !(0..2)
            .all(|k| p[k] >= self.lo[k] && p[k] <= self.lo[k] + self.cell[k] * self.n[k] as f64)
        {
            return false;
        }
        let bucket = self.bucket(p, 1) * self.n[0] + self.bucket(p, 0);
        self.buckets[bucket].iter().any(|&t| {
            let [a, b, c] = self.triangles[t];
            let side = |u: [f64; 2], v: [f64; 2]| {
                (v[0] - u[0]) * (p[1] - u[1]) - (v[1] - u[1]) * (p[0] - u[0])
            };
            let (s0, s1, s2) = (side(a, b), side(b, c), side(c, a));
            (s0 > 0.0 && s1 > 0.0 && s2 > 0.0) || (s0 < 0.0 && s1 < 0.0 && s2 < 0.0)
        })
    }
}
