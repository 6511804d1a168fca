//! Triangle meshes (and 1D node vectors) on which the bases are built.
//!
//! A [`TriMesh`] holds vertices, counter-clockwise triangles, the edge graph
//! (neighbours across each edge, global edge ids) and tags on boundary edges.
//! It is built once, validated on construction ([`MeshError`] names what is wrong),
//! and never changes afterwards: bases precompute their per-element data from it.
//!
//! Conventions used throughout the crate:
//! - local edge `k` of triangle `t` joins `triangles[t][k]` and `triangles[t][(k + 1) % 3]`;
//! - `neighbours[t][k]` is the triangle across local edge `k`, `None` on the boundary;
//! - `triangle_edges[t][k]` is the global id of local edge `k`;
//! - boundary edges carry an optional tag id into [`TriMesh::tags`].
//!
//! Submodules: [`generators`] (block grids, lattice Delaunay, quality meshes of
//! polygons), [`gmsh`] (`.msh` import), [`locate`] (point location),
//! [`mesh1d`] (node vectors on an interval).

pub mod generators;
pub mod gmsh;
pub mod locate;
pub mod mesh1d;

pub use locate::Locator;
pub use mesh1d::Mesh1d;

use nalgebra::Vector2;
use std::collections::HashMap;

/// A point or vector in the plane.
pub type Vec2 = Vector2<f64>;

/// What is wrong with a mesh. Every variant names the offending entity.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("mesh has no triangles")]
    Empty,
    #[error(
        "triangle {triangle} refers to vertex {vertex}, but the mesh has {num_vertices} vertices"
    )]
    VertexOutOfRange {
        triangle: usize,
        vertex: usize,
        num_vertices: usize,
    },
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteVertex { vertex: usize },
    #[error("triangle {triangle} repeats a vertex ({vertices:?})")]
    RepeatedVertex {
        triangle: usize,
        vertices: [usize; 3],
    },
    #[error("triangle {triangle} is degenerate (signed area {area:e} relative to the mesh size)")]
    DegenerateTriangle { triangle: usize, area: f64 },
    #[error("triangle {triangle} is clockwise (inverted); triangles must be counter-clockwise")]
    InvertedTriangle { triangle: usize },
    #[error("edge ({a}, {b}) is shared by more than two triangles or by two triangles with the same orientation (non-manifold)")]
    NonManifoldEdge { a: usize, b: usize },
    #[error("vertex {vertex} is where two separate fans of triangles touch (non-manifold vertex)")]
    NonManifoldVertex { vertex: usize },
    #[error("triangles {a} and {b} overlap (the centroid of {a} lies inside {b})")]
    Overlap { a: usize, b: usize },
    #[error("vertices {a} and {b} coincide at ({x}, {y})")]
    DuplicateVertex { a: usize, b: usize, x: f64, y: f64 },
    #[error("vertex {vertex} belongs to no triangle")]
    IsolatedVertex { vertex: usize },
    #[error("boundary edge ({a}, {b}) from ({ax}, {ay}) to ({bx}, {by}) has no tag, but every boundary edge must be tagged")]
    UntaggedBoundary {
        a: usize,
        b: usize,
        ax: f64,
        ay: f64,
        bx: f64,
        by: f64,
    },
    #[error("unknown boundary tag `{tag}`; the mesh has tags {known:?}")]
    UnknownTag { tag: String, known: Vec<String> },
    #[error("invalid mesh parameter: {0}")]
    InvalidParameter(String),
    #[error("mesher failed: {0}")]
    Mesher(String),
    /// The target edge length of a generated mesh cannot be used: too small for
    /// the domain, or asking for more points than the mesher may add.
    #[error("{0}")]
    EdgeLength(String),
    /// Coordinates too large or an extent too small for the geometry's products
    /// (areas, squared lengths) in `f64`; see [`MAX_COORDINATE`], [`MIN_EXTENT`].
    #[error("the mesh's coordinates reach {largest:.3e} and its extent is {extent:.3e}: the geometry needs coordinates within ±{MAX_COORDINATE:e} and an extent of at least {MIN_EXTENT:e} (beyond continuum mechanics in metres, and beyond what the geometry's round-off holds); give the mesh in other units")]
    Scale { largest: f64, extent: f64 },
}

