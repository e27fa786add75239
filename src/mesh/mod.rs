//! The mesh being refined: half-edge [`Topology`] plus the geometry and the
//! bookkeeping that keeps the input's shape exact.
//!
//! Every vertex has a [`Carrier`] (an input vertex, or an input edge and a
//! parameter on it); every edge knows the input edge it lies on, if any;
//! every face knows its planar region (SPEC §2). Whether an edge may be
//! flipped is read from this bookkeeping, never from a floating-point
//! coplanarity test on computed positions.

mod topology;

pub(crate) use topology::refuse_beyond_ids;
pub use topology::{
    component_is_orientable, room_for_splits, EdgeId, FaceId, HalfEdgeId, Saved, Topology, TopologyError, VertexId,
    ADJACENCY_LIMIT, MAX_HALFEDGES, MAX_TRIANGLES,
};

use crate::geometry::{self, DelaunayTest, PairShape, RegionPlane, ALGORITHM_TOLERANCE};
use crate::samples::point_on_edge;
use crate::union_find::UnionFind;
use glam::DVec3;

/// Where a vertex of the mesh lies on the input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Carrier {
    /// It is input vertex number `.0`.
    Vertex(u32),
    /// It lies on input edge `edge` at parameter `t` ∈ (0, 1), measured from
    /// the edge's lower-numbered end: position = v0 + t·(v1 − v0).
    Edge {
        /// The input edge.
        edge: u32,
        /// The parameter along it.
        t: f64,
    },
}

/// "No input edge": the edge was made by a split or a flip, inside a region.
pub const NO_INPUT_EDGE: u32 = u32::MAX;

/// Which exactly coplanar input faces may share a planar region (and so
/// have the edges between them flipped), beyond their geometry: what the
/// input's attributes allow ([`crate::attributes::AttributeCuts`]). Faces
/// are numbered as the input's triangles.
pub trait RegionCuts {
    /// Whether nothing is ever kept apart ([`NoCuts`]): the regions are then
    /// found in one pass, without the other questions.
    fn is_none(&self) -> bool {
        false
    }

    /// Whether `f1` and `f2`, which share an edge, never share a region (a
    /// texture seam or a group boundary between them).
    fn apart(&self, f1: u32, f2: u32) -> bool;

    /// Whether `faces`, joined across flat edges not kept [`apart`], with
    /// no such edge inside them, form one region as they are (their
    /// attributes one affine field, within tolerance).
    ///
    /// [`apart`]: RegionCuts::apart
    fn whole(&self, faces: &[u32]) -> bool;

    /// Inside faces that are not [`whole`], whether `f1` and `f2`, which
    /// share an edge, stay in different regions (their attributes are not
    /// one affine field on the two, exactly).
    ///
    /// [`whole`]: RegionCuts::whole
    fn apart_within(&self, f1: u32, f2: u32) -> bool;

    /// The first face cut from the same polygon of the file as `f` (so at
    /// most `f`; `f` itself for a face of its own). A polygon's values are given at its
    /// corners only: how they spread inside it depends on how it is cut
    /// into triangles, which is delmesh's choice, not the file's. So the
    /// edges inside one flat polygon join its faces even where its values
    /// are not one affine field ([`RegionCuts::polygons_flipped_inside`]).
    fn polygon(&self, f: u32) -> u32 {
        f
    }

    /// Told how many polygons (and how many faces in them) are flipped
    /// inside though their values are not one affine field over them.
    fn polygons_flipped_inside(&self, _polygons: usize, _faces: usize) {}

    /// The regions, given as each face's `region` (any numbering), in
    /// which a vertex has two values: faces joined around it, never across
    /// a seam at it, which only a flat region that overlaps itself allows.
    /// Sorted, each once; none by default.
    fn regions_with_two_values(&self, _region: &[u32]) -> Vec<u32> {
        Vec::new()
    }
}

/// The [`RegionCuts`] of a mesh without attributes: every flat edge joins.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCuts;

impl RegionCuts for NoCuts {
    fn is_none(&self) -> bool {
        true
    }
    fn apart(&self, _: u32, _: u32) -> bool {
        false
    }
    fn whole(&self, _: &[u32]) -> bool {
        true
    }
    fn apart_within(&self, _: u32, _: u32) -> bool {
        false
    }
}

/// A triangle mesh with the bookkeeping of its input. Sizes: 12 bytes per
/// half-edge (topology) + 4 per edge (input edge) + 8 per face (topology and
/// region) + 44 per vertex (position 24, carrier 16, topology 4).
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Connectivity.
    pub topo: Topology,
    /// Vertex positions: input vertices first, then added ones.
    pub positions: Vec<DVec3>,
    /// Where each vertex lies on the input.
    pub carriers: Vec<Carrier>,
    /// The planar region of each face.
    pub face_region: Vec<u32>,
    /// For each edge, the input edge it lies on, or [`NO_INPUT_EDGE`].
    pub edge_input: Vec<u32>,
    /// The input edges, as (lower, higher) input vertex numbers.
    pub input_edges: Vec<[u32; 2]>,
    /// How many vertices the input has.
    pub n_input_vertices: usize,
    /// How many planar regions the input has.
    pub n_regions: usize,
    /// Exactly flat input edges between two planar regions: kept apart by
    /// the input's attributes ([`RegionCuts`]), they are never flipped.
    pub flat_edges_apart: usize,
    /// Input edges where the surface folds flat onto itself
    /// ([`geometry::PairShape::Folded`]: a face turned over in a flat part,
    /// or the rim of a flat two-sided sheet): never flipped, as their two
    /// faces are in different planar regions; a non-Delaunay one is split.
    pub folded_edges: usize,
    /// The ends of the first such edge (input vertices), to name it.
    pub first_folded_edge: Option<[VertexId; 2]>,
    /// Smallest angle and extreme edge lengths of the input.
    pub input_figures: InputFigures,
    /// How each planar region's faces must look along a coordinate axis
    /// (from its largest input face): the exact test every new face passes.
    pub region_plane: Vec<RegionPlane>,
    /// Whether boundary edges must be Gabriel too: the one angle opposite
    /// each at most π/2, so that its cotangent weight is not negative
    /// (`--gabriel-boundary`; off by default, where boundary edges count as
    /// Delaunay, as the spec says). [`Surface::delaunay_test`] then tests
    /// them ([`geometry::boundary_test`]), and refining splits those that
    /// fail. Set it before the first pass
    /// ([`crate::refine::non_delaunay_edges`]).
    pub gabriel_boundary: bool,
}

/// Figures of the input that the report's tables give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputFigures {
    /// Smallest corner angle, radians.
    pub min_angle: f64,
    /// The sine of [`InputFigures::min_angle`], correctly rounded from the
    /// corner's vectors ([`crate::geometry::sine_of_direction`]: the same on
    /// every platform, where `sin` and `atan2` differ in their last bit
    /// between C libraries): the sample constants derive from it.
    pub min_angle_sin: f64,
    /// Shortest edge.
    pub min_edge: f64,
    /// Longest edge.
    pub max_edge: f64,
    /// The diagonal of the axis-aligned bounding box: the mesh's size.
    pub diagonal: f64,
    /// Edges shorter than [`NEAR_COINCIDENT`] times the bounding-box
    /// diagonal of their part (their connected component: a small part
    /// beside a large one has short edges of its own):
    /// near-coincident vertices, as marching cubes leaves where the field
    /// is almost zero at a grid point. Around crowds of them refining can
    /// stall or add very many vertices (the samples near the shortest can be
    /// finer than the coordinates can express); welding them (`--repair
    /// --weld-tolerance`) is the remedy.
    pub near_coincident_edges: usize,
    /// The diagonal of the largest part holding such an edge (0 if none):
    /// [`NEAR_COINCIDENT`] times it is a weld distance that merges them.
    pub near_coincident_part: f64,
    /// The shortest such edge, as a fraction of its part's diagonal
    /// (infinite if none).
    pub near_coincident_ratio: f64,
    /// The shortest edge that is not near-coincident (infinite if none): a
    /// weld distance beyond it would merge it too.
    pub shortest_other_edge: f64,
    /// Whether every coordinate is a single-precision number (as in STL
    /// and float PLY files): planes tilted in them are far from exact.
    pub single_precision: bool,
}

/// What [`Surface::vertices_at_shared_positions`] counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SharedPositions {
    /// Added vertices at the position of another vertex, input or added.
    pub added: usize,
    /// Input vertices at the position of another input vertex.
    pub input: usize,
}

