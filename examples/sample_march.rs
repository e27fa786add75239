//! Why `-ds pqueue -s 0 -nomedian` cannot finish on `anchor.obj`: it runs
//! that combination up to a work limit, then reports where the added vertices
//! are and how far the longest non-Delaunay sub-edge still has to go.
//!
//! With score 0 every sample scores the same and without the median rule the
//! first sample from the edge's start is taken (SPEC §4), so a long crease
//! edge is split one sample spacing (`rho_e`) at a time while it stays the
//! longest edge of the priority queue.
//!
//! ```sh
//! cargo run --release --example sample_march -- ../shared/meshes/anchor.obj 400000
//! ```

use std::collections::BTreeMap;
use std::path::Path;

use delmesh::geometry::delaunay_excess;
use delmesh::io::{self, ReadOptions};
use delmesh::mesh::{Carrier, EdgeId, NO_INPUT_EDGE};
use delmesh::refine::{make_delaunay, Options, Worklist};
use delmesh::samples::Score;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = Path::new(args.get(1).map_or("../shared/meshes/anchor.obj", String::as_str));
    let limit: usize = args.get(2).map_or(400_000, |n| n.parse().expect("a work limit"));
    let mut input = io::read_mesh(path, &ReadOptions::default()).expect("a readable mesh");
    let mut s = io::build_surface(&mut input, path).expect("a mesh delmesh accepts");
    let mut options = Options::new(Worklist::PriorityQueue, Score::AllEqual, false);
    options.max_added = limit;
    match make_delaunay(&mut s, &options) {
        Ok(stats) => println!("finished: {} splits, {} flips", stats.splits, stats.flips),
        Err(e) => println!("{e}"),
    }
    let rho_e = delmesh::refine::sample_constants(&s).rho_e;

    // The input edge with the most added vertices, and their spacing.
    let mut on_edge: BTreeMap<u32, Vec<f64>> = BTreeMap::new();
    for c in &s.carriers {
        if let Carrier::Edge { edge, t } = *c {
            on_edge.entry(edge).or_default().push(t);
        }
    }
    if let Some((edge, mut ts)) = on_edge.into_iter().max_by_key(|(_, ts)| ts.len()) {
        ts.sort_by(f64::total_cmp);
        let [p, q] = s.input_edge_ends(edge);
        let length = (q - p).length();
        let gaps: Vec<f64> = ts.windows(2).map(|w| (w[1] - w[0]) * length).collect();
        let (min, max) = gaps
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &g| (lo.min(g), hi.max(g)));
        println!(
            "input edge {edge} (length {length:.4}): {} added vertices, t in [{:.7}, {:.7}], \
             neighbours {min:.4e} .. {max:.4e} apart (rho_e = {rho_e:.4e})",
            ts.len(),
            ts[0],
            ts[ts.len() - 1]
        );
    }

    // The longest non-Delaunay sub-edge: how far must one end move along it,
    // its apexes fixed, before it is Delaunay?
    let longest = (0..s.topo.n_edges() as u32)
        .map(EdgeId)
        .filter(|&e| s.edge_input[e.idx()] != NO_INPUT_EDGE && s.is_non_delaunay(e, 1e-10))
        .max_by(|&x, &y| s.edge_length(x).total_cmp(&s.edge_length(y)));
    if let Some(e) = longest {
        let [a, b, c, d] = s.edge_quad(e);
        let length = (b - a).length();
        println!(
            "longest non-Delaunay sub-edge: length {length:.6}, alpha+beta-pi = {:.4} rad",
            delaunay_excess(a, b, c, d)
        );
        for (name, moved_end_first) in [("start", true), ("end", false)] {
            // Bisection on the fraction f of the sub-edge the end moves by.
            let excess = |f: f64| match moved_end_first {
                true => delaunay_excess(a + (b - a) * f, b, c, d),
                false => delaunay_excess(a, b + (a - b) * f, c, d),
            };
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if excess(mid) > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            println!(
                "  Delaunay once its {name} has moved {:.4} of it: {:.3e} samples of rho_e",
                hi,
                hi * length / rho_e
            );
        }
    }
}