/// Largest coordinate magnitude of a mesh (1e30: beyond any continuum in metres;
/// squared lengths and products of areas stay far inside `f64`, where a mesh
/// scaled by 1e300 reported coinciding vertices).
pub const MAX_COORDINATE: f64 = 1e30;
/// Smallest extent (bounding-box diagonal) of a mesh (1e-10: an ångström, below
/// continuum mechanics in metres; the Powell–Sabin control triangles, whose
/// round-off tolerances are partly absolute, are found down to 1e-12 and fail
/// from 1e-14).
pub const MIN_EXTENT: f64 = 1e-10;

/// One edge of the mesh: its two vertices (in the orientation of its first
/// triangle), the triangles on either side, and its tag if it is a tagged
/// boundary edge.
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    /// End vertices, ordered as in `triangles[0]` (counter-clockwise there).
    pub vertices: [usize; 2],
    /// The triangle having this edge counter-clockwise, and the one across (`None` on the boundary).
    pub triangles: (usize, Option<usize>),
    /// Tag id into [`TriMesh::tags`], boundary edges only.
    pub tag: Option<usize>,
}

impl Edge {
    /// `true` when the edge has a triangle on one side only.
    pub fn is_boundary(&self) -> bool {
        self.triangles.1.is_none()
    }
}

/// A validated, counter-clockwise triangle mesh with tagged boundary edges.
#[derive(Debug, Clone)]
pub struct TriMesh {
    vertices: Vec<Vec2>,
    triangles: Vec<[usize; 3]>,
    neighbours: Vec<[Option<usize>; 3]>,
    triangle_edges: Vec<[usize; 3]>,
    edges: Vec<Edge>,
    tags: Vec<String>,
    /// For every vertex, the triangles around it (a fan, counter-clockwise order not guaranteed).
    vertex_triangles: Vec<Vec<usize>>,
    locator: Locator,
}

/// Relative tolerance for degenerate triangles (area relative to the squared
/// length scale of the mesh) and duplicate vertices (distance relative to it).
pub const GEOMETRY_TOLERANCE: f64 = 1e-12;

