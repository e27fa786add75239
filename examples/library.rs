//! delmesh as a library: read a mesh, make it a Delaunay mesh, prune the
//! added vertices it can do without, verify it, and write it with its
//! texture coordinates, normals, colours, groups and materials (what the
//! command line does), then hand the cotangent weights' inputs (positions
//! and triangles) to your own code.
//!
//! ```sh
//! cargo run --release --example library -- data/bunny.obj bunny-dm.obj
//! ```
//!
//! The attributes: [`Transfer::new`] takes the input's (per corner of its
//! triangles) and the surface *before* refinement; after refining (and
//! pruning), [`Transfer::apply`] gives them per corner of the output's
//! triangles, for [`io::write_mesh_with_attributes`]. (Writing
//! `surface.positions` and `surface.triangles()` with [`io::write_mesh`]
//! alone drops them.) The face map ([`FaceOrigins`]) is made the same way,
//! before refinement, from triangles read with `face_numbers`.

use std::path::Path;

use delmesh::attributes::Transfer;
use delmesh::face_map::FaceOrigins;
use delmesh::io::{self, ReadOptions};
use delmesh::{make_delaunay, Options};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (input_path, output_path) = match &args[..] {
        [_, input, output] => (Path::new(input), Path::new(output)),
        _ => return Err("usage: library INPUT OUTPUT".into()),
    };
    // Read (any format, welded and validated; `repair: Some(..)` fixes what
    // would be refused) and build the refinable surface (`build_surface_with`
    // takes other attribute tolerances).
    // (`face_numbers`: each triangle's face of the file, for the face map.)
    let options = ReadOptions {
        face_numbers: true,
        ..ReadOptions::default()
    };
    let mut input = io::read_mesh(input_path, &options)?;
    let mut surface = io::build_surface(&mut input, input_path)?;
    for note in &input.notes {
        println!("note: {note}");
    }
    // The attributes' transfer, made before refinement (empty if the input
    // has none: `apply` then gives none, and the output is positions only).
    let transfer = Transfer::new(input.attributes.clone(), &input.triangles, &surface);
    // Likewise the face map (which input face each output face lies in).
    let origins = FaceOrigins::new(&input.triangles, &input.triangle_polygon, &surface);
    // Algorithm 2 with the defaults (stack, score 2, median), then pruning.
    let options = Options::default();
    let stats = make_delaunay(&mut surface, &options)?;
    let pruned = delmesh::prune::prune(&mut surface, &options);
    // The input's vertices come first, bit for bit; every other vertex lies
    // on an input edge (`surface.vertex_sources()` says which, and where).
    let (positions, triangles) = (surface.positions.clone(), surface.triangles());
    let report = delmesh::check::check_meshes(
        &delmesh::check::Mesh3 {
            positions: input.positions.clone(),
            triangles: input.triangles.clone(),
        },
        &delmesh::check::Mesh3 {
            positions: positions.clone(),
            triangles: triangles.clone(),
        },
    );
    assert!(report.passed(), "{:?}", report.failures);
    // Per corner of `triangles`: interpolated at the added vertices.
    let attributes = transfer.apply(&surface);
    let written = io::write_mesh_with_attributes(output_path, &positions, &triangles, &attributes)?;
    for note in &written.notes {
        println!("note: {note}"); // what the output's format cannot hold
    }
    // Per output face (as `triangles` orders them; `written.face_order`
    // gives the file's order): a per-face label of the input follows it.
    let map = origins.apply(&surface);
    let across = map.iter().filter(|o| !o.inside).count();
    println!(
        "face map: {across} of {} faces lie across several input faces",
        map.len()
    );
    println!(
        "{} splits, {} flips, {} of them removed again: {} vertices, {} faces, {} non-Delaunay edges",
        stats.splits,
        stats.flips,
        pruned.removed,
        positions.len(),
        triangles.len(),
        report.non_delaunay_edges
    );
    Ok(())
}
