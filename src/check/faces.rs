//! Rules 3 and 4: every output face inside one planar region with its orientation, and every
//! region's area kept.

use super::*;

/// The output area assigned to every region, and the groups of regions an output face could be
/// assigned to equally.
pub(super) struct Assignment {
    pub(super) area: Vec<f64>,
    groups: UnionFind,
}

/// Checks rule 3 and returns the output area assigned to every region.
///
/// A face goes to one of the regions shared by its three vertices: preferably one in which it is
/// exactly well oriented, then the one its normal agrees with best. It must be well oriented in
/// that region, exactly ([`Regions::side`]): a reversed (folded) face, or one whose projection on
/// the region's plane is degenerate, is a failure. When the face is well oriented in several of
/// the shared regions (coplanar regions that overlap, possible in a self-intersecting input), it
/// cannot be told from geometry which one it belongs to: those regions form one group, whose
/// total area is checked ([`check_areas`]).
///
/// A face with a vertex that is neither an input vertex nor on an input edge (reported by
/// [`classify_output_vertices`]) goes to the regions of its other vertices whose planes hold that
/// vertex too, and proves no overlap (it joins no group). In the plane of none of them, it lies on
/// no input face: a failure, its area in no region. A face with no such other vertex is left to
/// its vertices' failures.
pub(super) fn assign_faces(
    model: &InputModel,
    output_names: &Names,
    candidates: &Candidates,
    fail: &mut Failures,
) -> Assignment {
    let (regions, output) = (&model.regions, output_names.mesh);
    let mut assigned = vec![CompensatedSum::default(); regions.area.len()];
    let mut groups = UnionFind::new(regions.area.len());
    let mut common = Vec::new();
    let mut scored: Vec<(i8, f64, usize)> = Vec::new();
    for (f, t) in output.triangles.iter().enumerate() {
        if is_degenerate(t) {
            continue;
        }
        // (In a small array, not a vector: nothing is allocated per face.)
        let mut known = [0u32; 3];
        let mut count = 0;
        for &v in t.iter().filter(|&&v| candidates.known[v as usize]) {
            known[count] = v;
            count += 1;
        }
        let known = &mut known[..count];
        let all_known = count == 3;
        // The common regions are found by walking the shortest list (sorted: the same result
        // from any of them): a vertex of high valence can have thousands.
        known.sort_by_key(|&v| candidates.regions.row(v as usize).len());
        let Some((&first, rest)) = known.split_first() else {
            continue; // all three vertices already reported
        };
        common.clear();
        common.extend(candidates.regions.row(first as usize).iter().copied().filter(|r| {
            rest.iter()
                .all(|&v| candidates.regions.row(v as usize).binary_search(r).is_ok())
        }));
        let triangle = corners(output, t);
        let normal = triangle_normal(triangle);
        if !all_known {
            // Only the regions whose planes hold the face's vertices off the input's edges.
            let off = || t.iter().filter(|&&v| !candidates.known[v as usize]);
            common.retain(|&r| off().all(|&v| regions.holds(r as usize, output.positions[v as usize])));
            if common.is_empty() {
                fail.push(KIND_FACE, || {
                    known.sort_unstable();
                    let at: Vec<String> = known.iter().map(|&v| output_names.label(v)).collect();
                    let off: Vec<String> = off().map(|&v| output_names.label(v)).collect();
                    let verb = if off.len() == 1 { "is" } else { "are" };
                    format!(
                        "output {} lies on no input face: {}, off the input's edges, {verb} in the plane \
                         of none of the input faces at {}",
                        output_names.face(f),
                        off.join(" and "),
                        at.join(" and ")
                    )
                });
                continue;
            }
        }
        scored.clear();
        scored.extend(common.iter().map(|&r| {
            let r = r as usize;
            (regions.side(r, triangle), regions.normal[r].dot(normal), r)
        }));
        let best = scored
            .iter()
            .copied()
            .max_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)));
        let Some((side, _, r)) = best else {
            fail.push(KIND_FACE, || {
                format!(
                    "output {} does not lie inside one planar region of the input \
                     (its vertices share no region)",
                    output_names.face(f)
                )
            });
            continue;
        };
        assigned[r].add(0.5 * normal.length());
        if side > 0 {
            for &(other_side, _, other) in &scored {
                // (A face with a vertex off the input's edges proves no overlap.)
                if other_side > 0 && other != r && all_known {
                    groups.union(r as u32, other as u32);
                }
            }
        } else {
            fail.push(KIND_FACE, || {
                let what = if exactly_degenerate(triangle) {
                    "has zero area (its corners are collinear) in"
                } else if side == 0 {
                    "has zero area in the projection on the plane of"
                } else {
                    "is reversed relative to"
                };
                let dot = regions.normal[r].dot(normal.normalize_or_zero());
                format!(
                    "output {} {what} {} (unit normal . region normal = {dot:.3e})",
                    output_names.face(f),
                    regions.name(r, &model.names)
                )
            });
        }
    }
    Assignment {
        area: assigned.iter().map(CompensatedSum::value).collect(),
        groups,
    }
}