impl TriMesh {
    /// Builds and validates a mesh from vertices and counter-clockwise triangles.
    /// Boundary edges start untagged; see [`TriMesh::tag_boundary`].
    ///
    /// Errors: out-of-range or repeated vertex indices, non-finite coordinates,
    /// degenerate or clockwise triangles, non-manifold edges or vertices,
    /// duplicate or isolated vertices.
    pub fn new(vertices: Vec<Vec2>, triangles: Vec<[usize; 3]>) -> Result<Self, MeshError> {
        if triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        let nv = vertices.len();
        for (i, v) in vertices.iter().enumerate() {
            if !v.x.is_finite() || !v.y.is_finite() {
                return Err(MeshError::NonFiniteVertex { vertex: i });
            }
        }
        let (lo, hi) = bounding_box(&vertices);
        let largest = lo.abs().max().max(hi.abs().max());
        let extent = (hi - lo).norm();
        if !(largest <= MAX_COORDINATE && extent >= MIN_EXTENT) {
            return Err(MeshError::Scale { largest, extent });
        }
        let scale = extent;
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                if v >= nv {
                    return Err(MeshError::VertexOutOfRange {
                        triangle: t,
                        vertex: v,
                        num_vertices: nv,
                    });
                }
            }
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                return Err(MeshError::RepeatedVertex {
                    triangle: t,
                    vertices: *tri,
                });
            }
            let area = signed_area(vertices[tri[0]], vertices[tri[1]], vertices[tri[2]]);
            let rel = area / (scale * scale);
            if rel.abs() <= GEOMETRY_TOLERANCE {
                return Err(MeshError::DegenerateTriangle {
                    triangle: t,
                    area: rel,
                });
            }
            if area < 0.0 {
                return Err(MeshError::InvertedTriangle { triangle: t });
            }
        }

        // Duplicate vertices: sort by x and compare neighbours in a window.
        let tol = GEOMETRY_TOLERANCE * scale * 1e3;
        let mut order: Vec<usize> = (0..nv).collect();
        order.sort_by(|&a, &b| vertices[a].x.total_cmp(&vertices[b].x).then(a.cmp(&b)));
        for i in 0..nv {
            let a = order[i];
            for &b in &order[i + 1..] {
                if vertices[b].x - vertices[a].x > tol {
                    break;
                }
                if (vertices[b] - vertices[a]).norm() <= tol {
                    let (a, b) = (a.min(b), a.max(b));
                    return Err(MeshError::DuplicateVertex {
                        a,
                        b,
                        x: vertices[a].x,
                        y: vertices[a].y,
                    });
                }
            }
        }

        // Edges: a directed edge (a, b) may occur once; its twin (b, a) at most once.
        let mut directed: HashMap<(usize, usize), (usize, usize)> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if directed.insert((a, b), (t, k)).is_some() {
                    return Err(MeshError::NonManifoldEdge {
                        a: a.min(b),
                        b: a.max(b),
                    });
                }
            }
        }
        let mut neighbours = vec![[None; 3]; triangles.len()];
        let mut triangle_edges = vec![[usize::MAX; 3]; triangles.len()];
        let mut edges = Vec::new();
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                if triangle_edges[t][k] != usize::MAX {
                    continue;
                }
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let twin = directed.get(&(b, a)).copied();
                let id = edges.len();
                triangle_edges[t][k] = id;
                if let Some((t2, k2)) = twin {
                    triangle_edges[t2][k2] = id;
                    neighbours[t][k] = Some(t2);
                    neighbours[t2][k2] = Some(t);
                }
                edges.push(Edge {
                    vertices: [a, b],
                    triangles: (t, twin.map(|(t2, _)| t2)),
                    tag: None,
                });
            }
        }

        let mut vertex_triangles = vec![Vec::new(); nv];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                vertex_triangles[v].push(t);
            }
        }
        for (v, fan) in vertex_triangles.iter().enumerate() {
            if fan.is_empty() {
                return Err(MeshError::IsolatedVertex { vertex: v });
            }
            // A manifold vertex has its triangles connected through edges at v.
            let mut seen = vec![fan[0]];
            let mut stack = vec![fan[0]];
            while let Some(t) = stack.pop() {
                for k in 0..3 {
                    let tri = triangles[t];
                    if tri[k] != v && tri[(k + 1) % 3] != v {
                        continue;
                    }
                    if let Some(n) = neighbours[t][k] {
                        if !seen.contains(&n) {
                            seen.push(n);
                            stack.push(n);
                        }
                    }
                }
            }
            if seen.len() != fan.len() {
                return Err(MeshError::NonManifoldVertex { vertex: v });
            }
        }

        let mut mesh = TriMesh {
            vertices,
            triangles,
            neighbours,
            triangle_edges,
            edges,
            tags: Vec::new(),
            vertex_triangles,
            locator: Locator::default(),
        };
        mesh.locator = Locator::new(&mesh);
        // Overlapping triangles (a second copy of the mesh, a triangle laid over
        // others) pass every check above when they share no edge: the centroid of
        // a triangle lies strictly inside it, so location finds another triangle
        // there only where two overlap.
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.triangles[t].map(|v| mesh.vertices[v]);
            let centroid = (a + b + c) / 3.0;
            if let Some(other) = mesh.locate(centroid, None).filter(|&o| o != t) {
                return Err(MeshError::Overlap { a: t, b: other });
            }
        }
        Ok(mesh)
    }

    /// Tags boundary edges: `tagger(a, b)` receives the end points of each boundary
    /// edge and returns its tag name, or `None` to leave it as it is. Returns the
    /// number of edges tagged.
    pub fn tag_boundary(&mut self, mut tagger: impl FnMut(Vec2, Vec2) -> Option<String>) -> usize {
        let mut count = 0;
        for e in 0..self.edges.len() {
            if !self.edges[e].is_boundary() {
                continue;
            }
            let [a, b] = self.edges[e].vertices;
            if let Some(name) = tagger(self.vertices[a], self.vertices[b]) {
                let id = self.tag_id_or_insert(&name);
                self.edges[e].tag = Some(id);
                count += 1;
            }
        }
        count
    }

    /// Tags the boundary edges lying on the sides of the axis-aligned box
    /// `[x0, x1] × [y0, y1]` as `left`, `right`, `bottom` and `top` (relative
    /// tolerance 1e-9 of the box size). Other boundary edges are left untouched.
    pub fn tag_box_sides(&mut self, x0: f64, x1: f64, y0: f64, y1: f64) -> usize {
        let tol = 1e-9 * ((x1 - x0).abs() + (y1 - y0).abs());
        self.tag_boundary(|a, b| {
            let on = |p: f64, q: f64, c: f64| (p - c).abs() <= tol && (q - c).abs() <= tol;
            if on(a.x, b.x, x0) {
                Some("left".into())
            } else if on(a.x, b.x, x1) {
                Some("right".into())
            } else if on(a.y, b.y, y0) {
                Some("bottom".into())
            } else if on(a.y, b.y, y1) {
                Some("top".into())
            } else {
                None
            }
        })
    }

    /// Sets the tag of the boundary edge joining vertices `a` and `b` (either
    /// order). Returns `false` when no such boundary edge exists.
    pub fn set_edge_tag(&mut self, a: usize, b: usize, tag: &str) -> bool {
        let Some(e) = self.find_edge(a, b) else {
            return false;
        };
        if !self.edges[e].is_boundary() {
            return false;
        }
        let id = self.tag_id_or_insert(tag);
        self.edges[e].tag = Some(id);
        true
    }

    fn tag_id_or_insert(&mut self, name: &str) -> usize {
        match self.tags.iter().position(|t| t == name) {
            Some(i) => i,
            None => {
                self.tags.push(name.to_string());
                self.tags.len() - 1
            }
        }
    }

    /// Checks that every boundary edge carries a tag.
    pub fn require_tagged_boundary(&self) -> Result<(), MeshError> {
        for e in &self.edges {
            if e.is_boundary() && e.tag.is_none() {
                let [a, b] = e.vertices;
                let (pa, pb) = (self.vertices[a], self.vertices[b]);
                return Err(MeshError::UntaggedBoundary {
                    a,
                    b,
                    ax: pa.x,
                    ay: pa.y,
                    bx: pb.x,
                    by: pb.y,
                });
            }
        }
        Ok(())
    }

    /// The id of a tag name, or [`MeshError::UnknownTag`] listing the known ones.
    pub fn tag_id(&self, name: &str) -> Result<usize, MeshError> {
        self.tags
            .iter()
            .position(|t| t == name)
            .ok_or_else(|| MeshError::UnknownTag {
                tag: name.to_string(),
                known: self.tags.clone(),
            })
    }

    /// Global id of the edge joining `a` and `b`, if any.
    pub fn find_edge(&self, a: usize, b: usize) -> Option<usize> {
        for &t in &self.vertex_triangles[a] {
            for k in 0..3 {
                let tri = self.triangles[t];
                let (p, q) = (tri[k], tri[(k + 1) % 3]);
                if (p == a && q == b) || (p == b && q == a) {
                    return Some(self.triangle_edges[t][k]);
                }
            }
        }
        None
    }

    /// Vertex coordinates.
    pub fn vertices(&self) -> &[Vec2] {
        &self.vertices
    }
    /// Counter-clockwise triangles as vertex indices.
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }
    /// `neighbours()[t][k]`: the triangle across local edge `k` of `t`.
    pub fn neighbours(&self) -> &[[Option<usize>; 3]] {
        &self.neighbours
    }
    /// `triangle_edges()[t][k]`: global id of local edge `k` of `t`.
    pub fn triangle_edges(&self) -> &[[usize; 3]] {
        &self.triangle_edges
    }
    /// All edges.
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }
    /// Tag names; boundary edges refer to them by index.
    pub fn tags(&self) -> &[String] {
        &self.tags
    }
    /// Triangles incident to vertex `v`.
    pub fn vertex_triangles(&self, v: usize) -> &[usize] {
        &self.vertex_triangles[v]
    }
    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.vertices.len()
    }
    /// Number of triangles.
    pub fn num_triangles(&self) -> usize {
        self.triangles.len()
    }
    /// The three corner points of triangle `t`.
    pub fn triangle_points(&self, t: usize) -> [Vec2; 3] {
        let [a, b, c] = self.triangles[t];
        [self.vertices[a], self.vertices[b], self.vertices[c]]
    }
    /// Area of triangle `t` (positive).
    pub fn area(&self, t: usize) -> f64 {
        let [a, b, c] = self.triangle_points(t);
        signed_area(a, b, c)
    }
    /// Axis-aligned bounding box `(min, max)` of the vertices.
    pub fn bounding_box(&self) -> (Vec2, Vec2) {
        bounding_box(&self.vertices)
    }
    /// The point locator built with the mesh.
    pub fn locator(&self) -> &Locator {
        &self.locator
    }
    /// The triangle containing `p`, searching first from `hint` (e.g. a particle's
    /// previous triangle). `None` when `p` lies outside the mesh. Points on a shared
    /// edge or vertex are assigned to one of the triangles containing them.
    pub fn locate(&self, p: Vec2, hint: Option<usize>) -> Option<usize> {
        self.locator.locate(self, p, hint)
    }
    /// Calls `visit` with every triangle other than `t` whose closure holds `p`
    /// (which lies in `t`) up to [`locate::TOUCH_TOLERANCE`]: the neighbour across
    /// the edge `p` lies on, or every other triangle around the vertex it lies on.
    /// A point on a shared edge or vertex lies in all of them, and
    /// [`locate`](Self::locate) picks one by round-off; decisions that depend on
    /// which triangles hold a point use these as well, so that they do not.
    pub fn other_triangles_at(&self, t: usize, p: Vec2, visit: &mut dyn FnMut(usize)) {
        let l = self.barycentric(t, p);
        let on: [bool; 3] = std::array::from_fn(|k| l[k] <= locate::TOUCH_TOLERANCE);
        match on.iter().filter(|&&o| o).count() {
            1 => {
                // The edge opposite vertex m is local edge m + 1 (edge k joins k, k + 1).
                let m = on.iter().position(|&o| o).unwrap();
                if let Some(n) = self.neighbours[t][(m + 1) % 3] {
                    visit(n);
                }
            }
            2 => {
                let c = on.iter().position(|&o| !o).unwrap();
                for &n in self.vertex_triangles(self.triangles[t][c]) {
                    if n != t {
                        visit(n);
                    }
                }
            }
            _ => {}
        }
    }
    /// The triangle that holds `p` (located in `t`) for a basis whose gradient jumps
    /// across edges (PL): `t` itself unless `p` lies on an edge or vertex, within
    /// [`locate::INSIDE_TOLERANCE`], where every triangle whose closure holds `p`
    /// is a candidate and one is kept by a rule of the mesh's geometry alone, so
    /// that the choice does not depend on round-off or on the walk's path and
    /// commutes with mirrors about lines along `axis`.
    ///
    /// With `d` the offset of a candidate's centroid from the shared feature (the
    /// edge's midpoint, or the vertex), the candidate reaching farthest across the
    /// mirror axis's direction wins: for a vertical axis the largest `|d_y| − |d_x|`,
    /// for a horizontal one the largest `|d_x| − |d_y|` (both unchanged by either
    /// mirror). On the diagonals of the `four-triangles` grid this keeps the left or
    /// right triangle of the block for a vertical axis (its centroid lies above or
    /// below the half-diagonal's midpoint, rather than beside it), the bottom or top
    /// one for a horizontal axis; at a block centre the bottom one for a vertical
    /// axis, the left one for a horizontal one. Ties (up to `1e-9` of the offsets) go to the lower centroid along the
    /// axis (`y` for a vertical axis, also unchanged by the mirror), then to the
    /// lower index. A point on a vertex of the mirror line itself (a grid corner on
    /// it) has candidates that are mirror images of each other: no choice keeps
    /// the symmetry there.
    pub fn triangle_kept_at(&self, t: usize, p: Vec2, axis: MirrorAxis) -> usize {
        let l = self.barycentric(t, p);
        let on: [bool; 3] = std::array::from_fn(|k| l[k] <= locate::INSIDE_TOLERANCE);
        let vertices = self.triangles[t];
        let feature = match on.iter().filter(|&&o| o).count() {
            1 => {
                let m = on.iter().position(|&o| o).unwrap();
                let (a, b) = (vertices[(m + 1) % 3], vertices[(m + 2) % 3]);
                (self.vertices[a] + self.vertices[b]) * 0.5
            }
            2 => self.vertices[vertices[on.iter().position(|&o| !o).unwrap()]],
            _ => return t,
        };
        // (primary key, secondary key) of a candidate: larger primary, then lower
        // secondary, wins.
        let key = |n: usize| {
            let [a, b, c] = self.triangle_points(n);
            let centroid = (a + b + c) / 3.0;
            let d = centroid - feature;
            match axis {
                MirrorAxis::Vertical => (d.y.abs() - d.x.abs(), centroid.y, d.norm()),
                MirrorAxis::Horizontal => (d.x.abs() - d.y.abs(), centroid.x, d.norm()),
                // Along (`x + y`) and across (`y − x`) a 45° line: its mirror keeps
                // the first and turns the second, as the horizontal one does with
                // `x` and `y` (the anti-diagonal's the other way round).
                MirrorAxis::Diagonal => (
                    (d.x + d.y).abs() - (d.y - d.x).abs(),
                    centroid.x + centroid.y,
                    d.norm(),
                ),
                MirrorAxis::AntiDiagonal => (
                    (d.y - d.x).abs() - (d.x + d.y).abs(),
                    centroid.y - centroid.x,
                    d.norm(),
                ),
            }
        };
        let mut best = t;
        let mut best_key = key(t);
        self.other_triangles_at(t, p, &mut |n| {
            if self
                .barycentric(n, p)
                .iter()
                .any(|&l| l < -locate::INSIDE_TOLERANCE)
            {
                return;
            }
            let k = key(n);
            let tolerance = 1e-9 * k.2.max(best_key.2);
            let wins = if (k.0 - best_key.0).abs() > tolerance {
                k.0 > best_key.0
            } else if (k.1 - best_key.1).abs() > tolerance {
                k.1 < best_key.1
            } else {
                n < best
            };
            if wins {
                best = n;
                best_key = k;
            }
        });
        best
    }
    /// Barycentric coordinates of `p` in triangle `t` (they sum to one).
    pub fn barycentric(&self, t: usize, p: Vec2) -> [f64; 3] {
        let [a, b, c] = self.triangle_points(t);
        barycentric(a, b, c, p)
    }
}

