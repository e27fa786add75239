//! Rules 1 and 2: every input vertex kept bit for bit, every added vertex on an input edge, and
//! the regions each output vertex may belong to.

use super::*;

/// Candidate regions of every output vertex.
pub(super) struct Candidates {
    /// Regions per output vertex (sorted, unique).
    pub(super) regions: Csr,
    /// Whether the vertex was recognised (input vertex or on an input edge).
    pub(super) known: Vec<bool>,
    /// Number of referenced output vertices that are not input vertices.
    pub(super) added: usize,
    /// Number of output vertices no face uses.
    pub(super) unused: usize,
    /// Output vertices used by a face on no input edge and at no input vertex, and how many of
    /// them have only short coordinates ([`CheckReport::misplaced_vertices`]).
    pub(super) misplaced: (usize, usize),
    /// Whether an added vertex lies on each input edge (indexed like `Prepared::edges`).
    pub(super) edge_has_added: Vec<bool>,
    /// `(output vertex, input boundary edge)` for every input boundary edge each recognised
    /// output vertex is on: as an endpoint (at an input vertex's position) or within the on-edge
    /// tolerance; by vertex, then by edge.
    pub(super) on_boundary: Vec<(u32, u32)>,
}

impl Candidates {
    /// The input boundary edges output vertex `v` is on (sorted, unique).
    pub(super) fn boundary_edges_of(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let start = self.on_boundary.partition_point(|&(w, _)| w < v);
        self.on_boundary[start..]
            .iter()
            .take_while(move |&&(w, _)| w == v)
            .map(|&(_, e)| e)
    }
}

/// Where the output's vertices are looked up: the input's vertices by position, and for the
/// others the input's edges ([`EdgeGrid`]).
pub(super) struct VertexSearch {
    /// The first input vertex (used by a face) at every such position...
    lookup: FastMap<[u64; 3], u32>,
    /// ...and the next one there (several share one position where a pinch was read as
    /// separate fans, see `split_pinched_vertices`), or [`VertexSearch::END`].
    same_next: Vec<u32>,
    /// Output vertices used by a face at each input vertex's position (counted on the first
    /// input vertex there).
    at_position: Vec<u32>,
    /// The positions of the output vertices the grid will look up (its trees are shaped by them).
    added_points: Vec<DVec3>,
    /// The positions of the input vertices no face uses: an unused output vertex may sit there.
    unused_input: HashSet<[u64; 3], crate::hash::FastBuild>,
    /// The grid, once built: at once when some output vertex is not at an input vertex's
    /// position, else when first needed (if ever).
    pub(super) grid: Option<EdgeGrid>,
    /// The input edges containing each output vertex used by a face and not at an input
    /// vertex's position, looked up in the grid as soon as it is built (a row per output
    /// vertex, empty for the others): on the thread that builds the grid, beside the input's
    /// regions and the output's edges.
    added_edges: Csr,
    /// `(output vertex, input boundary edge)` for each input boundary edge that contains such an
    /// output vertex within the on-edge tolerance, nearest or not
    /// ([`EdgeGrid::boundary_edges_containing`]), by output vertex.
    added_boundary: Vec<(u32, u32)>,
}

impl VertexSearch {
    /// Marks the end of a `same_next` chain.
    const END: u32 = u32::MAX;