/// Checks rule 3 across the output's edges: two output faces folded onto each other (coplanar,
/// their third corners on the same side of the edge between them) face opposite ways
/// in one plane, so lie in two planar regions of the input that meet there, along an input edge
/// (a folded one: where an input overlaps itself, one sheet turning back over the other).
/// Across any other output edge, one of the two is a face turned over. So the edge must lie
/// along an input edge: both its ends at that edge's ends or on it, within the on-edge
/// tolerance.
///
/// ```text
///             d
///            /|        faces (a, b, c) and (b, a, d) in one plane, c and d on the same
///       c   / |        side of a-b: they overlap, folded onto each other. Along an input
///       |\ /  |        edge between two sheets of a folded input, as they may be; anywhere
///       a-----b        else, one of the two is turned over.
/// ```
///
/// Areas alone cannot tell such a face where the input is folded: turned over, it fits the other
/// sheet's region, the right way up there, and a tiny one moves less area between the two
/// regions than a billionth of theirs (`AREA_TOLERANCE`). `folds` are the interior output
/// edges whose faces are [`folded`] (exactly, or within rounding where their normals are
/// clear: in a plane that is not an axis plane, added vertices are rounded off it), found by
/// rule 6's pass over the edges (few: none unless the input is folded).
pub(super) fn check_folds(
    model: &InputModel,
    output_names: &Names,
    output_edges: &[Edge],
    folds: &[u32],
    fail: &mut Failures,
) {
    if folds.is_empty() {
        return;
    }
    let (input, input_edges, output) = (model.mesh, &model.prepared.edges, output_names.mesh);
    let ends = |e: u32| {
        let e = &output_edges[e as usize];
        (output.positions[e.lo as usize], output.positions[e.hi as usize])
    };
    // Looked up at the edges' midpoints: every input edge containing one is among the grid's
    // candidates there.
    let middle = |(a, b): (DVec3, DVec3)| 0.5 * a + 0.5 * b;
    let middles: Vec<DVec3> = folds.iter().map(|&e| middle(ends(e))).collect();
    let grid = EdgeGrid::new(input, input_edges, &middles);
    // `x` at an end of the input edge from `u` to `w`, or on it within the on-edge tolerance.
    let on_or_at = |x: DVec3, u: DVec3, w: DVec3| x == u || x == w || distance_on_edge(x, u, w).is_some();
    for (&e, &m) in folds.iter().zip(&middles) {
        let (pa, pb) = ends(e);
        let along = grid.candidates(m).iter().any(|&k| {
            let k = &input_edges[k as usize];
            let (u, w) = (input.positions[k.lo as usize], input.positions[k.hi as usize]);
            on_or_at(pa, u, w) && on_or_at(pb, u, w)
        });
        if !along {
            let (a, b, f, g) = output_edges[e as usize].oriented();
            fail.push(KIND_FACE, || {
                format!(
                    "output {} and {} lie folded onto each other across the edge ({}, {}), which lies \
                     along no input edge: one of them is turned over",
                    output_names.face(f as usize),
                    output_names.face(g as usize),
                    output_names.label(a),
                    output_names.label(b)
                )
            });
        }
    }
}

/// Whether faces `(a, b, c)` and `(b, a, d)` lie folded onto each other: exactly
/// ([`coplanar_and_folded`]), or within the rounding of their corners' positions where their
/// normals are clear (in a plane that is not an axis plane, vertices added on a folded input
/// edge are rounded off it). Their normals are then opposite; the computed ones are within
/// their rounding of that (far from it only for needles), which rules out nearly every other
/// pair before the exact test.
///
/// Across an edge that lies along no input edge, two output faces lie in one planar region
/// of the input, whose corners are in its plane exactly: their normals agree to within that
/// rounding, and a pair whose normals are clear is never taken for folded there.
pub(super) fn folded([a, b, c, d]: [DVec3; 4]) -> bool {
    if ![a, b, c, d].iter().all(|p| p.is_finite()) {
        return false; // (reported as an invalid coordinate)
    }
    let (n1, n2) = ((b - a).cross(c - a), (a - b).cross(d - b));
    // The computation's rounding, and the positions' (an added vertex is a rounded point of
    // its input edge: within a few units of roundoff of the largest coordinate).
    let arithmetic = normal_rounding(n1, b - a, c - a) + normal_rounding(n2, a - b, d - b);
    let largest = [a, b, c, d].iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
    let positions = position_rounding(n1, b - a, c - a, largest) + position_rounding(n2, a - b, d - b, largest);
    let slack = arithmetic + positions;
    // 0 for opposite directions (NaN for a zero normal: then the exact test decides).
    let opposite = 1.0 + n1.dot(n2) / (n1.length() * n2.length());
    if opposite > 0.5 * slack * slack + 8.0 * f64::EPSILON {
        return false;
    }
    coplanar_and_folded(a, b, c, d) || slack < CLEAR_NORMALS
}