/// An axis-aligned mirror line a scene is symmetric about, which the discrete
/// choices of a basis keep where the mesh alone allows either of two mirror
/// lines. The interior vertices of the block grids have PS points symmetric about
/// both axis-aligned lines through them, and no triangle has two mirror lines: a
/// PS control triangle keeps the axis asked for
/// (`basis::powell_sabin::control_triangle`). A point on a shared edge or vertex
/// lies in several triangles, and the PL gradient there depends on which one
/// holds it: [`TriMesh::triangle_kept_at`] picks one by a rule that commutes with
/// mirrors about lines along this axis. The mass strategies that treat rows one
/// by one (lumping, the extension) keep a scene's symmetry only on a symmetric
/// basis: the axis is the scene's mirror line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MirrorAxis {
    /// A line `x = const`: a scene symmetric left to right (gravity along `y`).
    #[default]
    Vertical,
    /// A line `y = const`: a scene symmetric top to bottom (bodies striking each
    /// other along `x` about a horizontal mid-line, gravity along `x` or none).
    Horizontal,
    /// A line `y − x = const`: a scene symmetric about a 45° line (two disks
    /// striking each other along the diagonal of a square, no gravity). PS only:
    /// PL keeps point location's own triangle on an edge.
    Diagonal,
    /// A line `x + y = const`: a scene symmetric about a −45° line.
    AntiDiagonal,
}