/// An edge shorter than this fraction of the mesh's size joins
/// near-coincident vertices ([`InputFigures::near_coincident_edges`]): below
/// what single precision can tell apart at that size (2⁻²³ ≈ 1.2e-7), so no
/// scanner or modeller meant it. Marching cubes leaves such edges where it
/// clamps its crossings a millionth of a cell from the grid points (a
/// 20-cell sphere: vertices 4e-8 of its size apart; 17 of the 18 settings
/// get stuck or pass 300,000 added vertices, the other adds 274,350, and
/// welded it takes 2,130), or computes them exactly (1e-17 apart).
pub const NEAR_COINCIDENT: f64 = 1e-7;

/// What [`Surface::figures`] finds of near-coincident edges.
struct NearCoincidentFigures {
    /// [`InputFigures::near_coincident_edges`].
    edges: usize,
    /// [`InputFigures::near_coincident_part`].
    part: f64,
    /// [`InputFigures::near_coincident_ratio`].
    ratio: f64,
    /// [`InputFigures::shortest_other_edge`].
    shortest_other: f64,
}

/// Two faces whose planes meet at less than this angle (radians) are meant
/// to be one plane ([`Surface::nearly_flat_input_edges`]): far below what a
/// modeller or scanner resolves, far above what rounding a rotated plane's
/// vertices leaves (about 1e-16).
pub const NEARLY_FLAT: f64 = 1e-9;

/// [`NEARLY_FLAT`] for an input whose coordinates are all single-precision
/// numbers (STL, float PLY): rounding a tilted plane's vertices to 24 bits
/// leaves creases of about 1e-7 rad, far below this still, and far below
/// the angle between neighbouring faces of any tessellated curve.
pub const NEARLY_FLAT_SINGLE: f64 = 1e-5;

/// The least extent of a near-plane that [`Surface::nearly_flat_input_edges`]
/// counts, as a fraction of the mesh's size.
const NEARLY_FLAT_EXTENT: f64 = 1e-3;

/// Why [`Surface::new`] refuses a mesh: what the command line's readers
/// refuse in a file (their messages name its lines instead).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum InputError {
    /// There are no triangles: nothing to make Delaunay (the readers refuse
    /// a file without faces).
    NoFaces,
    /// The triangles do not make a manifold, consistently oriented mesh.
    Topology(TopologyError),
    /// A coordinate of this vertex is NaN or infinite.
    NonFinite {
        /// The vertex (0-based).
        vertex: u32,
    },
    /// A coordinate of this vertex is beyond ±[`crate::io::MAX_COORDINATE`]:
    /// products of such coordinates overflow.
    OutOfRange {
        /// The vertex (0-based).
        vertex: u32,
    },
    /// No triangle uses this vertex: the mesh would be one the construction
    /// cannot grow around (and a Laplacian gets an empty row for it).
    UnusedVertex {
        /// The vertex (0-based).
        vertex: u32,
    },
    /// This triangle's corners are collinear, exactly.
    ZeroArea {
        /// The triangle (0-based).
        face: usize,
    },
    /// This triangle has an edge shorter than [`crate::io::MIN_EDGE`]: the
    /// Delaunay test's products of lengths would underflow.
    EdgeTooShort {
        /// The triangle (0-based).
        face: usize,
    },
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InputError::NoFaces => write!(f, "the mesh has no triangles"),
            InputError::Topology(e) => write!(f, "{e}"),
            InputError::NonFinite { vertex } => write!(f, "vertex {vertex} has a non-finite coordinate"),
            InputError::OutOfRange { vertex } => write!(
                f,
                "vertex {vertex} has a coordinate beyond ±{:e}, the supported range",
                crate::io::MAX_COORDINATE
            ),
            InputError::UnusedVertex { vertex } => write!(f, "vertex {vertex} is in no triangle"),
            InputError::ZeroArea { face } => write!(f, "triangle {face} has zero area (collinear corners)"),
            InputError::EdgeTooShort { face } => write!(f, "triangle {face} {}", crate::io::short_edge_text()),
        }
    }
}

impl std::error::Error for InputError {}

impl From<TopologyError> for InputError {
    fn from(e: TopologyError) -> Self {
        InputError::Topology(e)
    }
}

impl Surface {
    /// Builds the mesh of an input whose equal positions are one vertex (as
    /// the readers weld them; not checked here). Refused, as the readers
    /// refuse a file, with an error naming the 0-based vertex or triangle:
    /// no triangles, a coordinate that is not finite or beyond
    /// ±[`crate::io::MAX_COORDINATE`], a vertex no triangle uses, an edge
    /// shorter than [`crate::io::MIN_EDGE`], a triangle of zero area,
    /// triangles that do not make a manifold, consistently oriented mesh.
    pub fn new(positions: Vec<DVec3>, triangles: &[[u32; 3]]) -> Result<Surface, InputError> {
        Surface::with_region_cuts(positions, triangles, &NoCuts)
    }