    /// Indexes the `input` (validated as `prepared`) for the vertices of `output`, whose faces
    /// use the vertices marked in `out_referenced`.
    pub(super) fn new(input: &Mesh3, prepared: &Prepared, output: &Mesh3, out_referenced: &[bool]) -> VertexSearch {
        let mut lookup: FastMap<[u64; 3], u32> = FastMap::default();
        let mut same_next = vec![Self::END; input.positions.len()];
        for (v, p) in input.positions.iter().enumerate().rev() {
            if prepared.referenced[v] {
                if let Some(old) = lookup.insert(bits(*p), v as u32) {
                    same_next[v] = old;
                }
            }
        }
        let mut at_position = vec![0u32; input.positions.len()];
        let mut added_points = Vec::new();
        let unused_input: HashSet<[u64; 3], crate::hash::FastBuild> = (input.positions.iter().enumerate())
            .filter(|&(v, _)| !prepared.referenced[v])
            .map(|(_, p)| bits(*p))
            .collect();
        let is_input_position = |p: DVec3| lookup.contains_key(&bits(p)) || unused_input.contains(&bits(p));
        for (v, p) in output.positions.iter().enumerate() {
            match (out_referenced[v], lookup.get(&bits(*p))) {
                (true, Some(&first)) => at_position[first as usize] += 1,
                (true, None) => added_points.push(*p),
                (false, _) if p.is_finite() && !is_input_position(*p) => added_points.push(*p),
                (false, _) => {}
            }
        }
        // Every vertex of `added_points` is looked up in the grid.
        let grid = (!added_points.is_empty()).then(|| EdgeGrid::new(input, &prepared.edges, &added_points));
        let mut added_edges = CsrBuilder::default();
        let mut added_boundary = Vec::new();
        let has_boundary = prepared.edges.iter().any(Edge::is_boundary);
        if let Some(grid) = &grid {
            let mut on_edges = Vec::new();
            for (v, p) in output.positions.iter().enumerate() {
                if out_referenced[v] && !lookup.contains_key(&bits(*p)) {
                    grid.edges_containing(input, &prepared.edges, *p, &mut on_edges);
                    added_edges.extend(&on_edges);
                    if has_boundary {
                        grid.boundary_edges_containing(input, &prepared.edges, *p, &mut on_edges);
                        added_boundary.extend(on_edges.iter().map(|&e| (v as u32, e)));
                    }
                }
                added_edges.finish_row();
            }
        }
        VertexSearch {
            lookup,
            same_next,
            at_position,
            added_points,
            unused_input,
            grid,
            added_edges: added_edges.build(),
            added_boundary,
        }
    }
}

/// Checks rules 1 and 2 and returns the candidate regions of every output vertex, looked up
/// in `search` (made for this model and output).
pub(super) fn classify_output_vertices(
    model: &InputModel,
    search: &mut VertexSearch,
    output_names: &Names,
    out_referenced: &[bool],
    fail: &mut Failures,
) -> Candidates {
    let input = model.mesh;
    let output = output_names.mesh;
    const END: u32 = VertexSearch::END;
    let VertexSearch {
        lookup,
        same_next,
        at_position,
        added_points,
        unused_input,
        grid,
        added_edges,
        added_boundary,
    } = search;
    // The boundary edges at each input vertex, to place the output's vertices at input positions.
    let boundary_ends: Vec<(u32, u32)> = (model.prepared.edges.iter().enumerate())
        .filter(|(_, edge)| edge.is_boundary())
        .flat_map(|(e, edge)| [(edge.lo, e as u32), (edge.hi, e as u32)])
        .collect();
    let boundary_at = Csr::from_pairs(input.positions.len(), &boundary_ends);
    drop(boundary_ends);
    let mut on_boundary = Vec::new();
    let mut boundary_set = Vec::new();
    let is_input_position = |p: DVec3| lookup.contains_key(&bits(p)) || unused_input.contains(&bits(p));
    let mut seen = vec![false; input.positions.len()];
    let mut regions = CsrBuilder::default();
    let mut known = vec![false; output.positions.len()];
    let mut added = 0;
    let mut unused = 0;
    let mut misplaced = (0, 0);
    let mut edge_has_added = vec![false; model.prepared.edges.len()];
    let mut on_edges = Vec::new();
    let mut set = Vec::new();
    let mut edge_regions = Vec::new();
    for (v, &p) in output.positions.iter().enumerate() {
        if !out_referenced[v] {
            // In no face, so in no region: it must only be where the output may have vertices.
            unused += 1;
            let on_input = p.is_finite()
                && (is_input_position(p) || {
                    let grid = grid.get_or_insert_with(|| EdgeGrid::new(input, &model.prepared.edges, added_points));
                    grid.edges_containing(input, &model.prepared.edges, p, &mut on_edges);
                    !on_edges.is_empty()
                });
            if !on_input {
                fail.push(KIND_VERTEX, || {
                    format!(
                        "an output vertex no face uses, {}, is neither an input vertex nor on an input edge",
                        point_text(p)
                    )
                });
            }
            regions.finish_row();
            continue;
        }
        if let Some(&first) = lookup.get(&bits(p)) {
            known[v] = true;
            set.clear();
            boundary_set.clear();
            let mut iv = first;
            let mut input_count = 0;
            while iv != END {
                seen[iv as usize] = true;
                set.extend_from_slice(model.vertex_regions.row(iv as usize));
                boundary_set.extend_from_slice(boundary_at.row(iv as usize));
                iv = same_next[iv as usize];
                input_count += 1;
            }
            // Where the surface touches itself, an input vertex can lie inside an input edge of
            // another part (a T-junction in space): a vertex added on that edge there can have
            // the input vertex's position, bit for bit, and belongs to the edge's regions. When
            // the output has more vertices at the position than the input, which is which is
            // unknown: all of them get the regions of both. (Not otherwise: an input vertex
            // merely within the on-edge tolerance of an edge does not join its regions.)
            if at_position[first as usize] > input_count {
                let grid = grid.get_or_insert_with(|| EdgeGrid::new(input, &model.prepared.edges, added_points));
                grid.edges_containing(input, &model.prepared.edges, p, &mut on_edges);
                model.regions_of_edges(&on_edges, &mut edge_regions);
                set.extend_from_slice(&edge_regions);
                on_edges.iter().for_each(|&e| edge_has_added[e as usize] = true);
                grid.boundary_edges_containing(input, &model.prepared.edges, p, &mut on_edges);
                boundary_set.extend_from_slice(&on_edges);
            }
            set.sort_unstable();
            set.dedup();
            regions.extend(&set);
            boundary_set.sort_unstable();
            boundary_set.dedup();
            on_boundary.extend(boundary_set.iter().map(|&e| (v as u32, e)));
        } else {
            added += 1;
            // (Looked up when the grid was built, which it was: `p` is among its points.)
            on_edges.clear();
            on_edges.extend_from_slice(added_edges.row(v));
            if on_edges.is_empty() {
                misplaced.0 += 1;
                misplaced.1 += usize::from(p.to_array().iter().all(|&x| is_short_coordinate(x)));
                fail.push(KIND_VERTEX, || {
                    format!(
                        "output {} is neither an input vertex nor on an input edge",
                        output_names.vertex(v as u32)
                    )
                });
            } else {
                known[v] = true;
                model.regions_of_edges(&on_edges, &mut set);
                regions.extend(&set);
                on_edges.iter().for_each(|&e| edge_has_added[e as usize] = true);
                // (`added_boundary` is in vertex order too.)
                let start = added_boundary.partition_point(|&(w, _)| w < v as u32);
                let row = added_boundary[start..].iter().take_while(|&&(w, _)| w == v as u32);
                on_boundary.extend(row);
            }
        }
        regions.finish_row();
    }
    for (v, &seen) in seen.iter().enumerate() {
        if model.prepared.referenced[v] && !seen {
            fail.push(KIND_MISSING, || {
                format!("input {} missing from output", model.names.vertex(v as u32))
            });
        }
    }
    Candidates {
        regions: regions.build(),
        known,
        added,
        unused,
        misplaced,
        edge_has_added,
        on_boundary,
    }
}