/// The signed area of triangle (a, b, c), positive when counter-clockwise.
pub fn signed_area(a: Vec2, b: Vec2, c: Vec2) -> f64 {
    0.5 * ((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y))
}

/// Barycentric coordinates of `p` with respect to triangle (a, b, c).
pub fn barycentric(a: Vec2, b: Vec2, c: Vec2, p: Vec2) -> [f64; 3] {
    let d = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
    let l1 = ((b.x - p.x) * (c.y - p.y) - (c.x - p.x) * (b.y - p.y)) / d;
    let l2 = ((c.x - p.x) * (a.y - p.y) - (a.x - p.x) * (c.y - p.y)) / d;
    [l1, l2, 1.0 - l1 - l2]
}

/// Axis-aligned bounding box of a point set.
pub fn bounding_box(points: &[Vec2]) -> (Vec2, Vec2) {
    let mut lo = Vec2::repeat(f64::INFINITY);
    let mut hi = Vec2::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On the `four-triangles` grid, a point on a diagonal or at a block centre is
    /// held by the same triangle whichever triangle around it location found, and
    /// the mirror image of the point about a line along the axis (a block edge or
    /// a block centre line) is held by the mirror image of that triangle.
    #[test]
    fn the_triangle_kept_on_an_edge_is_the_mirror_image_of_the_partners() {
        let mesh = generators::block_grid(0.0, 4.0, 0.0, 2.0, 16, 8).unwrap();
        let centroid = |t: usize| {
            let [a, b, c] = mesh.triangle_points(t);
            (a + b + c) / 3.0
        };
        for axis in [MirrorAxis::Vertical, MirrorAxis::Horizontal] {
            let index = usize::from(axis == MirrorAxis::Horizontal);
            let mut checked = 0;
            for (i, j) in (0..16).flat_map(|i| (0..8).map(move |j| (i, j))) {
                let corner = Vec2::new(0.25 * i as f64, 0.25 * j as f64);
                // Lattice points of 4 × 4 per block on both diagonals, and the centre.
                let offset = |k: usize| 0.25 * (k as f64 + 0.5) / 4.0;
                let mut points: Vec<Vec2> = (0..4)
                    .flat_map(|k| {
                        [
                            corner + Vec2::new(offset(k), offset(k)),
                            corner + Vec2::new(offset(k), offset(3 - k)),
                        ]
                    })
                    .collect();
                points.push(corner + Vec2::new(0.125, 0.125));
                for p in points {
                    let mut around = vec![mesh.locate(p, None).unwrap()];
                    mesh.other_triangles_at(around[0], p, &mut |n| around.push(n));
                    assert!(around.len() > 1, "{p:?} is on an edge");
                    let kept: Vec<usize> = around
                        .iter()
                        .map(|&t| mesh.triangle_kept_at(t, p, axis))
                        .collect();
                    assert!(kept.iter().all(|&k| k == kept[0]), "{p:?}: {kept:?}");
                    // The mirror about the grid's middle line along the axis.
                    let mut image = p;
                    image[index] = [4.0, 2.0][index] - p[index];
                    let found = mesh.locate(image, None).unwrap();
                    let partner = mesh.triangle_kept_at(found, image, axis);
                    let mut mirrored = centroid(kept[0]);
                    mirrored[index] = [4.0, 2.0][index] - mirrored[index];
                    assert!(
                        (centroid(partner) - mirrored).norm() < 1e-12,
                        "{axis:?} {p:?}: kept {} and {} for its image",
                        kept[0],
                        partner
                    );
                    checked += 1;
                }
            }
            assert_eq!(checked, 16 * 8 * 9);
        }
    }

    fn square() -> (Vec<Vec2>, Vec<[usize; 3]>) {
        (
            vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(0.0, 1.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn valid_square_has_edges_neighbours_and_tags() {
        let (v, t) = square();
        let mut m = TriMesh::new(v, t).unwrap();
        assert_eq!(m.edges().len(), 5);
        assert_eq!(m.edges().iter().filter(|e| e.is_boundary()).count(), 4);
        assert_eq!(m.neighbours()[0][2], Some(1));
        assert!(m.require_tagged_boundary().is_err());
        assert_eq!(m.tag_box_sides(0.0, 1.0, 0.0, 1.0), 4);
        m.require_tagged_boundary().unwrap();
        assert!(matches!(
            m.tag_id("inlet"),
            Err(MeshError::UnknownTag { .. })
        ));
    }

    #[test]
    fn each_kind_of_bad_mesh_is_named() {
        let (v, _) = square();
        let err = |v: Vec<Vec2>, t: Vec<[usize; 3]>| TriMesh::new(v, t).unwrap_err();
        assert_eq!(err(v.clone(), vec![]), MeshError::Empty);
        assert!(matches!(
            err(v.clone(), vec![[0, 1, 7]]),
            MeshError::VertexOutOfRange { vertex: 7, .. }
        ));
        assert!(matches!(
            err(v.clone(), vec![[0, 1, 1]]),
            MeshError::RepeatedVertex { .. }
        ));
        assert!(matches!(
            err(v.clone(), vec![[0, 2, 1], [0, 2, 3]]),
            MeshError::InvertedTriangle { triangle: 0 }
        ));
        let mut flat = v.clone();
        flat.push(Vec2::new(2.0, 0.0));
        assert!(matches!(
            err(flat, vec![[0, 1, 4], [0, 2, 3]]),
            MeshError::DegenerateTriangle { triangle: 0, .. }
        ));
        let mut dup = v.clone();
        dup.push(Vec2::new(1.0, 1.0));
        assert!(matches!(
            err(dup, vec![[0, 1, 2], [0, 4, 3]]),
            MeshError::DuplicateVertex { a: 2, b: 4, .. }
        ));
        // Scaled by 1e300 (squared lengths overflow) or 1e-150 (areas underflow).
        for factor in [1e300, 1e31, 1e-11, 1e-150] {
            let scaled: Vec<Vec2> = v.iter().map(|p| p * factor).collect();
            assert!(
                matches!(
                    err(scaled, vec![[0, 1, 2], [0, 2, 3]]),
                    MeshError::Scale { .. }
                ),
                "{factor}"
            );
        }
        for factor in [1e29, 1e-9] {
            let scaled: Vec<Vec2> = v.iter().map(|p| p * factor).collect();
            assert!(
                TriMesh::new(scaled, vec![[0, 1, 2], [0, 2, 3]]).is_ok(),
                "{factor}"
            );
        }
        // A triangle laid inside the square, sharing none of its vertices.
        let mut over = v.clone();
        over.extend([
            Vec2::new(0.6, 0.2),
            Vec2::new(0.8, 0.2),
            Vec2::new(0.8, 0.4),
        ]);
        assert!(matches!(
            err(over, vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]]),
            MeshError::Overlap { .. }
        ));
        let mut iso = v.clone();
        iso.push(Vec2::new(3.0, 3.0));
        assert!(matches!(
            err(iso, vec![[0, 1, 2], [0, 2, 3]]),
            MeshError::IsolatedVertex { vertex: 4 }
        ));
        // Three triangles on the edge 0–2.
        let mut fan = v.clone();
        fan.push(Vec2::new(2.0, 0.5));
        assert!(matches!(
            err(fan, vec![[0, 1, 2], [0, 2, 3], [0, 4, 2]]),
            MeshError::NonManifoldEdge { .. }
        ));
        // Two triangles touching only at vertex 2 (a bow tie).
        let bow = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(2.0, 1.0),
            Vec2::new(2.0, 2.0),
        ];
        assert!(matches!(
            err(bow, vec![[0, 1, 2], [2, 3, 4]]),
            MeshError::NonManifoldVertex { vertex: 2 }
        ));
        let mut nan = v.clone();
        nan[1].x = f64::NAN;
        assert!(matches!(
            err(nan, vec![[0, 1, 2]]),
            MeshError::NonFiniteVertex { vertex: 1 }
        ));
        // Messages name the entity.
        assert!(MeshError::IsolatedVertex { vertex: 4 }
            .to_string()
            .contains("vertex 4"));
    }
}