    /// As [`Surface::new`] (with the same refusals), but exactly coplanar
    /// input faces share a planar region only as `cuts` allow (an edge
    /// between two regions is never flipped). Used to keep texture seams,
    /// groups and the attributes' fields ([`crate::attributes`]).
    pub fn with_region_cuts(
        positions: Vec<DVec3>,
        triangles: &[[u32; 3]],
        cuts: &dyn RegionCuts,
    ) -> Result<Surface, InputError> {
        if triangles.is_empty() {
            return Err(InputError::NoFaces);
        }
        refuse_beyond_ids(positions.len(), triangles.len())?;
        if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
            return Err(InputError::NonFinite { vertex: v as u32 });
        }
        if let Some(v) = positions.iter().position(|&p| !crate::io::in_supported_range(p)) {
            return Err(InputError::OutOfRange { vertex: v as u32 });
        }
        let topo = Topology::from_triangles(positions.len(), triangles)?;
        if let Some(v) = (0..positions.len() as u32).find(|&v| topo.vertex_he(VertexId(v)).is_none()) {
            return Err(InputError::UnusedVertex { vertex: v });
        }
        let corners = |t: &[u32; 3]| t.map(|v| positions[v as usize]);
        // Below the supported scale first, as the readers test (the exact
        // collinearity test would not underflow, the Delaunay test would).
        if let Some(face) =
            (triangles.iter().map(corners)).position(|[a, b, c]| !crate::io::edges_in_supported_scale(a, b, c))
        {
            return Err(InputError::EdgeTooShort { face });
        }
        let collinear = geometry::collinear_for(&positions);
        if let Some(face) = triangles.iter().map(corners).position(|[a, b, c]| collinear(a, b, c)) {
            return Err(InputError::ZeroArea { face });
        }
        Ok(Surface::with_topology(positions, topo, cuts))
    }

    /// As [`Surface::with_region_cuts`], with the connectivity already built
    /// ([`Topology::from_triangles`] of the same positions and triangles),
    /// and nothing refused: for an input already checked (by the readers, or
    /// [`crate::io::build_surface_with`]).
    pub fn with_topology(positions: Vec<DVec3>, topo: Topology, cuts: &dyn RegionCuts) -> Surface {
        let n = positions.len();
        let spare = room_for_splits(topo.n_faces());
        let mut positions = positions;
        positions.reserve_exact(spare);
        let input_edges = (0..topo.n_edges())
            .map(|e| {
                let h = EdgeId(e as u32).halfedge();
                let (a, b) = (topo.origin(h).0, topo.dest(h).0);
                [a.min(b), a.max(b)]
            })
            .collect();
        let mut s = Surface {
            edge_input: {
                let mut v = Vec::with_capacity(topo.n_edges() + 3 * spare);
                v.extend(0..topo.n_edges() as u32);
                v
            },
            carriers: {
                let mut v = Vec::with_capacity(n + spare);
                v.extend((0..n as u32).map(Carrier::Vertex));
                v
            },
            face_region: Vec::new(),
            gabriel_boundary: false,
            n_input_vertices: n,
            n_regions: 0,
            flat_edges_apart: 0,
            folded_edges: 0,
            first_folded_edge: None,
            input_figures: InputFigures {
                min_angle: 0.0,
                min_angle_sin: 0.0,
                min_edge: 0.0,
                max_edge: 0.0,
                diagonal: 0.0,
                near_coincident_edges: 0,
                near_coincident_part: 0.0,
                near_coincident_ratio: f64::INFINITY,
                shortest_other_edge: f64::INFINITY,
                single_precision: false,
            },
            region_plane: Vec::new(),
            input_edges,
            positions,
            topo,
        };
        s.find_regions(cuts);
        s.input_figures = s.figures();
        s
    }

    /// Joins faces across exactly flat edges into planar regions, as `cuts`
    /// allow: first into candidates, across the edges that `cuts` does not
    /// keep [`RegionCuts::apart`]; a candidate with no such edge inside it
    /// that `cuts` finds [`RegionCuts::whole`] is one region; the others
    /// are joined only across the edges [`RegionCuts::apart_within`] allows.
    fn find_regions(&mut self, cuts: &dyn RegionCuts) {
        let n_faces = self.topo.n_faces();
        // The exact test on every interior edge (read-only: on every core),
        // then the joins (sequential, cheap). It tells folds too, at no cost:
        // a pair in one plane is one or the other.
        // Coordinates checked once for the whole mesh, not per edge.
        let pair_shape = geometry::pair_shape_for(&self.positions);
        let parts = crate::parallel::map_ranges(self.topo.n_edges(), |edges| {
            let (mut flat, mut folded) = (Vec::new(), Vec::new());
            for e in edges.map(|e| EdgeId(e as u32)) {
                if !self.topo.is_interior(e) {
                    continue;
                }
                let [a, b, c, d] = self.edge_quad(e);
                match pair_shape(a, b, c, d) {
                    PairShape::Flat => flat.push(e.0),
                    PairShape::Folded => folded.push(e.0),
                    PairShape::Bent => {}
                }
            }
            (flat, folded)
        });
        let (flat, folded): (Vec<Vec<u32>>, Vec<Vec<u32>>) = parts.into_iter().unzip();
        let flat = crate::parallel::concat(flat);
        self.folded_edges = folded.iter().map(Vec::len).sum();
        self.first_folded_edge = folded.iter().flatten().next().map(|&e| {
            let h = EdgeId(e).halfedge();
            [self.topo.origin(h), self.topo.dest(h)]
        });
        let faces_of = |e: u32| {
            let h = EdgeId(e).halfedge();
            (self.topo.face(h).0, self.topo.face(h.twin()).0)
        };
        let mut sets = UnionFind::new(n_faces);
        if cuts.is_none() {
            for &e in &flat {
                let (f1, f2) = faces_of(e);
                sets.union(f1 as usize, f2 as usize);
            }
        } else {
            let apart: Vec<bool> = flat
                .iter()
                .map(|&e| {
                    let (f1, f2) = faces_of(e);
                    cuts.apart(f1, f2)
                })
                .collect();
            for (&e, _) in flat.iter().zip(&apart).filter(|(_, &apart)| !apart) {
                let (f1, f2) = faces_of(e);
                sets.union(f1 as usize, f2 as usize);
            }
            // Candidates with an edge kept apart inside them (joined around
            // it) are never whole.
            let mut whole = vec![true; n_faces];
            for (&e, _) in flat.iter().zip(&apart).filter(|(_, &apart)| apart) {
                let (f1, f2) = faces_of(e);
                let (r1, r2) = (sets.find(f1 as usize), sets.find(f2 as usize));
                if r1 == r2 {
                    whole[r1] = false;
                }
            }
            // Each candidate's faces, in order (a counting sort by root).
            let roots: Vec<u32> = (0..n_faces).map(|f| sets.find(f) as u32).collect();
            let mut start = vec![0u32; n_faces + 1];
            for &r in &roots {
                start[r as usize + 1] += 1;
            }
            for r in 0..n_faces {
                start[r + 1] += start[r];
            }
            let mut members = vec![0u32; n_faces];
            let mut next = start.clone();
            for (f, &r) in roots.iter().enumerate() {
                members[next[r as usize] as usize] = f as u32;
                next[r as usize] += 1;
            }
            for r in 0..n_faces {
                let faces = &members[start[r] as usize..start[r + 1] as usize];
                if faces.len() > 1 && whole[r] {
                    whole[r] = cuts.whole(faces);
                }
            }
            // The regions: whole candidates, and the others joined edge by
            // edge: inside one polygon of the file always (its values are
            // given at its corners only, see `RegionCuts::polygon`); between
            // faces of two polygons where the values are one affine field on
            // the two faces exactly, and each polygon is one such field
            // itself (a loose polygon, flipped inside though its values are
            // not, joins nothing else: a flip across its outline would
            // spread its values over the neighbour's).
            let joins: Vec<(u32, u32, bool)> = flat
                .iter()
                .zip(&apart)
                .filter(|(_, &apart)| !apart)
                .map(|(&e, _)| {
                    let (f1, f2) = faces_of(e);
                    let exact = whole[roots[f1 as usize] as usize] || !cuts.apart_within(f1, f2);
                    (f1, f2, exact)
                })
                .collect();
            // (The first face of a polygon is at most any of its faces: a
            // number past that, from another `RegionCuts`, is taken as none.)
            let polygon = |f: u32| cuts.polygon(f).min(f);
            let mut loose = vec![false; n_faces];
            for &(f1, f2, exact) in &joins {
                let p = polygon(f1);
                if !exact && p == polygon(f2) {
                    loose[p as usize] = true;
                }
            }
            let joined = |f1: u32, f2: u32, exact: bool| {
                let (p1, p2) = (polygon(f1), polygon(f2));
                p1 == p2 || (exact && !loose[p1 as usize] && !loose[p2 as usize])
            };
            sets = UnionFind::new(n_faces);
            for &(f1, f2, exact) in &joins {
                if joined(f1, f2, exact) {
                    sets.union(f1 as usize, f2 as usize);
                }
            }
            // A region in which a vertex has two values (joined around it
            // where the region overlaps itself) is taken apart into its
            // faces: a flip there could spread either value over the other.
            let roots: Vec<u32> = (0..n_faces).map(|f| sets.find(f) as u32).collect();
            let two_values = cuts.regions_with_two_values(&roots);
            if !two_values.is_empty() {
                sets = UnionFind::new(n_faces);
                for &(f1, f2, exact) in &joins {
                    if joined(f1, f2, exact) && two_values.binary_search(&roots[f1 as usize]).is_err() {
                        sets.union(f1 as usize, f2 as usize);
                    }
                }
            }
            let polygons = loose.iter().filter(|&&l| l).count();
            if polygons > 0 {
                let faces = (0..n_faces as u32).filter(|&f| loose[polygon(f) as usize]).count();
                cuts.polygons_flipped_inside(polygons, faces);
            }
        }
        let mut id = vec![u32::MAX; n_faces];
        let mut next = 0u32;
        self.face_region = Vec::with_capacity(n_faces + 2 * room_for_splits(n_faces));
        self.face_region.extend((0..n_faces as u32).map(|f| {
            let r = sets.find(f as usize);
            if id[r] == u32::MAX {
                id[r] = next;
                next += 1;
            }
            id[r]
        }));
        self.n_regions = next as usize;
        self.flat_edges_apart = flat
            .iter()
            .filter(|&&e| {
                let (f1, f2) = faces_of(e);
                self.face_region[f1 as usize] != self.face_region[f2 as usize]
            })
            .count();
        // Each region's plane, from its first face (any face gives the same:
        // see `RegionPlane::of_face`).
        let mut first = vec![FaceId::NONE; self.n_regions];
        for f in 0..n_faces {
            let r = self.face_region[f] as usize;
            if first[r].is_none() {
                first[r] = FaceId(f as u32);
            }
        }
        self.region_plane = crate::parallel::map(first.len(), |r| RegionPlane::of_face(self.face_positions(first[r])));
    }

    /// Positions (a, b, c, d) of the interior edge `e` = a→b (its first
    /// half-edge) with faces (a, b, c) and (b, a, d).
    #[inline(always)]
    pub fn edge_quad(&self, e: EdgeId) -> [DVec3; 4] {
        let h = e.halfedge();
        let t = &self.topo;
        let p = &self.positions;
        [
            p[t.origin(h).idx()],
            p[t.dest(h).idx()],
            p[t.apex(h).idx()],
            p[t.apex(h.twin()).idx()],
        ]
    }

    /// With [`Surface::gabriel_boundary`], the positions (a, b, c) of the
    /// boundary edge `e` = a→b, running along its one face (a, b, c); `None`
    /// without it, or for an interior edge (or a dead one).
    #[inline]
    pub fn boundary_triangle(&self, e: EdgeId) -> Option<[DVec3; 3]> {
        if !self.gabriel_boundary {
            return None;
        }
        let h = self.boundary_side(e)?;
        let (t, p) = (&self.topo, &self.positions);
        Some([t.origin(h), t.dest(h), t.apex(h)].map(|v| p[v.idx()]))
    }

    /// The half-edge of the boundary edge `e` that has the face; `None` if
    /// `e` is interior or has no face at all.
    #[inline]
    pub fn boundary_side(&self, e: EdgeId) -> Option<HalfEdgeId> {
        let h = e.halfedge();
        match (self.topo.is_boundary_he(h), self.topo.is_boundary_he(h.twin())) {
            (false, true) => Some(h),
            (true, false) => Some(h.twin()),
            _ => None,
        }
    }

    /// `(sin, cos)` of α + β − π for an interior edge, up to a positive
    /// factor (see [`geometry::excess_sin_cos`]); `None` on the boundary.
    #[inline]
    pub fn excess_sin_cos(&self, e: EdgeId) -> Option<(f64, f64)> {
        if !self.topo.is_interior(e) {
            // With `gabriel_boundary`: γ − π/2 of the angle γ opposite it.
            let [a, b, c] = self.boundary_triangle(e)?;
            return Some(geometry::boundary_excess_sin_cos(a, b, c));
        }
        let [a, b, c, d] = self.edge_quad(e);
        Some(geometry::excess_sin_cos(a, b, c, d))
    }

    /// Whether `e` is interior and its opposite angles exceed π by more than
    /// `tolerance`.
    #[inline(always)]
    pub fn is_non_delaunay(&self, e: EdgeId, tolerance: f64) -> bool {
        self.delaunay_test(e, tolerance) != DelaunayTest::Delaunay
    }

    /// [`geometry::delaunay_test`] of `e`; a boundary edge is Delaunay,
    /// unless [`Surface::gabriel_boundary`] asks for its
    /// [`geometry::boundary_test`].
    #[inline(always)]
    pub fn delaunay_test(&self, e: EdgeId, tolerance: f64) -> DelaunayTest {
        if !self.topo.is_interior(e) {
            return match self.boundary_triangle(e) {
                Some([a, b, c]) => geometry::boundary_test(a, b, c, tolerance),
                None => DelaunayTest::Delaunay,
            };
        }
        let [a, b, c, d] = self.edge_quad(e);
        geometry::delaunay_test(a, b, c, d, tolerance)
    }

    /// α + β − π of an interior edge (radians); `None` on the boundary,
    /// or γ − π/2 there with [`Surface::gabriel_boundary`].
    pub fn delaunay_excess(&self, e: EdgeId) -> Option<f64> {
        if !self.topo.is_interior(e) {
            let [a, b, c] = self.boundary_triangle(e)?;
            return Some(geometry::boundary_excess(a, b, c));
        }
        let [a, b, c, d] = self.edge_quad(e);
        Some(geometry::delaunay_excess(a, b, c, d))
    }

    /// Whether `e` may be flipped: it is interior and both its faces are in
    /// one planar region (decided on the input, exactly).
    #[inline]
    pub fn is_flippable(&self, e: EdgeId) -> bool {
        let h = e.halfedge();
        let (f1, f2) = (self.topo.face(h), self.topo.face(h.twin()));
        !f1.is_none() && !f2.is_none() && self.face_region[f1.idx()] == self.face_region[f2.idx()]
    }

    /// Length of edge `e`.
    #[inline]
    pub fn edge_length(&self, e: EdgeId) -> f64 {
        let h = e.halfedge();
        (self.positions[self.topo.dest(h).idx()] - self.positions[self.topo.origin(h).idx()]).length()
    }

    /// The parameter of vertex `v` along input edge `edge` (0 or 1 at its
    /// ends). `v` must lie on that edge.
    pub fn param_on(&self, v: VertexId, edge: u32) -> f64 {
        match self.carriers[v.idx()] {
            Carrier::Vertex(i) => {
                if i == self.input_edges[edge as usize][0] {
                    0.0
                } else {
                    1.0
                }
            }
            Carrier::Edge { t, .. } => t,
        }
    }

    /// Edge `e` as the input knows it (for [`crate::Error::Unsplittable`]).
    pub fn stuck_edge(&self, e: EdgeId) -> crate::error::StuckEdge {
        use crate::error::EdgeEnd;
        let h = e.halfedge();
        let end = |v: VertexId| match self.vertex_source(v) {
            (a, b, _) if a == b => EdgeEnd::Vertex(a),
            (a, b, _) => EdgeEnd::OnEdge(a, b),
        };
        let (a, b) = (self.topo.origin(h), self.topo.dest(h));
        let middle = (self.positions[a.idx()] + self.positions[b.idx()]) / 2.0;
        crate::error::StuckEdge::new([end(a), end(b)], middle.to_array()).on_boundary(!self.topo.is_interior(e))
    }

    /// Where each vertex comes from: `(a, b, t)` with input vertices `a`,
    /// `b` and its position exactly `p_a + t·(p_b − p_a)` in f64 (the
    /// formula of [`point_on_edge`]). An input vertex is `(i, i, 0)`.
    pub fn vertex_sources(&self) -> Vec<(u32, u32, f64)> {
        (0..self.carriers.len() as u32)
            .map(|v| self.vertex_source(VertexId(v)))
            .collect()
    }

    /// Where vertex `v` comes from, as [`Surface::vertex_sources`] says.
    pub fn vertex_source(&self, v: VertexId) -> (u32, u32, f64) {
        match self.carriers[v.idx()] {
            Carrier::Vertex(i) => (i, i, 0.0),
            Carrier::Edge { edge, t } => {
                let [a, b] = self.input_edges[edge as usize];
                (a, b, t)
            }
        }
    }

    /// End points of input edge `edge`.
    #[inline]
    pub fn input_edge_ends(&self, edge: u32) -> [DVec3; 2] {
        let [a, b] = self.input_edges[edge as usize];
        [self.positions[a as usize], self.positions[b as usize]]
    }

    /// Reserves room for `splits` more splits, so that the main loop does not
    /// regrow (copy) its arrays. Reserved memory is not touched until used.
    pub fn reserve_splits(&mut self, splits: usize) {
        self.topo.reserve_splits(splits);
        self.positions.reserve(splits);
        self.carriers.reserve(splits);
        self.edge_input.reserve(3 * splits);
        self.face_region.reserve(2 * splits);
    }

    /// The vertices that have the position of another vertex (one pass over
    /// the positions, a hash): the added ones among them (beside an input or
    /// another added vertex: the sheets of an edge that `--repair` cut apart,
    /// two input edges on one segment, each split at the same sample), and
    /// the input ones that share a position with another input vertex (the
    /// copies `--repair` makes where it cuts an edge or a vertex apart;
    /// reading welds every other shared position). The mesh keeps them apart
    /// by index; a file that copies vertices at attribute seams (PLY, OFF)
    /// or for their colours (OBJ) can only be read back by welding
    /// positions, and which copies are one vertex is then a guess.
    pub fn vertices_at_shared_positions(&self) -> SharedPositions {
        use crate::hash::{position_key, FastMap};
        // Per position: how many input vertices are there, how many added.
        // (Room for every position at once: growing the table rehashed it
        // a third of the pass's time on a textured million-face output.)
        let mut at: FastMap<[u64; 3], (u32, u32)> =
            FastMap::with_capacity_and_hasher(self.positions.len(), Default::default());
        let n = self.n_input_vertices;
        for (v, p) in self.positions.iter().enumerate() {
            let place = at.entry(position_key(p.to_array())).or_default();
            if v < n {
                place.0 += 1;
            } else {
                place.1 += 1;
            }
        }
        let mut shared = SharedPositions::default();
        for &(input, added) in at.values() {
            if added > 1 || (added > 0 && input > 0) {
                shared.added += added as usize;
            }
            if input > 1 {
                shared.input += input as usize;
            }
        }
        shared
    }

    /// How many input edges join two faces that are coplanar to within
    /// [`NEARLY_FLAT`] radians ([`NEARLY_FLAT_SINGLE`] for single-precision
    /// coordinates) but not exactly (nor kept apart on purpose,
    /// as by a texture seam), where such edges join three or more planar
    /// regions into one near-plane: a flat part rotated or tilted in
    /// floating point, whose vertices can no longer lie exactly in one
    /// plane. Such an edge is a crease to delmesh, which keeps the geometry
    /// exactly, so no flip crosses it, and a flat region cut up so can need
    /// very many added vertices (a 100:1 oval fanned from one corner: none
    /// when exactly flat, millions when tilted by a rounding). Two faces
    /// alone cost a split at most, and near-planes smaller than a thousandth
    /// of the mesh are not counted.
    /// Read from the mesh as it is (its pieces of input edges keep their
    /// input faces' planes); for messages, not for the algorithm.
    pub fn nearly_flat_input_edges(&self) -> usize {
        let nearly = if self.input_figures.single_precision {
            NEARLY_FLAT_SINGLE
        } else {
            NEARLY_FLAT
        };
        let mut nearly_flat = Vec::new();
        let mut seen = vec![false; self.input_edges.len()];
        for e in (0..self.topo.n_edges() as u32).map(EdgeId) {
            let input = self.edge_input[e.idx()];
            if input == NO_INPUT_EDGE || seen[input as usize] || !self.topo.is_interior(e) {
                continue;
            }
            let h = e.halfedge();
            let (f1, f2) = (self.topo.face(h), self.topo.face(h.twin()));
            let (r1, r2) = (self.face_region[f1.idx()], self.face_region[f2.idx()]);
            if r1 == r2 {
                continue;
            }
            let [a, b, c, d] = self.edge_quad(e);
            // The faces (a, b, c) and (b, a, d), their normals alike oriented.
            let (n1, n2) = ((b - a).cross(c - a), (a - b).cross(d - b));
            let sine = n1.cross(n2).length() / (n1.length() * n2.length());
            if n1.dot(n2) > 0.0 && sine < nearly && !geometry::flat_pair(a, b, c, d) {
                seen[input as usize] = true;
                nearly_flat.push((r1, r2, [a, b, c, d]));
            }
        }
        // The near-planes: regions joined across those edges, each with how
        // many regions it holds and the box of its corners seen.
        let n_regions = self.region_plane.len();
        let mut sets = UnionFind::new(n_regions);
        for &(r1, r2, _) in &nearly_flat {
            sets.union(r1 as usize, r2 as usize);
        }
        let mut size = vec![0u32; n_regions];
        for r in 0..n_regions {
            size[sets.find(r)] += 1;
        }
        let mut boxes = vec![(DVec3::INFINITY, DVec3::NEG_INFINITY); n_regions];
        for &(r, _, quad) in &nearly_flat {
            let b = &mut boxes[sets.find(r as usize)];
            for p in quad {
                *b = (b.0.min(p), b.1.max(p));
            }
        }
        // A near-plane of tiny faces (a crowd of near-coincident vertices,
        // as marching cubes leaves around a grid point, is flat at its own
        // scale) costs nothing like a flat part of the mesh's size.
        let least_extent = NEARLY_FLAT_EXTENT * self.input_figures.diagonal;
        nearly_flat
            .iter()
            .filter(|&&(r, _, _)| {
                let k = sets.find(r as usize);
                size[k] >= 3 && (boxes[k].1 - boxes[k].0).max_element() >= least_extent
            })
            .count()
    }

    /// Whether flipping the flippable edge `e` = (a, b) into (c, d) gives a
    /// valid mesh: both new faces must face the way of their region's plane
    /// (the judge's own criterion), and c–d must not already be an edge. In
    /// exact arithmetic a non-Delaunay edge of a flat region always passes;
    /// with needle triangles, whose computed positions are off by rounding,
    /// a flip can fold a face or duplicate an edge (also where the region
    /// overlaps itself). The adjacency test walks the fans of c and d side
    /// by side ([`Topology::are_adjacent_within_either`]), so that a flip
    /// beside a vertex with thousands of neighbours stays cheap. The new
    /// edge c–d must also be Delaunay itself (see below).
    pub fn flip_is_valid(&self, e: EdgeId) -> bool {
        self.flip_check(e, true)
    }

    /// [`Surface::flip_is_valid`] without its Delaunay test: whether the
    /// flip gives a valid mesh, whatever it does to the angles (the flips
    /// of [`crate::convex_regions`], which pass through triangulations
    /// farther from Delaunay on their way to it).
    pub fn flip_is_possible(&self, e: EdgeId) -> bool {
        self.flip_check(e, false)
    }

    #[inline(always)]
    fn flip_check(&self, e: EdgeId, new_edge_delaunay: bool) -> bool {
        let h = e.halfedge();
        let (c, d) = (self.topo.apex(h), self.topo.apex(h.twin()));
        // Unknown (both fans longer than the limit, which only settings
        // that split beside one vertex again and again reach) counts as
        // adjacent: refusing a flip is always safe, the edge is then split
        // (or left for the final count), and each test stays bounded.
        self.flip_shape_check(e, new_edge_delaunay)
            && self.topo.are_adjacent_within_either(c, d, ADJACENCY_LIMIT) == Some(false)
    }

    /// The edge c–d that alone keeps the flippable edge `e` = (a, b) from
    /// being flipped into (c, d) ([`Surface::flip_is_valid`]): c and d are
    /// joined already, elsewhere (where a region overlaps itself, as the two
    /// sheets of a flat two-sided plate do along their shared rim), and the
    /// flip is valid otherwise. `None` if the flip is valid, or invalid for
    /// another reason.
    pub fn edge_blocking_flip(&self, e: EdgeId) -> Option<EdgeId> {
        let h = e.halfedge();
        let (c, d) = (self.topo.apex(h), self.topo.apex(h.twin()));
        if !self.flip_shape_check(e, true) {
            return None;
        }
        let mut joining = None;
        self.topo.for_each_neighbour(c, |edge, v| {
            if v == d {
                joining = Some(edge);
            }
        });
        joining
    }

    /// [`Surface::flip_check`] but for the test that c–d is not an edge
    /// already.
    #[inline(always)]
    fn flip_shape_check(&self, e: EdgeId, new_edge_delaunay: bool) -> bool {
        let h = e.halfedge();
        let (c, d) = (self.topo.apex(h), self.topo.apex(h.twin()));
        if c == d {
            return false;
        }
        let (a, b) = (self.topo.origin(h), self.topo.dest(h));
        if self.on_one_input_edge([d, c, a]) || self.on_one_input_edge([c, d, b]) {
            return false;
        }
        let [a3, b3, c3, d3] = self.edge_quad(e);
        // After the flip: (d, c, a) and (c, d, b), both in the region of the
        // two faces now; each must have the region's orientation, exactly.
        let plane = self.region_plane[self.face_region[self.topo.face(h).idx()] as usize];
        if !plane.is_proper([d3, c3, a3]) || !plane.is_proper([c3, d3, b3]) {
            return false;
        }
        // The new edge must itself be Delaunay: on a quad that is degenerate
        // to rounding, both diagonals can look non-Delaunay, and flipping
        // would then go back and forth for ever.
        !(new_edge_delaunay && geometry::is_non_delaunay(c3, d3, a3, b3, ALGORITHM_TOLERANCE))
    }

    /// Whether the bookkeeping says that the three vertices all lie on one
    /// input edge: a face joining them would be exactly degenerate (rounding
    /// only makes it look like a sliver), which no flip may create.
    fn on_one_input_edge(&self, vs: [VertexId; 3]) -> bool {
        let on = |v: VertexId, edge: u32| match self.carriers[v.idx()] {
            Carrier::Vertex(i) => self.input_edges[edge as usize].contains(&i),
            Carrier::Edge { edge: other, .. } => other == edge,
        };
        vs.iter().any(|&v| match self.carriers[v.idx()] {
            Carrier::Edge { edge, .. } => vs.iter().all(|&w| on(w, edge)),
            Carrier::Vertex(_) => false,
        })
    }

    /// Flips edge `e` (which must be flippable). See [`Topology::flip`].
    pub fn flip(&mut self, e: EdgeId) {
        self.topo.flip(e);
        self.edge_input[e.idx()] = NO_INPUT_EDGE;
    }

    /// Whether splitting `e` = (a, b) at parameter `t` of its input edge gives
    /// faces that each have their region's orientation, exactly (see
    /// [`RegionPlane::is_proper`]). Always so in exact arithmetic; a point
    /// rounded to within a few ulps of a or b, or of the line from a or b to
    /// an apex, can fail it:
    ///
    /// ```text
    ///        c                    c
    ///       / \                  /|\
    ///      /   \                / | \
    ///     a-----b      ->      a--p--b     (a, p, c), (p, b, c),
    ///      \   /                \ | /      (b, p, d), (p, a, d)
    ///       \ /                  \|/
    ///        d                    d
    /// ```
    pub fn split_is_valid(&self, e: EdgeId, t: f64) -> bool {
        let [p0, p1] = self.input_edge_ends(self.edge_input[e.idx()]);
        let p = point_on_edge(p0, p1, t);
        // Each side (a face with corners x, y and apex z) becomes (x, p, z)
        // and (p, y, z); a boundary side has no face.
        let side = |h: HalfEdgeId| {
            let f = self.topo.face(h);
            f.is_none() || {
                let plane = self.region_plane[self.face_region[f.idx()] as usize];
                let [x, y, z] =
                    [self.topo.origin(h), self.topo.dest(h), self.topo.apex(h)].map(|v| self.positions[v.idx()]);
                plane.is_proper([x, p, z]) && plane.is_proper([p, y, z])
            }
        };
        let h = e.halfedge();
        side(h) && side(h.twin())
    }

    /// Whether face `f` has its region's orientation, exactly.
    pub fn face_is_proper(&self, f: FaceId) -> bool {
        self.region_plane[self.face_region[f.idx()] as usize].is_proper(self.face_positions(f))
    }

    /// The corner positions of face `f`.
    #[inline]
    pub fn face_positions(&self, f: FaceId) -> [DVec3; 3] {
        self.topo.face_vertices(f).map(|v| self.positions[v.idx()])
    }

    /// Splits edge `e`, which lies on an input edge, at parameter `t` of that
    /// input edge. Returns the new vertex. See [`Topology::split`] for the
    /// ids of the new edges and faces.
    pub fn split(&mut self, e: EdgeId, t: f64) -> VertexId {
        let edge = self.edge_input[e.idx()];
        debug_assert_ne!(edge, NO_INPUT_EDGE);
        let [p0, p1] = self.input_edge_ends(edge);
        let h = e.halfedge();
        let (f1, f2) = (self.topo.face(h), self.topo.face(h.twin()));
        let p = self.topo.split(e);
        self.positions.push(point_on_edge(p0, p1, t));
        self.carriers.push(Carrier::Edge { edge, t });
        self.edge_input.extend_from_slice(&[edge, NO_INPUT_EDGE, NO_INPUT_EDGE]);
        let (r1, r2) = (self.face_region[f1.idx()], self.face_region[f2.idx()]);
        self.face_region.extend_from_slice(&[r1, r2]);
        p
    }

    /// Splits the boundary edge `e`, which lies on an input edge, at
    /// parameter `t` of that input edge (with [`Surface::gabriel_boundary`]).
    /// Returns the new vertex. See [`Topology::split_boundary`] for the ids
    /// of the new edges and face.
    pub fn split_boundary(&mut self, e: EdgeId, t: f64) -> VertexId {
        let edge = self.edge_input[e.idx()];
        debug_assert_ne!(edge, NO_INPUT_EDGE);
        let [p0, p1] = self.input_edge_ends(edge);
        let f1 = self
            .boundary_side(e)
            .map(|h| self.topo.face(h))
            .expect("a boundary edge");
        let p = self.topo.split_boundary(e);
        self.positions.push(point_on_edge(p0, p1, t));
        self.carriers.push(Carrier::Edge { edge, t });
        self.edge_input.extend_from_slice(&[edge, NO_INPUT_EDGE]);
        self.face_region.push(self.face_region[f1.idx()]);
        p
    }

    /// Drops the vertices, edges and faces that [`Topology::unsplit`] left
    /// dead, renumbering the others in order (input vertices keep their ids).
    pub fn compact(&mut self) {
        let (vmap, emap, fmap) = self.topo.compact();
        fn keep<T: Copy, I: Copy>(values: &mut Vec<T>, map: &[I], is_none: fn(I) -> bool) {
            let mut w = 0;
            for i in 0..values.len() {
                if !is_none(map[i]) {
                    values[w] = values[i];
                    w += 1;
                }
            }
            values.truncate(w);
        }
        keep(&mut self.positions, &vmap, VertexId::is_none);
        keep(&mut self.carriers, &vmap, VertexId::is_none);
        keep(&mut self.edge_input, &emap, EdgeId::is_none);
        keep(&mut self.face_region, &fmap, FaceId::is_none);
    }

    /// Smallest angle, extreme edge lengths, size and near-coincident
    /// vertices.
    pub fn figures(&self) -> InputFigures {
        // The smallest angle of a triangle is opposite its shortest side and
        // is acute, where tan = |u × v| / (u · v) grows with the angle: keep
        // the smallest tangent, and take one atan2 at the end.
        // Each face's smallest corner (sine and cosine, up to a common
        // factor) on every core; the comparison then runs in face order,
        // exactly as a sequential loop would.
        let corners = crate::parallel::map(self.topo.n_faces(), |f| {
            let [a, b, c] = self.face_positions(FaceId(f as u32));
            let (ab, bc, ca) = (
                (b - a).length_squared(),
                (c - b).length_squared(),
                (a - c).length_squared(),
            );
            // The corner opposite the shortest side: (apex, one end, other end).
            let (apex, p, q) = if ab <= bc && ab <= ca {
                (c, a, b)
            } else if bc <= ca {
                (a, b, c)
            } else {
                (b, c, a)
            };
            let (u, v) = (p - apex, q - apex);
            (u.cross(v).length(), u.dot(v))
        });
        let (mut best_sin, mut best_cos) = (1.0f64, 0.0f64);
        for (sin, cos) in corners {
            // sin/cos < best_sin/best_cos without dividing (cosines are ≥ 0).
            if sin * best_cos < best_sin * cos {
                (best_sin, best_cos) = (sin, cos);
            }
        }
        let min_angle = if self.topo.n_faces() == 0 {
            f64::INFINITY
        } else {
            best_sin.atan2(best_cos)
        };
        let min_angle_sin = crate::geometry::sine_of_direction(best_sin, best_cos);
        // Minima, maxima and counts are exact, so the ranges combine in any
        // order.
        let boxes = crate::parallel::map_ranges(self.positions.len(), |r| {
            self.positions[r]
                .iter()
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
                    (lo.min(p), hi.max(p))
                })
        });
        let (lo, hi) = boxes
            .into_iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), (a, b)| {
                (lo.min(a), hi.max(b))
            });
        let diagonal = if self.positions.is_empty() {
            0.0
        } else {
            (hi - lo).length()
        };
        let near = NEAR_COINCIDENT * diagonal;
        let lengths = crate::parallel::map_ranges(self.topo.n_edges(), |r| {
            r.map(|e| self.edge_length(EdgeId(e as u32)))
                .fold((f64::INFINITY, 0.0f64, 0usize), |(lo, hi, n), l| {
                    (lo.min(l), hi.max(l), n + (l < near) as usize)
                })
        });
        let (min_edge, max_edge, near_globally) = lengths
            .into_iter()
            .fold((f64::INFINITY, 0.0f64, 0), |(lo, hi, n), (a, b, m)| {
                (lo.min(a), hi.max(b), n + m)
            });
        // An edge near-coincident in its part is so in the whole mesh too
        // (a part is no larger): the parts are looked at only if some are.
        let near = if near_globally == 0 {
            NearCoincidentFigures {
                edges: 0,
                part: 0.0,
                ratio: f64::INFINITY,
                shortest_other: min_edge,
            }
        } else {
            self.near_coincident_by_part()
        };
        InputFigures {
            min_angle,
            min_angle_sin,
            min_edge,
            max_edge,
            diagonal,
            near_coincident_edges: near.edges,
            near_coincident_part: near.part,
            near_coincident_ratio: near.ratio,
            shortest_other_edge: near.shortest_other,
            single_precision: crate::parallel::map_ranges(self.positions.len(), |r| {
                self.positions[r]
                    .iter()
                    .all(|p| p.to_array().iter().all(|&x| x as f32 as f64 == x))
            })
            .into_iter()
            .all(|single| single),
        }
    }

    /// The near-coincident edges, each measured against the diagonal of
    /// its part (connected component): see
    /// [`InputFigures::near_coincident_edges`].
    fn near_coincident_by_part(&self) -> NearCoincidentFigures {
        let n = self.positions.len();
        let mut parts = UnionFind::new(n);
        for e in 0..self.topo.n_edges() {
            let h = EdgeId(e as u32).halfedge();
            parts.union(self.topo.origin(h).idx(), self.topo.dest(h).idx());
        }
        let mut boxes = vec![(DVec3::INFINITY, DVec3::NEG_INFINITY); n];
        for v in 0..n {
            let r = parts.find(v);
            let p = self.positions[v];
            boxes[r] = (boxes[r].0.min(p), boxes[r].1.max(p));
        }
        let mut near = NearCoincidentFigures {
            edges: 0,
            part: 0.0,
            ratio: f64::INFINITY,
            shortest_other: f64::INFINITY,
        };
        for e in 0..self.topo.n_edges() {
            let e = EdgeId(e as u32);
            let r = parts.find(self.topo.origin(e.halfedge()).idx());
            let size = (boxes[r].1 - boxes[r].0).length();
            let length = self.edge_length(e);
            if length < NEAR_COINCIDENT * size {
                near.edges += 1;
                near.part = near.part.max(size);
                near.ratio = near.ratio.min(length / size);
            } else {
                near.shortest_other = near.shortest_other.min(length);
            }
        }
        near
    }

    /// Number of interior edges whose opposite angles exceed π by more than
    /// `tolerance`, and the largest excess among them.
    pub fn count_non_delaunay(&self, tolerance: f64) -> (usize, f64) {
        self.count_non_delaunay_among((0..self.topo.n_edges() as u32).map(EdgeId), tolerance)
    }

    /// [`Surface::count_non_delaunay`] among `edges` only.
    pub fn count_non_delaunay_among(&self, edges: impl IntoIterator<Item = EdgeId>, tolerance: f64) -> (usize, f64) {
        let (count, worst, _) = self.worst_non_delaunay_among(edges, tolerance);
        (count, worst)
    }

    /// [`Surface::count_non_delaunay_among`], and the first edge with the
    /// largest excess (`None` if none is non-Delaunay; an excess that is not
    /// a number, where the angles underflow, counts as the smallest).
    pub fn worst_non_delaunay_among(
        &self,
        edges: impl IntoIterator<Item = EdgeId>,
        tolerance: f64,
    ) -> (usize, f64, Option<EdgeId>) {
        let mut count = 0;
        let mut worst = f64::NEG_INFINITY;
        let mut worst_edge = None;
        for e in edges {
            if self.is_non_delaunay(e, tolerance) {
                count += 1;
                let excess = self.delaunay_excess(e).unwrap_or(0.0);
                if worst_edge.is_none() || excess > worst {
                    worst_edge = Some(e);
                }
                worst = worst.max(excess);
            }
        }
        (count, worst, worst_edge)
    }

    /// A lower bound on the vertices that any method keeping the geometry
    /// must add: the interior edges, non-Delaunay by more than twice the
    /// acceptance tolerance, whose two sides are planar regions of a single
    /// face each (with [`Surface::gabriel_boundary`], and the boundary edges
    /// so facing an obtuse angle in such a face). Inside such a face every possible opposite vertex (a point
    /// of the face) sees the edge under at least the angle its own apex
    /// does, so the edge stays non-Delaunay until a vertex is added on it.
    /// Computed on the input (before any refinement).
    pub fn added_vertex_lower_bound(&self) -> usize {
        let all: Vec<EdgeId> = (0..self.topo.n_edges() as u32).map(EdgeId).collect();
        self.added_vertex_lower_bound_among(&all)
    }

    /// [`Surface::added_vertex_lower_bound`], looking only at `candidates`,
    /// which must include every edge non-Delaunay by more than
    /// [`geometry::SEED_TOLERANCE`] (e.g. `refine::non_delaunay_edges`): the
    /// bound counts edges non-Delaunay by more than twice the acceptance
    /// tolerance, a larger one.
    pub fn added_vertex_lower_bound_among(&self, candidates: &[EdgeId]) -> usize {
        const _: () = assert!(2.0 * geometry::ACCEPT_TOLERANCE > geometry::SEED_TOLERANCE);
        let mut region_faces = vec![0u32; self.n_regions];
        for &r in &self.face_region {
            region_faces[r as usize] = region_faces[r as usize].saturating_add(1);
        }
        let single = |f: FaceId| region_faces[self.face_region[f.idx()] as usize] == 1;
        // With `gabriel_boundary`, likewise a boundary edge facing an obtuse
        // angle in its one face, a region of its own: every point of the face
        // sees it under at least that angle.
        let sides_single = |e: EdgeId| match self.boundary_side(e) {
            Some(h) => self.gabriel_boundary && single(self.topo.face(h)),
            None => {
                let h = e.halfedge();
                self.topo.is_interior(e) && single(self.topo.face(h)) && single(self.topo.face(h.twin()))
            }
        };
        (candidates.iter().copied())
            .filter(|&e| sides_single(e) && self.is_non_delaunay(e, 2.0 * geometry::ACCEPT_TOLERANCE))
            .count()
    }

    /// The faces as vertex triples.
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        self.topo.triangles()
    }

    /// Checks the topology and the bookkeeping: array sizes, carriers of
    /// vertices on their input edges, sub-edges lying on the input edge of
    /// both their end points, faces of one region across every flippable
    /// edge. Linear time; for tests.
    pub fn validate(&self) -> Result<(), String> {
        self.topo.validate()?;
        let (nv, ne, nf) = (self.topo.n_vertices(), self.topo.n_edges(), self.topo.n_faces());
        if self.positions.len() != nv || self.carriers.len() != nv {
            return Err("vertex arrays disagree in length".into());
        }
        if self.edge_input.len() != ne || self.face_region.len() != nf {
            return Err("edge or face arrays disagree in length".into());
        }
        for v in self.n_input_vertices..nv {
            match self.carriers[v] {
                Carrier::Edge { edge, t } if (edge as usize) < self.input_edges.len() && t > 0.0 && t < 1.0 => {
                    let [p0, p1] = self.input_edge_ends(edge);
                    if point_on_edge(p0, p1, t) != self.positions[v] {
                        return Err(format!("vertex {v} is not where its carrier says"));
                    }
                }
                c => return Err(format!("added vertex {v} has carrier {c:?}")),
            }
        }
        for e in 0..ne {
            let e = EdgeId(e as u32);
            let h = e.halfedge();
            let input = self.edge_input[e.idx()];
            if input == NO_INPUT_EDGE {
                // Made inside a region: both sides in one region.
                if !self.topo.is_interior(e) || !self.is_flippable(e) {
                    return Err(format!("{e:?} lies on no input edge but separates regions"));
                }
                continue;
            }
            let [i0, i1] = self.input_edges[input as usize];
            for v in [self.topo.origin(h), self.topo.dest(h)] {
                let on = match self.carriers[v.idx()] {
                    Carrier::Vertex(i) => i == i0 || i == i1,
                    Carrier::Edge { edge, .. } => edge == input,
                };
                if !on {
                    return Err(format!("{e:?} claims input edge {input} but {v:?} is not on it"));
                }
            }
        }
        Ok(())
    }
}