/// Whether `x` is what a file with rounded coordinates holds: a 32-bit float, or a decimal of
/// at most [`SHORT_DIGITS`] significant digits (its shortest round-trip form).
pub(super) fn is_short_coordinate(x: f64) -> bool {
    if x == 0.0 || f64::from(x as f32) == x {
        return true;
    }
    let text = format!("{:e}", x.abs());
    let mantissa = text.split('e').next().unwrap_or("");
    mantissa.chars().filter(char::is_ascii_digit).count() <= SHORT_DIGITS
}

/// The on-edge tolerance of input edge `(a, b)`; see [`ON_EDGE_TOLERANCE`].
pub(super) fn edge_tolerance(a: DVec3, b: DVec3) -> f64 {
    ON_EDGE_TOLERANCE * a.abs().max_element().max(b.abs().max_element()).max(1e-300)
}

/// The distance from `p` to segment `(a, b)` if `p` lies on it strictly between its endpoints,
/// within tolerance; `None` otherwise.
pub(super) fn distance_on_edge(p: DVec3, a: DVec3, b: DVec3) -> Option<f64> {
    let d = b - a;
    let len2 = d.length_squared();
    if len2 <= 0.0 {
        return None;
    }
    let t = (p - a).dot(d) / len2;
    let distance = (p - (a + t * d)).length();
    // Strictly between the endpoints: 0 < t < 1, decided from the nearer end (the computed t
    // rounds to 1 for a point a few units of roundoff of a from b on a long edge).
    let inside = (p - a).dot(d) > 0.0 && (p - b).dot(d) < 0.0;
    (inside && distance <= edge_tolerance(a, b)).then_some(distance)
}

/// How much farther than the nearest one another input edge containing a point may be and still
/// count as the point's edge, relative to the edge's largest coordinate: 16 units of roundoff,
/// the error of computing a point on an edge and its distance, and far below the on-edge
/// tolerance (about 70,000 units).
pub(super) const NEAREST_EDGE_SLACK: f64 = 16.0 * f64::EPSILON;