/// Two faces' normals are clear ([`folded`]) when rounding can turn them by less than this,
/// in radians, in all: far above the rounding of any face that is not a needle, and small
/// enough that two faces of one region, whose normals then agree within it, never look folded.
const CLEAR_NORMALS: f64 = 1e-3;

/// A bound, in radians, on how far the direction of `n`, the cross product `u x v` computed in
/// f64 (`u` and `v` themselves differences of positions), is from the exact one: a few units of
/// roundoff of `|u| |v|`, relative to `|n|` (infinite for a zero `n`).
fn normal_rounding(n: DVec3, u: DVec3, v: DVec3) -> f64 {
    16.0 * f64::EPSILON * u.length() * v.length() / n.length()
}

/// A bound, in radians, on how far rounding the face's corners (each by a few units of roundoff
/// of `largest`, the largest coordinate around) turns the direction of its normal `n = u x v`.
fn position_rounding(n: DVec3, u: DVec3, v: DVec3, largest: f64) -> f64 {
    16.0 * f64::EPSILON * largest * (u.length() + v.length()) / n.length()
}

/// How much the rounding of the added vertices may change the area of every region: the input
/// edges on the region's border (a boundary edge, or an edge to another region) that carry
/// added vertices, each allowing [`AREA_ROUNDING`] units of roundoff of its largest coordinate
/// across its length. (Vertices on an edge inside a region only move area between its faces.)
pub(super) fn rounding_allowance(model: &InputModel, edge_has_added: &[bool]) -> Vec<f64> {
    let regions = &model.regions;
    let p = |v: u32| model.mesh.positions[v as usize];
    let mut rounding = vec![0.0; regions.area.len()];
    let edges = &model.prepared.edges;
    for e in (0..edges.len()).filter(|&e| edge_has_added[e]).map(|e| &edges[e]) {
        let faces = &e.faces[..e.count.min(2) as usize];
        let region = |f: u32| regions.of_face[f as usize] as usize;
        if e.is_interior() && region(faces[0]) == region(faces[1]) {
            continue;
        }
        let (a, b) = (p(e.lo), p(e.hi));
        let coordinate = a.abs().max_element().max(b.abs().max_element());
        let allowance = AREA_ROUNDING * f64::EPSILON * coordinate * (b - a).length();
        if allowance.is_finite() {
            for &f in faces {
                rounding[region(f)] += allowance;
            }
        }
    }
    rounding
}

/// Checks rule 4: every region keeps its area; regions grouped by [`assign_faces`] keep their
/// total area. `rounding_of` is [`rounding_allowance`].
pub(super) fn check_areas(model: &InputModel, assignment: &mut Assignment, rounding_of: &[f64], fail: &mut Failures) {
    let regions = &model.regions;
    let n = regions.area.len();
    let mut before = vec![CompensatedSum::default(); n];
    let mut after = vec![CompensatedSum::default(); n];
    let mut rounding = vec![0.0; n];
    let roots: Vec<usize> = (0..n).map(|r| assignment.groups.find(r as u32) as usize).collect();
    for (r, &allowance) in rounding_of.iter().enumerate() {
        let root = roots[r];
        before[root].add(regions.area[r]);
        after[root].add(assignment.area[r]);
        rounding[root] += allowance;
    }
    // The regions of every group, in increasing order (a counting sort by root: no vector per
    // region, of which a curved input has about one per face).
    let (start, by_root) = grouped(n, || roots.iter().enumerate().map(|(r, &root)| (root, r)));
    let members = |root: usize| &by_root[start[root]..start[root + 1]];
    for root in (0..n).filter(|&r| !members(r).is_empty()) {
        let (before, after) = (before[root].value(), after[root].value());
        let tolerance = AREA_TOLERANCE * before + AREA_FLOOR + rounding[root];
        let kept = (after - before).abs() <= tolerance; // false for NaN too
        if !kept {
            fail.push(KIND_AREA, || match members(root) {
                [r] => format!("{} area {before} became {after}", regions.name(*r, &model.names)),
                group => {
                    let names: Vec<String> = group.iter().take(6).map(|&r| regions.name(r, &model.names)).collect();
                    let more = if group.len() > 6 { ", ..." } else { "" };
                    format!(
                        "the {} overlapping coplanar regions {}{more} (whose faces cannot be told \
                         apart) have total area {before}, which became {after}",
                        group.len(),
                        names.join(", ")
                    )
                }
            });
        }
    }
}