/// Items grouped by key (a counting sort): item `i` has key `keys[i]`; those
/// of key `k` below `n_keys`, in increasing order, are
/// `items[start[k]..start[k + 1]]` in the returned `(start, items)` (keys
/// from `n_keys` on are left out). The triangles of each region, the
/// corners of each vertex.
pub(crate) fn group_by_key(n_keys: usize, keys: impl Iterator<Item = u32> + Clone) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; n_keys + 1];
    for k in keys.clone().filter(|&k| (k as usize) < n_keys) {
        start[k as usize + 1] += 1;
    }
    for k in 0..n_keys {
        start[k + 1] += start[k];
    }
    let mut next = start.clone();
    let mut items = vec![0u32; start[n_keys] as usize];
    for (i, k) in keys.enumerate() {
        if (k as usize) < n_keys {
            items[next[k as usize] as usize] = i as u32;
            next[k as usize] += 1;
        }
    }
    (start, items)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An oval of `n` corners fanned from its first, in the plane z = 0 or
    /// turned about the x axis (its corners then off their plane by a
    /// rounding), closed by a cone below so that every edge is interior.
    fn fanned_oval(n: usize, turned: bool) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let (sin, cos) = 0.3f64.sin_cos();
        let mut positions: Vec<DVec3> = (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                let (x, y) = (10.0 * t.cos(), t.sin());
                if turned {
                    DVec3::new(x, y * cos, y * sin)
                } else {
                    DVec3::new(x, y, 0.0)
                }
            })
            .collect();
        let apex = positions.len() as u32;
        positions.push(if turned {
            DVec3::new(0.0, 3.0 * sin, -3.0 * cos)
        } else {
            DVec3::new(0.0, 0.0, -3.0)
        });
        let n = n as u32;
        let mut triangles: Vec<[u32; 3]> = (1..n - 1).map(|i| [0, i, i + 1]).collect();
        triangles.extend((0..n).map(|i| [(i + 1) % n, i, apex]));
        (positions, triangles)
    }

    #[test]
    fn folds_are_counted_where_coplanar_faces_lie_on_one_side_of_their_edge() {
        // A two-sided sheet: a triangle fanned from an inner point, closed
        // by the triangle turned over. Its three rim edges are folds, its
        // spokes flat; the fan is one region, the back another.
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.25, 0.25, 0.0),
        ];
        let sheet = [[0, 1, 3], [1, 2, 3], [2, 0, 3], [0, 2, 1]];
        let s = Surface::new(positions.clone(), &sheet).unwrap();
        s.validate().unwrap();
        assert_eq!((s.folded_edges, s.n_regions), (3, 2));
        let [a, b] = s.first_folded_edge.expect("a fold to name");
        let rim = [[0, 1], [1, 2], [2, 0]].map(|e| e.map(VertexId));
        assert!(rim.iter().any(|&e| e == [a, b] || e == [b, a]), "{a:?} {b:?}");
        // The oval's cap is flat and its cone bent: no fold.
        let (oval, triangles) = fanned_oval(12, false);
        let s = Surface::new(oval, &triangles).unwrap();
        assert_eq!((s.folded_edges, s.first_folded_edge), (0, None));
    }

    #[test]
    fn single_precision_planes_are_nearly_flat_within_their_rounding() {
        // The turned oval rounded to f32, as an STL stores it: its cap is
        // off its plane by far more than 1e-9 rad, and counted all the same.
        let (turned, triangles) = fanned_oval(40, true);
        let single: Vec<DVec3> = turned.iter().map(|p| p.as_vec3().as_dvec3()).collect();
        let s = Surface::new(single, &triangles).unwrap();
        assert!(s.input_figures.single_precision);
        let nearly_flat = s.nearly_flat_input_edges();
        assert!((20..=37).contains(&nearly_flat), "{nearly_flat}");
        let s = Surface::new(turned, &triangles).unwrap();
        assert!(!s.input_figures.single_precision);
    }

    #[test]
    fn nearly_flat_input_edges_are_those_of_a_plane_off_by_rounding() {
        let (flat, triangles) = fanned_oval(40, false);
        let s = Surface::new(flat, &triangles).unwrap();
        assert_eq!(s.nearly_flat_input_edges(), 0, "exactly flat: one region");
        let (turned, triangles) = fanned_oval(40, true);
        let s = Surface::new(turned, &triangles).unwrap();
        // The cap's 37 inner edges, some of them exactly flat by chance.
        let nearly_flat = s.nearly_flat_input_edges();
        assert!((1..=37).contains(&nearly_flat), "{nearly_flat}");
        // A cube's edges are real creases, its faces' diagonals exactly flat.
        let cube = Surface::new(
            (0..8)
                .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64))
                .collect(),
            &[
                [0, 2, 1],
                [1, 2, 3],
                [4, 5, 6],
                [5, 7, 6],
                [0, 1, 4],
                [1, 5, 4],
                [2, 6, 3],
                [3, 6, 7],
                [0, 4, 2],
                [2, 4, 6],
                [1, 3, 5],
                [3, 7, 5],
            ],
        )
        .unwrap();
        assert_eq!(cube.nearly_flat_input_edges(), 0);
    }

    /// `Surface::new` refuses what the readers refuse in a file (a library
    /// caller got `Ok`, then an output `check` rejects, or a mesh whose
    /// `validate` fails), each named by its 0-based number.
    #[test]
    fn new_refuses_what_no_input_may_have() {
        let tetra = || {
            vec![
                DVec3::ZERO,
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 0.0, 1.0),
            ]
        };
        let faces = [[1, 0, 2], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        assert!(Surface::new(tetra(), &faces).unwrap().validate().is_ok());
        let with = |v: usize, p: DVec3| {
            let mut positions = tetra();
            positions[v] = p;
            Surface::new(positions, &faces).unwrap_err()
        };
        assert_eq!(
            with(2, DVec3::new(f64::NAN, 1.0, 0.0)),
            InputError::NonFinite { vertex: 2 }
        );
        assert_eq!(
            with(3, DVec3::new(0.0, 0.0, f64::INFINITY)),
            InputError::NonFinite { vertex: 3 }
        );
        assert_eq!(
            with(1, DVec3::new(1e300, 0.0, 0.0)),
            InputError::OutOfRange { vertex: 1 }
        );
        assert_eq!(with(3, DVec3::new(2.0, 0.0, 0.0)), InputError::ZeroArea { face: 1 });
        let mut extra = tetra();
        extra.push(DVec3::splat(5.0));
        assert_eq!(
            Surface::new(extra, &faces).unwrap_err(),
            InputError::UnusedVertex { vertex: 4 }
        );
        let e = Surface::new(tetra(), &[[0, 1, 9]]).unwrap_err();
        assert_eq!(
            e,
            InputError::Topology(TopologyError::IndexOutOfRange { face: 0, index: 9 })
        );
        assert_eq!(e.to_string(), "triangle 0 uses vertex 9, beyond the vertex count");
        // No triangles (a vertex or none): refused, as the readers refuse a
        // file without faces (it was Ok, and its output failed `check`).
        assert_eq!(Surface::new(Vec::new(), &[]).unwrap_err(), InputError::NoFaces);
        assert_eq!(Surface::new(vec![DVec3::ZERO], &[]).unwrap_err(), InputError::NoFaces);
        // Edges below 1e-75 (io::MIN_EDGE), as the readers refuse them: the
        // crate example's folded rhombus at 1e-80 was Ok, and its output
        // failed `check`. At 1e-74 it is taken.
        let rhombus = |scale: f64| {
            let p = [[-2.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, -0.4, 0.3]];
            Surface::new(
                p.map(|p| DVec3::from_array(p) * scale).to_vec(),
                &[[0, 1, 2], [1, 0, 3]],
            )
        };
        assert!(rhombus(1e-74).is_ok());
        for scale in [1e-80, 1e-200] {
            let e = rhombus(scale).unwrap_err();
            assert_eq!(e, InputError::EdgeTooShort { face: 0 });
            assert_eq!(
                e.to_string(),
                "triangle 0 has an edge shorter than 1e-75, below the supported scale"
            );
        }
        assert_eq!(
            with(1, DVec3::new(1e76, 0.0, 0.0)),
            InputError::OutOfRange { vertex: 1 }
        );
    }

    /// Faces (a, b, c) and (b, a, d) in the plane z = 0, with a, b on the
    /// line y = x / 3 (c above it, d below), and the edge a–b.
    fn two_faces(c: DVec3) -> (Surface, EdgeId) {
        let positions = vec![DVec3::ZERO, DVec3::new(3.0, 1.0, 0.0), c, DVec3::new(1.0, -2.0, 0.0)];
        let s = Surface::new(positions, &[[0, 1, 2], [1, 0, 3]]).unwrap();
        let e = (0..s.topo.n_edges() as u32)
            .map(EdgeId)
            .find(|&e| {
                let h = e.halfedge();
                let ends = [s.topo.origin(h).0, s.topo.dest(h).0];
                ends == [0, 1] || ends == [1, 0]
            })
            .unwrap();
        (s, e)
    }

    /// Near-coincident edges are counted against the mesh's size, so that
    /// scaling a mesh does not change the count: a unit quad whose corner
    /// 3 sits 1e-12 from corner 2 has one, at any scale.
    #[test]
    fn near_coincident_edges_are_short_for_the_mesh_size() {
        let quad = |scale: f64, gap: f64| {
            let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1.0 - gap, 1.0], [0.0, 1.0]];
            let positions = corners
                .iter()
                .map(|&[x, y]| DVec3::new(x, y, 0.5 * x * y) * scale)
                .collect();
            let s = Surface::new(positions, &[[0, 1, 2], [0, 2, 3], [0, 3, 4]]).unwrap();
            s.validate().unwrap();
            s.input_figures
        };
        for scale in [1e-30, 1.0, 1e30] {
            let f = quad(scale, 1e-12);
            assert_eq!(f.near_coincident_edges, 1, "{scale}");
            assert!((f.diagonal / scale - 1.5).abs() < 1e-12, "{f:?}");
            assert_eq!(quad(scale, 1e-6).near_coincident_edges, 0);
        }
    }

    /// A split point rounded off its input edge's line, next to an apex that
    /// is barely off that line, makes a reversed face: `split_is_valid`
    /// refuses exactly that sample, and accepts it with the apex far away.
    #[test]
    fn split_refuses_a_point_rounded_past_an_apex() {
        let line_offset = |p: DVec3| geometry::projected_orientation([DVec3::ZERO, DVec3::new(3.0, 1.0, 0.0), p], 2);
        let mut found = 0;
        for k in 1..2000 {
            let t = k as f64 / 2000.0;
            let p = point_on_edge(DVec3::ZERO, DVec3::new(3.0, 1.0, 0.0), t);
            if line_offset(p) <= 0 {
                continue; // p on the line or below it
            }
            // c: p with both coordinates one ulp up. Where p's rounding put
            // it above the line by more than a quarter ulp of x, c is above
            // the line too (a valid input face), but below the line from p
            // to b, whose slope 1/3 is steeper than c - p's.
            let next = |x: f64| f64::from_bits(x.to_bits() + 1);
            let c = DVec3::new(next(p.x), next(p.y), 0.0);
            // Steeper only where y's ulp is a quarter of x's (not a half).
            if 4.0 * (c.y - p.y) != c.x - p.x || line_offset(c) <= 0 {
                continue;
            }
            let (s, e) = two_faces(c);
            s.validate().unwrap();
            let ends = s.input_edge_ends(s.edge_input[e.idx()]);
            let t_on_input = if ends[0] == DVec3::ZERO { t } else { 1.0 - t };
            if point_on_edge(ends[0], ends[1], t_on_input) != p {
                continue;
            }
            assert!(!s.split_is_valid(e, t_on_input), "t = {t}: (p, b, c) is reversed");
            let (far, e) = two_faces(DVec3::new(1.0, 2.0, 0.0));
            assert!(far.split_is_valid(e, t_on_input), "t = {t}");
            found += 1;
        }
        assert!(found > 0, "no sample rounded that way");
    }

    /// Region planes: a face of the region passes; reversed or degenerate
    /// faces do not.
    #[test]
    fn region_plane_judges_orientation_exactly() {
        let (a, b, c) = (DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0));
        let plane = RegionPlane::of_face([a, b, c]);
        assert_eq!(plane, RegionPlane { axis: 2, sign: 1 });
        assert!(plane.is_proper([a, b, c]));
        assert!(!plane.is_proper([a, c, b]));
        assert!(!plane.is_proper([a, b, DVec3::new(2.0, 0.0, 0.0)]));
    }
}
