//! `cargo bench`: the refine phase alone (Algorithm 2 on an already built
//! mesh), the build phase, and the read phase (parsing alone, and parsing
//! with welding and triangulating), on the armadillo (52,000 faces) and the
//! bunny; the refine phase also on the rotor, the one shared mesh whose
//! refine phase is short of ten times SplitToDelaunay's speed. Files are
//! read from disk once, outside the timed code. Needs `../shared/meshes`
//! beside the crate for the armadillo and the rotor; the bunny ships in
//! `data/`.

use std::path::{Path, PathBuf};

use delmesh::io;
use delmesh::mesh::Surface;
use delmesh::refine::{make_delaunay, Options};

fn main() {
    divan::main();
}

fn mesh_path(name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shared = root.join("../shared/meshes").join(name);
    if shared.exists() {
        shared
    } else {
        root.join("data").join(name)
    }
}

fn surface(name: &str) -> Surface {
    let path = mesh_path(name);
    let mut input = io::read_obj(&path).expect("readable mesh");
    io::build_surface(&mut input, &path).expect("valid mesh")
}

#[divan::bench(args = ["armadillo.obj", "bunny.obj", "rotor.obj"], sample_count = 20)]
fn refine(bencher: divan::Bencher, name: &str) {
    let base = surface(name);
    bencher.with_inputs(|| base.clone()).bench_local_values(|mut s| {
        make_delaunay(&mut s, &Options::default()).expect("refines");
        s
    });
}

#[divan::bench(args = ["armadillo.obj", "bunny.obj"], sample_count = 20)]
fn build(bencher: divan::Bencher, name: &str) {
    let path = mesh_path(name);
    let input = io::read_obj(&path).expect("readable mesh");
    bencher
        .with_inputs(|| input.clone())
        .bench_local_refs(|input| io::build_surface(input, &path).expect("valid mesh"));
}

/// The exact predicates as the reader and the build call them: `collinear`
/// on every input face, `flat_pair` on every interior input edge (the
/// fast path; no coordinate of these meshes is tiny).
#[divan::bench(args = ["armadillo.obj", "bunny.obj"], sample_count = 20)]
fn predicates(bencher: divan::Bencher, name: &str) {
    use delmesh::geometry::{collinear, flat_pair};
    use delmesh::mesh::EdgeId;
    let s = surface(name);
    let faces: Vec<[glam::DVec3; 3]> = s
        .triangles()
        .iter()
        .map(|t| t.map(|v| s.positions[v as usize]))
        .collect();
    let quads: Vec<[glam::DVec3; 4]> = (0..s.topo.n_edges() as u32)
        .map(EdgeId)
        .filter(|&e| s.topo.is_interior(e))
        .map(|e| s.edge_quad(e))
        .collect();
    bencher.bench_local(|| {
        let zero_area = faces.iter().filter(|[a, b, c]| collinear(*a, *b, *c)).count();
        let flat = quads.iter().filter(|[a, b, c, d]| flat_pair(*a, *b, *c, *d)).count();
        (zero_area, flat)
    });
}

/// Parsing the OBJ text alone (statements into a raw mesh), the file's
/// bytes already in memory.
#[divan::bench(args = ["armadillo.obj", "bunny.obj"], sample_count = 20)]
fn parse(bencher: divan::Bencher, name: &str) {
    let bytes = std::fs::read(mesh_path(name)).expect("readable file");
    bencher.bench_local(|| io::obj::parse_obj(&bytes).expect("an OBJ file"));
}

/// The whole read phase but the file system: parsing, then welding,
/// triangulating and checking the polygons (`io::parse_obj`).
#[divan::bench(args = ["armadillo.obj", "bunny.obj"], sample_count = 20)]
fn read(bencher: divan::Bencher, name: &str) {
    let path = mesh_path(name);
    let bytes = std::fs::read(&path).expect("readable file");
    bencher.bench_local(|| io::parse_obj(&bytes, &path).expect("valid mesh"));
}

/// The connectivity alone (`Topology::from_triangles`: pairing half-edges,
/// checking every vertex is one fan), the first part of the build phase.
#[divan::bench(args = ["armadillo.obj", "bunny.obj"], sample_count = 20)]
fn topology(bencher: divan::Bencher, name: &str) {
    let path = mesh_path(name);
    let input = io::read_obj(&path).expect("readable mesh");
    bencher.bench_local(|| {
        delmesh::mesh::Topology::from_triangles(input.positions.len(), &input.triangles).expect("valid mesh")
    });
}
